"""Shared fixtures: the published case, and every shipped case solved once per test session.

:func:`solved` keeps each shipped case's answer (by its file, placement, law and fields changed), so the many
tests that read a shipped case's plan solve it once per test process (pytest-xdist runs one per core)."""

from __future__ import annotations

import json
import os
from functools import cache
from pathlib import Path

import pytest

from planning.model.case import Case
from planning.model.case_file import read_case
from planning.solver.optimize import solve
from planning.solver.solution import Solution

# the tests solve with the interpreted derivative functions, whatever a developer compiled on this machine
# (``pressplan compile``; the same numbers either way): tests/test_compiled.py sets its own cache
os.environ["PRESSPLAN_CACHE"] = "off"
ROOT = Path(__file__).resolve().parents[1]
PUBLISHED_CASE = ROOT / "cases" / "wang2023-side-panel.yaml"
SHIPPED_CASES = sorted((ROOT / "cases").glob("*.yaml"))


def shipped(path: Path, law: str | None = None, **fields: object) -> Case:
    """A shipped case read from ``path``, under ``law``, with dotted ``fields`` replaced (``limits__x`` for
    ``limits.x``)."""
    case = read_case(path, {k.replace("__", "."): v for k, v in fields.items()})
    return case.with_law(law) if law is not None else case


def solved(path: Path, placement: str | None = None, law: str | None = None, **fields: object) -> Solution:
    """The answer of a shipped case (see :func:`shipped`), solved once per test process."""
    return _solved(str(path), placement, law, json.dumps(fields, sort_keys=True))


@cache
def _solved(path: str, placement: str | None, law: str | None, fields: str) -> Solution:
    return solve(shipped(Path(path), law, **json.loads(fields)), placement)


@pytest.fixture(scope="session")
def case():
    return read_case(PUBLISHED_CASE)


@pytest.fixture(scope="session")
def published_solution():
    return solved(PUBLISHED_CASE, "published")


@pytest.fixture(scope="session")
def free_solution():
    return solved(PUBLISHED_CASE, "free")
