"""Shared fixtures: the published case, and its solutions solved once per test session."""

from __future__ import annotations

from pathlib import Path

import pytest

from planning.model.case_file import read_case
from planning.solver.optimize import solve

ROOT = Path(__file__).resolve().parents[1]
PUBLISHED_CASE = ROOT / "cases" / "wang2023-side-panel.yaml"


@pytest.fixture(scope="session")
def case():
    return read_case(PUBLISHED_CASE)


@pytest.fixture(scope="session")
def published_solution(case):
    return solve(case, "published")


@pytest.fixture(scope="session")
def free_solution(case):
    return solve(case, "free")
