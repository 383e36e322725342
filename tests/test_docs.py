"""The README and docs/: short enough to read, links that resolve, and every command output they show
as the command prints it today (``scripts/docs_outputs.py`` writes them; this fails when one is stale)."""

from __future__ import annotations

import functools
import importlib.util
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README_LIMIT_BYTES = 20_000


@functools.cache
def _docs_outputs():
    spec = importlib.util.spec_from_file_location("docs_outputs", ROOT / "scripts" / "docs_outputs.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks its module up
    spec.loader.exec_module(module)
    return module


def test_the_readme_is_short():
    assert len((ROOT / "README.md").read_bytes()) <= README_LIMIT_BYTES


SLOW_BLOCKS = ("pressplan line ",)  # commands of tens of seconds (a whole press line): their blocks in the slow tier


def _slow(command: str) -> bool:
    return command.startswith(SLOW_BLOCKS)
@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes


def test_every_shown_output_is_what_the_command_prints_now():
    docs = _docs_outputs()
    blocks = docs.fresh_outputs(keep=lambda command: not _slow(command))
    assert len(blocks) >= 8 and any(b.page.name == "README.md" for b, _ in blocks)
    stale = docs.stale(blocks)
    assert not stale, f"run `python scripts/docs_outputs.py` (or fix the code): {stale}"


@pytest.mark.slow
def test_every_shown_output_of_a_long_command_is_what_it_prints_now():
    docs = _docs_outputs()
    blocks = docs.fresh_outputs(keep=_slow)
    assert blocks
    stale = docs.stale(blocks)
    assert not stale, f"run `python scripts/docs_outputs.py` (or fix the code): {stale}"


@pytest.mark.parametrize(  # results.md (20 s of bounds) in the slow tier
    "part",
    [pytest.param(k, marks=pytest.mark.slow, id=f"results.md {k + 1}") for k in (0, 1)] + [2],
    ids=lambda part: "the other pages" if part == 2 else None,
)
def test_every_number_in_the_text_is_what_the_command_gives_now(part):
    """Each inline value as its command gives it now (in three parts the workers share, each command run
    once per part)."""
    docs = _docs_outputs()
    results = ROOT / "docs" / "results.md"
    pages = (results,) if part < 2 else tuple(p for p in docs.PAGES if p != results)
    commands = sorted({v.command for v in docs.values(pages)})
    mine = set(commands[part::2]) if part < 2 else set(commands)
    values = docs.fresh_values(pages, mine)
    assert len(values) >= 5
    stale = docs.stale(values)
    assert not stale, f"run `python scripts/docs_outputs.py` (or fix the code): {stale}"


def test_a_value_is_found_in_the_json():
    docs = _docs_outputs()
    data = {"laws": [{"law": "quintic", "spm": 11.97}, {"law": "optimal", "spm": 12.4}], "drive": {"x": [1, 2]}}
    assert docs.lookup(data, "laws.[law=optimal].spm") == 12.4
    assert docs.lookup(data, "drive.x.1") == 2
    assert docs.lookup({"d": {"peak [mm/s^2]": 3}}, "d.{peak [mm/s^2]}") == 3
    assert docs.evaluate({"n": [{"name": "a b", "v": 2.0}]}, "n.[name=a b].v * 100") == 200
    assert docs.evaluate({"t": [5, 23400.0]}, "t.1 / 1000") == 23.4
    assert docs.shown_like(13.0379, "13.04") == "13.04" and docs.shown_like(952.46, "952") == "952"


@pytest.mark.parametrize(
    ("shown", "now", "stale"),
    (
        ("12.123 strokes/min", "12.123 strokes/min", False),
        ("12.123 strokes/min", "12.124 strokes/min", False),  # the last digit, round-off across machines
        ("12.123 strokes/min", "12.125 strokes/min", True),
        ("12.124 strokes/min", "12.123 strokes/min", False),
        ("12.2 strokes/min", "12.123 strokes/min", False),  # shown to one decimal: 12.2 is within 0.1
        ("12.0 strokes/min", "12.123 strokes/min", True),
        ("binding: transfer time", "binding: slider acceleration", True),
        ("one line", "one line\nand another", True),
    ),
)
def test_a_number_changed_by_hand_is_stale(shown, now, stale):
    assert bool(_docs_outputs().differences(shown, now)) == stale


def test_links_resolve():
    for page in (ROOT / "README.md", *(ROOT / "docs").glob("*.md")):
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text(encoding="utf-8")):
            if target.startswith(("http://", "https://")):
                continue
            assert (page.parent / target).exists(), f"{page.name}: {target}"
