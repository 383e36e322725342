"""Every motion law on one case, beside the time-optimal bound: ``pressplan laws``.

Each law is solved and verified like ``pressplan solve`` (the case's placement); the figures of merit
come from the verified plan's dense trajectory (uniform grid of at most 1 ms from TDC), except the
peak crank jerk, which is the closed-form peak of the law (``planning.solver.verify``). The bound is the
case's time-optimal bound on its grid (with the crank-jerk limit when the case sets one; a restriction,
which approaches the optimum from below); each law's share is of the certified upper bound
(``planning.solver.upper_bound``), which no motion within the limits exceeds, so no share is above 100 %;
the bracket is the best verified law against it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.case import RPM, Case, CaseError
from planning.model.case_file import CaseFileError
from planning.model.laws import LAWS
from planning.model.outcome import Outcome
from planning.model.profile import max_abs_jerk
from planning.reports.report import MAX_ROWS, TRAJECTORY_COLUMNS, binding, trajectory
from planning.solver.ahead import SIDE_BY_SIDE_WORKERS, Ahead, Call
from planning.solver.bound import Bound, time_optimal_bound
from planning.solver.optimize import solve
from planning.solver.outcomes import PlanningError
from planning.solver.solution import Solution
from planning.solver.upper_bound import UpperBound, upper_bound

# the certified upper bound beside the laws: a grid that takes about half a second on the published case
# (13.044 there; the default 1440 intervals of ``pressplan bound --certified`` give 13.044 in about 1.2 s)
LAWS_UPPER_POINTS = 720
LAWS_UPPER_PIECES = 1

COLUMNS = (
    ("law", "law", ""),
    ("spm", "SPM", ".3f"),
    ("share_of_upper_bound_pct", "% of upper bound", ".1f"),
    ("peak_crank_speed_rpm", "peak crank speed [rpm]", ".2f"),
    ("peak_crank_accel_rad_s2", "peak crank accel [rad/s²]", ".3f"),
    ("peak_crank_jerk_rad_s3", "peak crank jerk [rad/s³]", ".1f"),
    ("peak_slider_jerk_mm_s3", "peak slider jerk [mm/s³]", ".0f"),
    ("rms_crank_accel_rad_s2", "RMS crank accel [rad/s²]", ".3f"),
    ("continuity", "continuous up to", ""),
)
DRIVE_COLUMNS = (  # with a drive, after the others
    ("peak_motor_torque_Nm", "peak motor torque [N m]", ".0f"),
    ("rms_motor_torque_Nm", "RMS motor torque [N m]", ".0f"),
    ("energy_net_kJ", "net energy [kJ/stroke]", ".1f"),
)


def law_row(
    law: str, solution: Solution, case: Case, bound: Bound | None, upper: UpperBound | None = None
) -> dict[str, Any]:
    """The figures of merit of one verified plan (engineering units in the keys), from its evaluation's
    uniform samples; its share of the grid ``bound`` and of the certified ``upper`` bound (never above 100 %)."""
    plan = solution.plan
    dense, rows = solution.evaluation.samples, solution.evaluation.rows(MAX_ROWS)
    t, om, al = dense.t[rows], dense.omega[rows] / RPM, dense.alpha[rows]
    slider_jerk = dense.slide_jerk[rows]
    sq = al**2
    mean_sq = float(np.sum(np.diff(t) * (sq[1:] + sq[:-1]) / 2)) / plan.period  # time average (trapezoids)
    return {
        "law": law,
        "status": Outcome.VERIFIED,
        "spm": plan.spm,
        "cycle_time_s": plan.period,
        "share_of_bound_pct": 100.0 * plan.spm / bound.spm if bound is not None else None,
        "share_of_upper_bound_pct": 100.0 * plan.spm / upper.spm if upper is not None else None,
        "peak_crank_speed_rpm": float(np.max(om)),
        "peak_crank_accel_rad_s2": float(np.max(np.abs(al))),
        "peak_crank_jerk_rad_s3": max_abs_jerk(plan.profile),
        "peak_slider_jerk_mm_s3": float(np.max(np.abs(slider_jerk))),
        "rms_crank_accel_rad_s2": float(math.sqrt(mean_sq)),
        "continuity": LAWS[law].continuity,
        **_drive_columns(solution, case),
        "law_parameter": float(plan.parameters.law_parameter) if LAWS[law].parameter else None,
        "law_parameter_name": LAWS[law].parameter.name if LAWS[law].parameter else None,
        "placement": plan.placement,
        "structure": plan.structure,
        "binding_constraints": binding(solution),
    }


def _drive_columns(solution: Solution, case: Case) -> dict[str, Any]:
    if solution.drive is None:
        return {}
    fig = solution.drive.as_dict()
    return {key: fig[key] for key, _, _ in DRIVE_COLUMNS}


def _columns(data: dict[str, Any]) -> tuple:
    return COLUMNS + (DRIVE_COLUMNS if data.get("drive") else ())


def compare_laws(
    case: Case, laws: tuple[str, ...] = tuple(LAWS), side_by_side_workers: bool = False
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Solve ``case`` under each law; returns the comparison dictionary and, per law with a verified
    plan, its trajectory (columns :data:`planning.reports.report.TRAJECTORY_COLUMNS`).

    A law without a verified plan gets a row with its ``status`` (the outcome) and ``message`` and no numbers;
    when the bound has no answer the laws are still compared (``bound`` None, ``bound_failure`` says why). The
    bounds and the laws' solves are independent: with ``side_by_side_workers`` (``pressplan laws``), on two cores,
    they are made side by side in two forked workers (``planning.solver.ahead``: the same solves, the same numbers;
    their NLPs built there, not kept here), taken in order; the optimal law's after the improved S-curve's row,
    whose peak jerk it may plan under. Else one after another here."""
    with Ahead(SIDE_BY_SIDE_WORKERS if side_by_side_workers else 0) as ahead:
        bound_call = ahead.start(time_optimal_bound, case)
        upper_call = ahead.start(upper_bound, case, LAWS_UPPER_POINTS, LAWS_UPPER_PIECES)
        plain = {law: _start_law(ahead, law, *_variant(case, law)) for law in laws if not LAWS[law].needs_jerk_limit}
        bound, bound_failure = _taken(bound_call)
        upper, _ = _taken(upper_call)
        rows, tables = [], {}
        for law in laws:
            variant, note, call = plain.get(law) or _start_law(ahead, law, *_jerk_limited_or_why(case, law, rows))
            rows.append(_row(law, variant, note, call, tables, bound, upper))
    verified = [r for r in rows if Outcome.of(r["status"]).succeeded]
    best = max(verified, key=lambda r: r["spm"]) if verified else None
    bracket = None
    if best is not None and upper is not None:
        gap = 100.0 * (upper.spm - best["spm"]) / upper.spm
        bracket = {"verified_spm": best["spm"], "law": best["law"], "upper_spm": upper.spm, "gap_pct": gap}
    return {
        "case": case.name,
        "placement": case.planner.placement,
        "bound": bound.as_dict() if bound is not None else None,
        "upper_bound": upper.as_dict() if upper is not None else None,
        "bracket": bracket,
        **({"bound_failure": bound_failure} if bound_failure else {}),
        "jerk_limited_bound": case.limits.crank_jerk_rad_s3 is not None,
        **({"drive": True} if case.drive is not None else {}),
        "laws": rows,
    }, tables


def _taken(call: Call) -> tuple[Any, str | None]:
    """A bound's value and None, or None and why there is none."""
    try:
        return call.take(), None
    except PlanningError as exc:
        return None, str(exc)


def _variant(case: Case, law: str) -> tuple[Case | None, dict[str, Any]]:
    """``case`` under ``law``, or None and the reason (a law that cannot plan the case's draw: at constant slide
    speed)."""
    try:
        return case.with_law(law), {}
    except CaseError as exc:
        return None, {"reason": str(exc)}


def _jerk_limited_or_why(case: Case, law: str, rows: list[dict[str, Any]]) -> tuple[Case | None, dict[str, Any]]:
    """The optimal law's case (:func:`_jerk_limited`), or None and the reason (e.g. an objective at a rate, which
    it does not plan)."""
    try:
        return _jerk_limited(case, law, rows)
    except (CaseError, CaseFileError) as exc:
        return None, {"reason": str(exc)}


def _start_law(ahead: Ahead, law: str, variant: Case | None, note: dict) -> tuple[Case | None, dict, Call | None]:
    """The law's solve started in ``ahead``'s workers (none without a case to solve)."""
    return variant, note, ahead.start(solve, variant) if variant is not None else None


def _row(
    law: str,
    variant: Case | None,
    note: dict[str, Any],
    call: Call | None,
    tables: dict[str, np.ndarray],
    bound: Bound | None,
    upper: UpperBound | None,
) -> dict[str, Any]:
    """The law's row from its solve ``call`` (its trajectory into ``tables``), or its outcome and message."""
    note = dict(note)
    outcome, message = Outcome.VERIFIED, ""
    if variant is None:
        outcome, message = Outcome.BAD_INPUT, note.pop("reason")
    else:
        try:
            sol = call.take()
        except PlanningError as exc:
            outcome, message = exc.outcome, str(exc)
    if not outcome.succeeded:
        return {"law": law, "status": outcome, "message": message, "continuity": LAWS[law].continuity, **note}
    columns = trajectory(sol, variant)
    tables[law] = np.column_stack([columns[name] for name in TRAJECTORY_COLUMNS])
    return {**law_row(law, sol, variant, bound, upper), **note}


def _jerk_limited(case: Case, law: str, rows: list[dict[str, Any]]) -> tuple[Case | None, dict[str, Any]]:
    """The case for the optimal law: at the case's crank-jerk limit, else at the peak crank jerk of the
    improved S-curve's plan (a row already in ``rows``); the note says which."""
    from planning.model.case_file import case_from_data
    from planning.model.laws import DEFAULT_LAW

    if case.limits.crank_jerk_rad_s3 is not None:
        return case.with_law(law), {"jerk_limit_rad_s3": case.limits.crank_jerk_rad_s3, "jerk_limit_from": "case"}
    ref = next((r for r in rows if r["law"] == DEFAULT_LAW and Outcome.of(r["status"]).succeeded), None)
    if ref is None:
        return None, {"reason": f"no jerk limit: the case sets none and the {DEFAULT_LAW} law has no plan"}
    data = case.model_dump(exclude_none=True)
    data["limits"]["crank_jerk_rad_s3"] = ref["peak_crank_jerk_rad_s3"]
    data["planner"] = {**data.get("planner", {}), "motion_law": law}
    data["planner"].pop("law_parameter", None)
    note = {"jerk_limit_rad_s3": ref["peak_crank_jerk_rad_s3"], "jerk_limit_from": f"the {DEFAULT_LAW} plan's peak"}
    return case_from_data(data, case.name), note


def _cell(value: Any, fmt: str) -> str:
    """A table cell: ``value`` formatted, or a dash when there is none (no bound)."""
    if value is None:
        return "–"
    return format(value, fmt) if fmt else str(value)


def laws_markdown(data: dict[str, Any]) -> str:
    """The comparison as a Markdown table, with the bound in the last row."""
    columns = _columns(data)
    head = "| " + " | ".join(title for _, title, _ in columns) + " |"
    rule = "|" + "|".join("---" if fmt == "" else "---:" for _, _, fmt in columns) + "|"
    lines = [head, rule]
    for row in data["laws"]:
        if not Outcome.of(row["status"]).succeeded:
            lines.append(f"| {row['law']} | failed: {row['message']} |" + " |" * (len(columns) - 2))
            continue
        cells = [_cell(row[key], fmt) for key, _, fmt in columns]
        lines.append("| " + " | ".join(cells) + " |")
    b, u = data["bound"], data.get("upper_bound")
    tail = " |" * (len(columns) - len(COLUMNS))
    if b is not None:
        kind = "jerk-limited bound" if data["jerk_limited_bound"] else "time-optimal bound"
        share = _cell(100.0 * b["spm"] / u["spm"] if u else None, ".1f")
        peak = f"{b['peak_crank_speed_rpm']:.2f}"
        lines.append(f"| *{kind} (grid)* | {b['spm']:.3f} | {share} | {peak} | | | | | shape free |{tail}")
    if u is not None:
        lines.append(f"| *certified upper bound* | {u['spm']:.3f} | 100.0 | | | | | | |{tail}")
    notes = [f"{r['law']}: {_jerk_note(r)}." for r in data["laws"] if r.get("jerk_limit_rad_s3") is not None]
    return "\n".join(lines) + "\n" + "".join(f"\n{n}\n" for n in notes)


def laws_text(data: dict[str, Any]) -> str:
    """The console table of a comparison."""
    b, u = data["bound"], data.get("upper_bound")
    bound_text = f"grid bound {b['spm']:.3f} SPM" if b is not None else f"no bound ({data.get('bound_failure')})"
    upper_text = f", certified upper bound {u['spm']:.3f} SPM" if u is not None else ", no certified upper bound"
    lines = [
        f"{data['case']}: motion laws ({data['placement']} placement), {bound_text}"
        + (" (with the crank-jerk limit)" if data["jerk_limited_bound"] else "")
        + upper_text,
        f"  {'law':<17} {'SPM':>7} {'% upper':>7} {'rpm max':>8} {'acc max':>8} {'jerk max':>9} "
        f"{'slider jerk':>11} {'acc RMS':>8}  continuous up to",
    ]
    for r in data["laws"]:
        if not Outcome.of(r["status"]).succeeded:
            lines.append(f"  {r['law']:<17} failed: {r['message']}")
            continue
        lines.append(
            f"  {r['law']:<17} {r['spm']:7.3f} {_cell(r['share_of_upper_bound_pct'], '7.1f')} "
            f"{r['peak_crank_speed_rpm']:8.2f} "
            f"{r['peak_crank_accel_rad_s2']:8.3f} {r['peak_crank_jerk_rad_s3']:9.1f} "
            f"{r['peak_slider_jerk_mm_s3']:11.0f} {r['rms_crank_accel_rad_s2']:8.3f}  {r['continuity']}"
        )
        if data.get("drive"):
            lines.append(
                f"  {'':<17} motor: peak {r['peak_motor_torque_Nm']:.0f} N m, RMS {r['rms_motor_torque_Nm']:.0f} N m, "
                f"net {r['energy_net_kJ']:.1f} kJ/stroke"
            )
    lines.append("  units: rpm, rad/s^2, rad/s^3, mm/s^3; RMS over one cycle")
    if data.get("bracket"):
        br = data["bracket"]
        lines.append(
            f"  bracket: {br['verified_spm']:.3f} SPM verified ({br['law']}) ... {br['upper_spm']:.3f} SPM certified "
            f"upper bound: no motion within the limits makes more; gap {br['gap_pct']:.2f} %"
        )
    lines += [f"  {r['law']}: {_jerk_note(r)}" for r in data["laws"] if r.get("jerk_limit_rad_s3") is not None]
    return "\n".join(lines)


def _jerk_note(row: dict[str, Any]) -> str:
    return f"planned under |crank jerk| <= {row['jerk_limit_rad_s3']:.4g} rad/s^3 ({row['jerk_limit_from']})"
