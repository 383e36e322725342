"""One marked section of benchmarks/RESULTS.md, rewritten by the benchmark that owns it (the rest kept)."""

from __future__ import annotations

from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "RESULTS.md"


def write_section(begin: str, end: str, body: str) -> None:
    """Put ``body`` between the markers ``begin`` and ``end`` of RESULTS.md (appended at the end, after the
    sections bench_solve.py keeps, when the markers are not there yet)."""
    text = RESULTS.read_text(encoding="utf-8")
    if begin not in text:
        text = text.rstrip("\n") + f"\n\n{begin}\n{end}\n"
    head, rest = text.split(begin)
    tail = rest.split(end)[1]
    RESULTS.write_text(f"{head}{begin}\n{body}\n{end}{tail}", encoding="utf-8")
