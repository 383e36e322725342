"""Rewrite the SPM-against-jerk-limit table of the optimal law in docs/results.md.

    python scripts/readme_jerk.py

For the published case and the small fast press: the optimal law at 1, 3, 10 and 100 times the improved
S-curve's own peak crank jerk (each from the plan of the tighter limit before it, which holds here),
each as % of the jerk-limited bound (``pressplan bound`` with that limit) and of the acceleration bound
(no jerk limit). The table between ``<!-- jerk:begin -->`` and
``<!-- jerk:end -->`` is replaced; tests/test_optimal.py checks the SPM rise with the limit.
"""

from __future__ import annotations

from pathlib import Path

from readme_block import replace_block

from planning.model.case_file import case_from_data, read_case
from planning.model.profile import max_abs_jerk
from planning.solver.bound import time_optimal_bound
from planning.solver.optimize import solve

ROOT = Path(__file__).resolve().parents[1]
CASES = ("wang2023-side-panel", "small-fast-cup")
FACTORS = (1, 3, 10, 100)


def jerk_rows(name: str) -> list[dict]:
    """The optimal law's SPM at each factor of the improved S-curve's peak crank jerk, with the bounds."""
    case = read_case(ROOT / "cases" / f"{name}.yaml")
    reference = max_abs_jerk(solve(case).plan.profile)
    free_bound = time_optimal_bound(case).spm
    rows, previous = [], None
    for factor in FACTORS:
        data = case.model_dump(exclude_none=True)
        data["limits"]["crank_jerk_rad_s3"] = factor * reference
        data["planner"] = {**data.get("planner", {}), "motion_law": "optimal"}
        limited = case_from_data(data, name)
        plan = solve(limited, neighbour=previous).plan  # the tighter limit's plan holds here: a start
        previous, spm = plan, plan.spm
        bound = time_optimal_bound(limited).spm
        rows.append(
            {"factor": factor, "jerk": factor * reference, "spm": spm, "jerk_bound": bound, "bound": free_bound}
        )
    return rows


def table() -> str:
    lines = [
        "| case | crank jerk limit [rad/s³] | × S-curve's peak | optimal SPM | % of the jerk-limited bound "
        "| % of the acceleration bound |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for name in CASES:
        for r in jerk_rows(name):
            lines.append(
                f"| `{name}` | {r['jerk']:.4g} | {r['factor']} | {r['spm']:.3f} | "
                f"{100 * r['spm'] / r['jerk_bound']:.1f} ({r['jerk_bound']:.3f}) | "
                f"{100 * r['spm'] / r['bound']:.1f} ({r['bound']:.3f}) |"
            )
    return "\n".join(lines) + "\n"


def run() -> None:
    rows = table()
    print(rows)
    replace_block("jerk", rows)


if __name__ == "__main__":
    run()
