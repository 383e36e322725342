"""Sweeps that scale: a 160-point transfer-time sweep of the published case as a whole `pressplan sweep` process
with 1 and 2 workers (paired: one run each, in turn), and a 640-point one with 2 workers, read from each run's
timeline (sweep.json); writes its section of benchmarks/RESULTS.md (between the ``sweep`` markers). Run
``python benchmarks/bench_sweep.py [POINTS [LARGE]]`` from the project root where pressplan is installed (about
3.5 minutes on 2 cores at 160 and 640 points).

Target (issue 27): with 2 workers the wall at most 1.15 x (the points' solve times / 2) + 1.5 s; the serial part
(start-up, the second pass's finding, the writing) at most 2 s at 640 points.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from results_section import write_section  # benchmarks/ is the script's folder

ROOT = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- sweep:begin -->", "<!-- sweep:end -->"


def run(points: int, workers: int) -> dict:
    """One whole sweep process: its wall time and its timeline."""
    with tempfile.TemporaryDirectory() as tmp:
        args = [sys.executable, "-m", "planning.cli", "sweep", str(ROOT / "cases" / "wang2023-side-panel.yaml")]
        args += ["--vary", f"process.transfer_time_s=0.5:3.0:{points}", "--workers", str(workers), "--out", tmp]
        t = time.perf_counter()
        subprocess.run(args, cwd=ROOT, check=True, capture_output=True)
        wall = time.perf_counter() - t
        return {"process_s": wall, **json.loads(Path(tmp, "sweep.json").read_text())["timeline"]}


def main() -> None:
    points = int(sys.argv[1]) if len(sys.argv) > 1 else 160
    large = int(sys.argv[2]) if len(sys.argv) > 2 else 640
    runs = {workers: run(points, workers) for workers in (1, 2)}
    big = run(large, 2)
    two = runs[2]
    target = 1.15 * two["solve_time_sum_s"] / 2 + 1.5
    lines = [
        f"## Sweeps that scale (`python benchmarks/bench_sweep.py {points}`)",
        "",
        f"A {points}-point transfer-time sweep of the published case, a whole `pressplan sweep` process each, read",
        "from its timeline (`sweep.json`). Target with 2 workers: the timeline's wall at most 1.15 x (solve times",
        "/ 2) + 1.5 s.",
        "",
        "| workers | process [s] | timeline wall [s] | points/s | solve times [s] | start-up [s] | second pass "
        "(serial) [s] | writing [s] | serial [s] | efficiency |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for workers, r in runs.items():
        lines.append(
            f"| {workers} | {r['process_s']:.2f} | {r['wall_s']:.2f} | {r['points'] / r['wall_s']:.2f} | "
            f"{r['solve_time_sum_s']:.2f} | {r['startup_s']:.2f} | {r['second_pass_s']:.2f} "
            f"({r['second_pass_serial_s']:.2f}) | {r['writing_s']:.2f} | {r['serial_s']:.2f} | {r['efficiency']:.3f} |"
        )
    lines += [
        "",
        f"2 workers: wall {two['wall_s']:.2f} s against the target {target:.2f} s "
        f"({'met' if two['wall_s'] <= target else 'NOT met'}); speed-up over 1 worker "
        f"{runs[1]['wall_s'] / two['wall_s']:.2f}.",
        "",
        f"{large} points, 2 workers: wall {big['wall_s']:.2f} s, {big['points'] / big['wall_s']:.2f} points/s, solve "
        f"times {big['solve_time_sum_s']:.1f} s, efficiency {big['efficiency']:.3f}; "
        f"serial part {big['serial_s']:.2f} s "
        f"(start-up {big['startup_s']:.2f}, the second pass's finding {big['second_pass_serial_s']:.2f} of its "
        f"{big['second_pass_s']:.2f}, writing {big['writing_s']:.2f}; target at most 2 s: "
        f"{'met' if big['serial_s'] <= 2.0 else 'NOT met'}).",
    ]
    block = "\n".join(lines)
    write_section(BEGIN, END, block)
    print(block)


if __name__ == "__main__":
    main()
