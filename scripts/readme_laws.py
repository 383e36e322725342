"""Rewrite the law-comparison table in docs/results.md from `pressplan laws` on the published case.

    python scripts/readme_laws.py

The table between ``<!-- laws:begin -->`` and ``<!-- laws:end -->`` is replaced by the command's
``laws.md``; tests/test_laws.py checks that the README still matches a fresh run.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from readme_block import replace_block

from planning.cli import main

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "wang2023-side-panel.yaml"


def run() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "laws"
        if main(["laws", str(CASE), "--out", str(out)]) != 0:
            raise SystemExit("pressplan laws failed")
        table = (out / "laws.md").read_text(encoding="utf-8")
    replace_block("laws", table)


if __name__ == "__main__":
    run()
