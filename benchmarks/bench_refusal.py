"""How fast an impossible case is refused: key angles typed in radians (closing 1.05, draw start 2.44, draw
end 3.32, opening 5.24 on a 300/1000 mm press), and three other robot windows through BDC. Whole
``pressplan check`` and ``pressplan solve`` processes, median of 5 each; target: under 1 s. Writes the
``refusal`` block of benchmarks/RESULTS.md.

    python benchmarks/bench_refusal.py
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from results_section import write_section  # benchmarks/ is the script's folder

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
RUNS = 5
TARGET_S = 1.0


def timed(cmd: list[str]) -> float:
    t = time.perf_counter()
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    if done.returncode != 3:
        raise SystemExit(f"{' '.join(cmd)}: exit {done.returncode}, expected 3 (refused)")
    return time.perf_counter() - t


def main() -> None:
    from tests.test_first_hour import WINDOWS_THROUGH_BDC, window_case  # the cases the test refuses

    exe = str(Path(sys.executable).with_name("pressplan"))
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name in WINDOWS_THROUGH_BDC:
            path = window_case(Path(folder), name)
            check = statistics.median(timed([exe, "check", str(path)]) for _ in range(RUNS))
            solve = statistics.median(
                timed([exe, "solve", str(path), "--out", str(Path(folder) / "out")]) for _ in range(RUNS)
            )
            rows.append(f"| {name} | {check:.3f} | {solve:.3f} |")
    block = "\n".join(
        [
            f"Refused before solving (exit 3), whole processes, median of {RUNS}; target {TARGET_S:g} s "
            "(`python benchmarks/bench_refusal.py`):",
            "",
            "| robot window through BDC | `pressplan check` [s] | `pressplan solve` [s] |",
            "|---|---:|---:|",
            *rows,
            "",
        ]
    )
    write_section("<!-- refusal:begin -->", "<!-- refusal:end -->", block.rstrip("\n"))
    print(block)


if __name__ == "__main__":
    main()
