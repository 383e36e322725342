"""Speed of the drive's electrical side: drive solves with storage and a grid limit beside the same drive solve
without (paired: the variants take turns, in-process with the NLPs built, medians); writes its section of
benchmarks/RESULTS.md (between the ``grid`` markers, at the end). Run ``python benchmarks/bench_grid.py`` from the
project root where pressplan is installed."""

from __future__ import annotations

import statistics
import time
from pathlib import Path

from results_section import write_section  # benchmarks/ is the script's folder

ROOT = Path(__file__).resolve().parents[1]
RUNS = 5
BEGIN, END = "<!-- grid:begin -->", "<!-- grid:end -->"  # after the web section: bench_solve.py keeps it
VARIANTS = [  # (case file, label, overrides)
    ("cup-2000kN-drive.yaml", "the drive alone", {}),
    ("cup-2000kN-drive.yaml", "grid limit 400 kW, no storage", {"drive.grid.peak_power_kW": 400.0}),
    (
        "cup-2000kN-drive.yaml",
        "grid limit 400 kW, storage 2 kJ (the storage's energy row binds)",
        {"drive.grid.peak_power_kW": 400.0, "drive.storage.usable_energy_kJ": 2.0},
    ),
    (
        "cup-2000kN-drive.yaml",
        "grid limit 400 kW, storage 200 kJ",
        {"drive.grid.peak_power_kW": 400.0, "drive.storage.usable_energy_kJ": 200.0},
    ),
    ("wang2023-side-panel-drive.yaml", "the drive alone", {}),
    (
        "wang2023-side-panel-drive.yaml",
        "storage 500 kJ, losses",
        {
            "drive.storage.usable_energy_kJ": 500.0,
            "drive.converter_efficiency": 0.97,
            "drive.motor.copper_loss_at_rated_kW": 40.0,
        },
    ),
]


def main() -> None:
    from planning.model.case_file import read_case
    from planning.solver.optimize import solve

    cases = [read_case(ROOT / "cases" / name, overrides) for name, _, overrides in VARIANTS]
    spm = [solve(case).plan.spm for case in cases]  # warm-up: every NLP built
    times: list[list[float]] = [[] for _ in cases]
    for _ in range(RUNS):
        for k, case in enumerate(cases):
            t = time.perf_counter()
            solve(case)
            times[k].append(time.perf_counter() - t)
    medians = [statistics.median(t) for t in times]
    lines = [
        "## The drive's electrical side (`python benchmarks/bench_grid.py`)",
        "",
        f"In-process solves with the NLPs built, the variants taking turns, median of {RUNS}; the ratio divides by",
        "the same case's drive solve without the new keys (target for storage with a grid limit: at most 2).",
        "",
        "| case | variant | SPM | solve [s] | ratio |",
        "|---|---|---:|---:|---:|",
    ]
    base = {}
    for (name, label, _), s, m in zip(VARIANTS, spm, medians, strict=True):
        base.setdefault(name, m)
        lines.append(f"| `{name}` | {label} | {s:.3f} | {m:.3f} | {m / base[name]:.2f} |")
    block = "\n".join(lines)
    write_section(BEGIN, END, block)
    print(block)


if __name__ == "__main__":
    main()
