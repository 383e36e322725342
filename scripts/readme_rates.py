"""Rewrite the at-the-line's-rate table in docs/rates.md and the trade-off figures in docs/.

    python scripts/readme_rates.py

For both drive cases at three rates: the least RMS motor torque (``min-rms-torque``) and the least
energy from the supply (``min-energy``), each against the baseline (the max-SPM plan with the spare time
in the transfer dwell). The table between ``<!-- rates:begin -->`` and ``<!-- rates:end -->`` is
replaced; ``docs/tradeoff-<case>.png`` is the figure of ``pressplan tradeoff CASE --spm START:max:7``.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from readme_block import replace_block

from planning.cli import main
from planning.model.case_file import read_case
from planning.solver.objectives import solve_at_rate
from planning.solver.optimize import solve

ROOT = Path(__file__).resolve().parents[1]
RATES = {"wang2023-side-panel-drive": (5.0, 7.0, 8.5), "cup-2000kN-drive": (20.0, 30.0, 38.0)}


def table() -> str:
    lines = [
        "| case | SPM | RMS torque, optimised [kN m] | baseline | saving | energy per stroke, optimised [kJ] "
        "| baseline | saving |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, rates in RATES.items():
        case = read_case(ROOT / "cases" / f"{name}.yaml")
        fastest = solve(case)
        for rate in rates:
            rms = solve_at_rate(case.with_objective("min-rms-torque", rate), fastest=fastest)
            energy = solve_at_rate(case.with_objective("min-energy", rate), fastest=fastest)
            lines.append(
                f"| `{name}` | {rate:g} | {rms.drive.rms_motor_torque_Nm / 1e3:.2f} | "
                f"{rms.at_rate.baseline.drive.rms_motor_torque_Nm / 1e3:.2f} | "
                f"{rms.saving_pct('rms_motor_torque_Nm'):.1f} % | "
                f"{energy.drive.supply_energy_kJ:.1f} | {energy.at_rate.baseline.drive.supply_energy_kJ:.1f} | "
                f"{energy.saving_pct('supply_energy_kJ'):.1f} % |"
            )
    return "\n".join(lines) + "\n"


def figures() -> None:
    starts = {"wang2023-side-panel-drive": 5.0, "cup-2000kN-drive": 20.0}
    with tempfile.TemporaryDirectory() as tmp:
        for name, start in starts.items():
            out = Path(tmp) / name
            args = ["tradeoff", str(ROOT / "cases" / f"{name}.yaml"), "--spm", f"{start}:max:7", "--out", str(out)]
            if main(args) != 0:
                raise SystemExit(f"pressplan tradeoff failed on {name}")
            (ROOT / "docs" / f"tradeoff-{name}.png").write_bytes((out / "tradeoff.png").read_bytes())


def run() -> None:
    rows = table()
    replace_block("rates", rows)
    figures()


if __name__ == "__main__":
    run()
