"""How long the shipped press line takes: whole ``pressplan line cases/tandem-line/line.yaml`` processes
(with its figure), median of 3; target: under 30 s on 2 cores (issue 43). Writes the ``line`` block of
benchmarks/RESULTS.md.

    python benchmarks/bench_line.py
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from results_section import write_section  # benchmarks/ is the script's folder

ROOT = Path(__file__).resolve().parents[1]
LINE = ROOT / "cases" / "tandem-line" / "line.yaml"
RUNS = 3
TARGET_S = 30.0


def timed(exe: str, out: Path) -> float:
    t = time.perf_counter()
    done = subprocess.run([exe, "line", str(LINE), "--out", str(out)], stdout=subprocess.DEVNULL)
    if done.returncode != 0:
        raise SystemExit(f"pressplan line: exit {done.returncode}")
    return time.perf_counter() - t


def main() -> None:
    exe = str(Path(sys.executable).with_name("pressplan"))
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "line"
        times = [timed(exe, out) for _ in range(RUNS)]
        result = json.loads((out / "line_result.json").read_text())
    block = "\n".join(
        [
            "## The press line (`python benchmarks/bench_line.py`)",
            "",
            f"`pressplan line cases/tandem-line/line.yaml` (4 presses, 5 robots, with `line_timing.png`), whole "
            f"processes on {os.cpu_count()} cores, median of {RUNS}; target under {TARGET_S:g} s:",
            "",
            "| line | strokes/min | bottleneck | wall [s] | runs [s] |",
            "|---|---:|---|---:|---|",
            f"| {result['line']} | {result['spm']:.3f} | {result['bottleneck']['kind']} "
            f"{result['bottleneck']['name']} | {statistics.median(times):.1f} | "
            + ", ".join(f"{t:.1f}" for t in times)
            + " |",
        ]
    )
    write_section("<!-- line:begin -->", "<!-- line:end -->", block)
    print(block)


if __name__ == "__main__":
    main()
