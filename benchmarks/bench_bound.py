"""What is possible, and what it costs to know: the grid bound, the certified upper bound on its grids and
the bracket (``pressplan bound --bracket``), each in a fresh process so that every NLP build counts.

Writes its section of benchmarks/RESULTS.md. Run: ``python benchmarks/bench_bound.py`` (about 3 minutes).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

from results_section import write_section  # benchmarks/ is the script's folder

ROOT = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- bound:begin -->", "<!-- bound:end -->"
PUBLISHED = "cases/wang2023-side-panel.yaml"
UPPER_MESHES = (360, 720, 1440, 2880)
BRACKETS = [  # (case file, overrides, label)
    (PUBLISHED, [], "published case, no jerk limit"),
    (PUBLISHED, ["--set", "limits.crank_jerk_rad_s3=3263"], "published case, crank jerk <= 3263 rad/s^3"),
    ("cases/link-drive-side-panel.yaml", [], "link drive (with its drive)"),
    ("cases/cup-2000kN-drive.yaml", [], "cup press with its drive"),
]


def _bound(args: list[str]) -> tuple[dict, float]:
    """``pressplan bound ARGS --json`` in a new process: its JSON and the process's wall time [s]."""
    t = time.perf_counter()
    out = subprocess.run(
        [sys.executable, "-m", "planning.cli", "bound", *args, "--json"],
        cwd=ROOT,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out), time.perf_counter() - t


def _in_process() -> list[tuple[int, float, float]]:
    """The certified upper bound of the published case on each grid: (intervals, SPM, seconds)."""
    sys.path.insert(0, str(ROOT))
    from planning.model.case_file import read_case
    from planning.solver.upper_bound import upper_bound

    case = read_case(ROOT / PUBLISHED)
    upper_bound(case, 96, 1)  # imports and first use
    rows = []
    for n in UPPER_MESHES:
        t = time.perf_counter()
        upper = upper_bound(case, n, 1)
        rows.append((n, upper.spm, time.perf_counter() - t))
    return rows


def main() -> None:
    lines = [
        "## What is possible: the bound, the certified upper bound, the bracket (`python benchmarks/bench_bound.py`)",
        "",
        "The certified upper bound of the published case on each grid, in process (convex relaxation, one piece",
        "per interval, 256 sub-pieces each); the grid bound (1440 intervals) is no upper bound:",
        "",
        "| intervals | certified upper bound [SPM] | time [s] |",
        "|---:|---:|---:|",
    ]
    for n, spm, seconds in _in_process():
        lines.append(f"| {n} | {spm:.5f} | {seconds:.2f} |")
    data, seconds = _bound([PUBLISHED])
    lines += ["", f"Grid bound, whole `pressplan bound` process: {data['spm']:.4f} SPM in {seconds:.2f} s.", ""]
    lines += [
        "`pressplan bound CASE --bracket` (whole process): the verified motion, the certified upper bound, their",
        "gap and the rounds it took (default tolerance 0.05 %):",
        "",
        "| case | verified [SPM] | certified upper [SPM] | gap [%] | within | rounds | time [s] |",
        "|---|---:|---:|---:|---|---:|---:|",
    ]
    for case, extra, label in BRACKETS:
        data, seconds = _bound([case, "--bracket", *extra])
        b = data["bracket"]
        lines.append(
            f"| {label} | {b['verified_spm']:.4f} | {b['upper_spm']:.4f} | {b['gap_pct']:.3f} | "
            f"{'yes' if b['met'] else 'no'} | {len(b['rounds'])} | {seconds:.1f} |"
        )
        print(lines[-1], flush=True)
    write_section(BEGIN, END, "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
