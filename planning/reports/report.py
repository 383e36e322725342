"""Plain-data views of a solved plan: the result dictionary, the dense trajectory, the summary text.

Every output file is a function of a :class:`~planning.solver.optimize.Solution` and its case; nothing here
solves or verifies again.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.case import KEY_POINT_NAMES, RPM, Case
from planning.model.cycle import HALVES
from planning.model.laws.improved_scurve import ImprovedSCurve
from planning.model.limits import draw_speed_bounds
from planning.model.limits.capacity import curve, has_curve, tonnage_use, torque_capacity_kNm
from planning.model.limits.draw_slide_speed import held_band
from planning.model.limits.slider_accel import SliderAccelLimit
from planning.model.outcome import Outcome
from planning.model.plan import Plan
from planning.model.profile import MAX_STEP_S, Profile
from planning.model.units import rounded_down
from planning.reports.robots import robot_columns, robot_lines, robot_values, robots_block
from planning.reports.source_solution import paper_solution
from planning.reports.stages import stage_table
from planning.solver.solution import ENERGY, GRID_PEAK, Solution
from planning.solver.verify import Evaluation
from planning.tolerances import BINDING_SHARE, CAP_SHARE, KNOT_TIME_S, SAME_RELATIVE
from press.dynamics import envelope_torque
from press.mechanism import Mechanism

TRAJECTORY_COLUMNS = (
    "time_s",
    "crank_angle_deg",
    "crank_speed_rpm",
    "crank_accel_rad_s2",
    "crank_jerk_rad_s3",
    "slider_height_mm",
    "slider_speed_mm_s",
    "slider_accel_mm_s2",
)
DRIVE_COLUMNS = ("crank_torque_Nm", "motor_speed_rpm", "motor_torque_Nm", "motor_power_kW")  # with a drive
POWER_COLUMNS = ("copper_loss_kW", "bus_power_kW", "grid_power_kW", "storage_energy_kJ")  # drive.electrical
# result.json's process: the motion modes' fields only where set (a rotary case's as before the modes)
MODE_FIELDS = ("hold_time_s", "hold_height_mm", "draw_slide_speed_mm_s")
MAX_ROWS = 200_000  # trajectory rows at most: a cycle longer than 200 s gets a step of period / MAX_ROWS


def sample_profile(profile: Profile, machine: Mechanism, max_step: float = MAX_STEP_S) -> np.ndarray:
    """A profile that is no solved plan's (the source's published solution, rebuilt) over its whole duration
    on a uniform time grid with step <= ``max_step`` [s] (at most :data:`MAX_ROWS` + 1 rows); columns as
    :data:`TRAJECTORY_COLUMNS`; the first and last rows are the profile's ends. A plan's rows come from its
    evaluation (:func:`trajectory`)."""
    n = min(int(math.ceil(profile.duration / max_step)), MAX_ROWS)
    t = np.linspace(0.0, profile.duration, n + 1)
    th, om, al, je = profile.at_time(profile.t0 + t)
    h, v, a, _ = machine.slider(th, om, al, je)
    return np.column_stack([t, np.degrees(th), om / RPM, al, je, h, v, a])


def trajectory_columns(case: Case) -> tuple[str, ...]:
    """The columns of ``trajectory.csv`` for ``case``."""
    columns = TRAJECTORY_COLUMNS
    if case.drive is not None:
        columns += DRIVE_COLUMNS + (POWER_COLUMNS if case.electrical else ())
    return columns + robot_columns(case)


def trajectory(solution: Solution, case: Case, most: int = MAX_ROWS) -> dict[str, np.ndarray]:
    """One full cycle of the plan from TDC on the uniform grid of its evaluation (at most ``most`` + 1 rows,
    evenly spaced), one array per column of ``trajectory.csv`` (:func:`trajectory_columns`: ``time_s``,
    ``crank_angle_deg``, ..., ``slider_accel_mm_s2``, and the drive's with a drive); the first and last
    samples are one period apart."""
    return columns_at(solution.evaluation, case, solution.evaluation.rows(most))


def columns_at(evaluation: Evaluation, case: Case, rows: np.ndarray) -> dict[str, np.ndarray]:
    """The columns of ``trajectory.csv`` (:func:`trajectory_columns`) at the evaluation's samples ``rows``."""
    d = evaluation.samples
    columns = [d.t, np.degrees(d.theta), d.omega / RPM, d.alpha, d.jerk, d.h, d.v, d.a]
    if case.drive is not None:
        s = d.drive_state
        columns += [s["crank_torque_Nm"], s["motor_speed_rad_s"] / RPM, s["motor_torque_Nm"], s["motor_power_W"] / 1e3]
        if case.electrical:
            c = evaluation.power_columns
            columns += [c["copper_loss_W"] / 1e3, c["bus_power_W"] / 1e3, c["grid_power_W"] / 1e3]
            columns.append(c["storage_energy_J"] / 1e3)
    columns += robot_values(d, case)
    return {name: np.asarray(column)[rows] for name, column in zip(trajectory_columns(case), columns, strict=True)}


def key_points(solution: Solution) -> list[dict[str, Any]]:
    """The four key points: name, angle [deg], time from TDC [s], height [mm], slider speed [mm/s]
    (magnitude; ``direction`` down/up), crank speed [rpm] (the evaluation's, at their exact times)."""
    plan = solution.plan
    dense = solution.evaluation.samples
    motion = dense.key_motion
    return [
        {
            "name": name,
            "angle_deg": float(math.degrees(plan.key_angles[i])),
            "time_s": float(dense.key_times[i]),
            "height_mm": float(motion["h"][i]),
            "slider_speed_mm_s": float(abs(motion["v"][i])),
            "direction": "down" if motion["v"][i] < 0 else "up",
            "crank_speed_rpm": float(motion["omega"][i] / RPM),
        }
        for i, name in enumerate(KEY_POINT_NAMES)
    ]


def segments(solution: Solution) -> list[dict[str, Any]]:
    """Every segment of the profile from TDC: name, duration [s], start/end angle [deg], jerk [rad/s^3]."""
    prof = solution.plan.profile
    knots = prof.knots()
    out = []
    jerk = prof.at_time(prof.knot_times)[3]  # right-continuous: the start of each segment
    jerk_end = prof.at_time(prof.knot_times[1:] - SAME_RELATIVE * np.maximum(prof.durations, KNOT_TIME_S))[3]
    for k, seg in enumerate(prof.segments):
        T = float(seg.duration)
        j_start, j_end = float(jerk[k]), float(jerk_end[k])
        out.append(
            {
                "name": seg.name,
                "duration_s": T,
                "start_time_s": float(prof.knot_times[k]),
                "start_angle_deg": float(math.degrees(knots[k, 0])),
                "end_angle_deg": float(math.degrees(knots[k + 1, 0])),
                "jerk_rad_s3": j_start if abs(j_start) >= abs(j_end) else j_end,
                "jerk_start_rad_s3": j_start,
                "jerk_end_rad_s3": j_end,
            }
        )
    return out


def binding(solution: Solution) -> list[str]:
    """Names of the inequality checks that sit at their limit (``Check.binds``)."""
    return [c.name for c in solution.verification.binding()]


def result_dict(solution: Solution, case: Case) -> dict[str, Any]:
    """Everything ``result.json`` holds (engineering units in the keys)."""
    plan = solution.plan
    p = plan.parameters
    ver = solution.verification
    accel = ver.check(SliderAccelLimit.id)
    result = {
        "case": case.name,
        "spm": plan.spm,
        "cycle_time_s": plan.period,
        "status": Outcome.VERIFIED if ver.passed else Outcome.UNVERIFIED,
        "verified": ver.passed,
        "placement": plan.placement,
        "motion_law": plan.motion_law,
        "structure": plan.structure,
        "draw_speed_rpm": float(p.draw_speed) / RPM,
        "draw_speed_given": case.process.draw_speed_rpm is not None,
        "draw_speed_highest_rpm": min(draw_speed_bounds(case).values()) / RPM,
        "transfer_speed_rpm": float(p.transfer_speed) / RPM,
        "feed_peak_speed_rpm": float(p.feed_peak_speed) / RPM,
        "return_peak_speed_rpm": float(p.return_peak_speed) / RPM,
        "peak_crank_jerk_rad_s3": float(max(p.peak_jerks())),
        "peak_crank_accel_rad_s2": float(max(p.peak_accelerations())),
        "law_parameter": float(p.law_parameter),
        "half_durations_s": {k: float(p.half(k)[0]) for k in HALVES} if hasattr(p, "half") else None,
        "segment_count": len(plan.profile.segments),
        "transfer_dwell_s": float(p.transfer_dwell),
        **({"hold": hold_block(plan, case)} if getattr(p, "has_hold", False) else {}),
        **({"draw_slide_speed": slide_draw_block(solution, case)} if case.free_draw else {}),
        "transfer_window_s": plan.transfer_window(),
        "max_abs_slider_accel_mm_s2": accel.value,
        "binding_constraints": binding(solution),
        "process": case.process.model_dump(exclude={k for k in MODE_FIELDS if getattr(case.process, k) is None}),
        "limits": case.limits.model_dump(),
        "key_points": key_points(solution),
        "segments": segments(solution),
        "paper_solution": paper_solution(plan) if plan.motion_law == ImprovedSCurve.name else None,
        **({"drive": drive_block(solution, case)} if case.drive is not None else {}),
        **({"capacity": capacity_block(case)} if case.press.capacity is not None else {}),
        **({"power": solution.drive.power.as_dict()} if solution.drive and solution.drive.power else {}),
        **({"robots": robots_block(solution, case)} if case.robots is not None else {}),
        **objective_block(solution, case),
        "verification": {
            "passed": ver.passed,
            "step_s": ver.step_s,
            "samples": ver.samples,
            "checks": [c.as_dict() for c in ver.checks],
        },
        "solver": {
            "iterations": plan.solver.iterations,
            "wall_time_s": plan.solver.wall_time_s,
            "starts": plan.solver.starts,
            "status": plan.solver.status,
        },
    }
    evaluation = solution.evaluation
    table = stage_table(result["segments"], evaluation, evaluation.rows(MAX_ROWS))  # after the segments: their stages
    ordered = {}
    for key, value in result.items():
        ordered[key] = value
        if key == "segments":
            ordered.update(table)
    return ordered


def drive_block(solution: Solution, case: Case) -> dict[str, Any]:
    """The ``drive`` block of ``result.json``: what the motor must give over the cycle (the figures the
    solve computed), and its limits (the motor's copper loss only where the drive states one: without the
    electrical keys the block is what it was before them)."""
    motor = case.drive.motor.model_dump()
    if not motor["copper_loss_at_rated_kW"]:
        del motor["copper_loss_at_rated_kW"]
    return {**solution.drive.as_dict(), "motor": motor, "gear_ratio": case.drive.gear_ratio}


CURVE_POINTS = 101  # points of the tonnage curve result.json carries (the figure draws it from them)


def capacity_block(case: Case) -> dict[str, Any]:
    """The ``capacity`` block of ``result.json``: the press's rating, its crank torque capacity [kN m], its
    tonnage curve on :data:`CURVE_POINTS` heights ``[[height mm, force kN], ...]`` (``press.capacity``) and,
    with a forming force table, where the table comes closest to the curve."""
    c = case.press.capacity
    out: dict[str, Any] = {
        "rated_force_kN": c.rated_force_kN,
        "rated_distance_mm": c.rated_distance_mm,
        "crank_torque_capacity_kNm": torque_capacity_kNm(case),
        "tonnage_curve": None,
    }
    if has_curve(case):
        heights, forces = curve(case)
        h = np.linspace(float(heights[0]), float(heights[-1]), CURVE_POINTS)
        out["tonnage_curve"] = [[float(x), float(y)] for x, y in zip(h, np.interp(h, heights, forces), strict=True)]
        if case.process.forming_force_kN is not None:
            use, at, force, allowed = tonnage_use(case)
            out["tonnage_use"] = {"share": use, "height_mm": at, "force_kN": force, "allowed_kN": allowed}
    return out


def objective_block(solution: Solution, case: Case) -> dict[str, Any]:
    """The objective keys of ``result.json``: ``objective``, ``target_spm``; at a target rate also the
    ``baseline``'s figures (the max-SPM planner with the spare time given to the transfer: its RMS motor
    torque, energy from the supply per stroke, robot's window and SPM), the ``saving_pct`` of the plan's
    (in the ``drive`` block) against them, and the ``fastest_spm`` the limits allow."""
    out: dict[str, Any] = {"objective": case.planner.objective, "target_spm": case.planner.target_spm}
    a = solution.at_rate
    if a is not None:
        out["energy_kJ"] = solution.energy_kJ
        out["energy_at"] = "bus" if solution.drive.power is not None else "shaft"
        b = a.baseline
        out["baseline"] = {
            "rms_motor_torque_Nm": b.drive.rms_motor_torque_Nm,
            "supply_energy_kJ": b.drive.supply_energy_kJ,
            "energy_kJ": b.energy_kJ,
            "transfer_window_s": b.plan.transfer_window(),
            "spm": b.plan.spm,
        }
        out["saving_pct"] = {
            "rms_torque": solution.saving_pct("rms_motor_torque_Nm"),
            "energy": solution.saving_pct(ENERGY),
        }
        if b.drive.power is not None and solution.drive.power is not None:  # the grid's side (Case.electrical)
            out["baseline"]["grid_peak_kW"] = b.drive.power.grid_peak_kW
            out["saving_pct"]["grid_peak"] = solution.saving_pct(GRID_PEAK)
        out["improved_on_baseline"] = a.improved
        out["fastest_spm"] = a.fastest_spm
    return out


def summary_text(result: dict[str, Any]) -> str:
    """The console summary of a result dictionary."""
    r = result
    lines = _plan_lines(r) + _key_point_lines(r) + _stage_lines(r) + robot_lines(r) + _drive_lines(r)
    lines += _objective_lines(r)
    lines.append("")
    lines.append("  binding: " + (", ".join(r["binding_constraints"]) or "none"))
    v = r["verification"]
    lines.append(
        f"  verified on {v['samples']} points (step {v['step_s'] * 1e3:.3f} ms): "
        + ("all checks pass" if v["passed"] else "FAILED")
    )
    lines.append(
        f"  solver: {r['solver']['iterations']} iterations, {r['solver']['starts']} starts, "
        f"{r['solver']['wall_time_s']:.3f} s"
    )
    return "\n".join(lines)


def _plan_lines(r: dict[str, Any]) -> list[str]:
    """The plan in a few lines: strokes, where theta1 and theta4 fall, speeds, peaks, the halves, the window."""
    hd = r["half_durations_s"]
    return [
        f"{r['case']}: {r['spm']:.3f} strokes/min, cycle {r['cycle_time_s']:.4f} s "
        f"({r['motion_law']}, {r['placement']} placement, {r['status']})",
        f"  theta1 (closing) in {r['structure']['closing']}, theta4 (opening) in {r['structure']['opening']}",
        f"  crank speed: dwell {r['transfer_speed_rpm']:.3f} rpm, feed peak {r['feed_peak_speed_rpm']:.3f} rpm, "
        f"draw {r['draw_speed_rpm']:.3f} rpm{_draw_words(r)}, return peak {r['return_peak_speed_rpm']:.3f} rpm",
        f"  peaks: crank acceleration {r['peak_crank_accel_rad_s2']:.3f} rad/s^2, "
        f"crank jerk {r['peak_crank_jerk_rad_s3']:.3f} rad/s^3",
        f"  halves: feed {hd['feed_accel']:.4f} / {hd['feed_decel']:.4f} s, return {hd['return_accel']:.4f} / "
        f"{hd['return_decel']:.4f} s; draw {_draw_s(r):.4f} s"
        if hd
        else f"  free profile: {r['segment_count']} segments of constant jerk (no halves), "
        f"|jerk| <= {r['limits']['crank_jerk_rad_s3']:g} rad/s^3",
        f"  {'theta4 -> theta1' if r.get('robots') else 'robot window theta4 -> theta1'}: "
        f"{r['transfer_window_s']:.4f} s; "
        f"max |slider accel| {r['max_abs_slider_accel_mm_s2']:.1f} mm/s^2",
        *_hold_lines(r),
        *_slide_draw_lines(r),
    ]


def _slide_draw_lines(r: dict[str, Any]) -> list[str]:
    """A draw at constant slide speed: where the plan holds it, and what caps it in the rest of the draw (none
    without one)."""
    d = r.get("draw_slide_speed")
    if not d:
        return []
    if d["held_from_deg"] is None:
        return [f"  draw at {d['set_mm_s']:g} mm/s slide speed: never within 0.1 % of it (the crank's limits)"]
    capped = f"; elsewhere in the draw, {', '.join(d['capped_by'])} cap it" if d["capped_by"] else ""
    return [
        f"  draw at {d['set_mm_s']:g} mm/s slide speed: within 0.1 % from {d['held_from_deg']:.2f} to "
        f"{d['held_to_deg']:.2f} deg ({d['held_share_pct']:.0f} % of the draw's angle){capped}"
    ]


def _draw_s(r: dict[str, Any]) -> float:
    """The draw's time [s]: the cycle's but the halves', the dwell's and a hold's (brake and standstill)."""
    hold = r.get("hold")
    held = hold["brake_s"] + hold["time_s"] if hold else 0.0
    return r["cycle_time_s"] - sum(r["half_durations_s"].values()) - r["transfer_dwell_s"] - held


def _hold_lines(r: dict[str, Any]) -> list[str]:
    """A hold's line: the brake from the draw's end and the standstill (none without a hold)."""
    hold = r.get("hold")
    if not hold:
        return []
    return [
        f"  hold: the crank brakes {hold['brake_s']:.4f} s from theta3 to {hold['angle_deg']:.3f} deg and stands "
        f"{hold['time_s']:.4f} s, the slide {hold['height_mm']:g} mm above BDC"
    ]


def hold_block(plan: Plan, case: Case) -> dict[str, float]:
    """``result.json``'s hold: its time [s], the slide's height [mm above BDC], the crank's angle [deg], the
    brake's time [s] from theta3 and the planned stop's crank angles [deg] (theta3 to the return's rise's end:
    the least crank speed does not hold there)."""
    p = plan.parameters
    start, end = plan.planned_stop()
    return {
        "time_s": float(p.hold_time),
        "height_mm": case.hold_height_mm,
        "angle_deg": math.degrees(float(p.hold_angle)),
        "brake_s": float(p.brake_duration),
        "stop_from_deg": math.degrees(start),
        "stop_to_deg": math.degrees(end),
    }


def slide_draw_block(solution: Any, case: Case) -> dict[str, Any]:
    """``result.json``'s draw at constant slide speed: the set speed [mm/s], the longest stretch of the draw the
    plan holds it within :data:`~planning.tolerances.DRAW_SPEED_BAND` (``held_from_deg`` ... ``held_to_deg``, its
    share of the draw's angle) and the limits binding in the rest of the draw (the crank's and the motor's, which
    cap it there)."""
    dense = solution.evaluation.samples
    run = held_band(case, dense.theta, dense.v)
    _, th2, th3, _ = case.key_angles
    t2, t3 = float(dense.key_times[1]), float(dense.key_times[2])
    if run is None:
        held, share, rest = (None, None), 0.0, [(t2, t3)]
    else:
        ends = np.mod(dense.theta[list(run)], 2 * math.pi)
        held, share = tuple(np.degrees(ends).tolist()), 100 * (ends[1] - ends[0]) / (th3 - th2)
        rest = [(t2, float(dense.t[run[0]])), (float(dense.t[run[1]]), t3)]
    return {
        "set_mm_s": case.process.draw_slide_speed_mm_s,
        "held_from_deg": held[0],
        "held_to_deg": held[1],
        "held_share_pct": float(share),
        "capped_by": capping(dense, case, rest),
    }


def capping(dense: Any, case: Case, spans: list[tuple[float, float]]) -> list[str]:
    """The crank's, the slide's and the motor's limits (case fields) within :data:`~planning.tolerances.CAP_SHARE`
    of their value somewhere in the ``spans`` ``(start, end)`` [s from TDC]: what caps a draw at constant slide
    speed (the motor's torque against its envelope, which falls as ``base / speed`` above the base speed)."""
    lim = case.limits
    window = np.zeros(dense.t.shape, dtype=bool)
    for start_s, end_s in spans:
        window |= (dense.t >= start_s) & (dense.t <= end_s)
    figures = [
        ("limits.crank_speed_rpm", np.abs(dense.omega) / RPM, lim.crank_speed_rpm),
        ("limits.crank_accel_rad_s2", np.abs(dense.alpha), lim.crank_accel_rad_s2),
        ("limits.crank_jerk_rad_s3", np.abs(dense.jerk), lim.crank_jerk_rad_s3),
        ("limits.slider_accel_mm_s2", np.abs(dense.a), lim.slider_accel_mm_s2),
        ("limits.die_speed_mm_s", np.where(dense.h <= lim.die_height_mm, np.abs(dense.v), 0.0), lim.die_speed_mm_s),
    ]
    if dense.drive_state is not None:
        motor, speed = case.drive.motor, np.abs(dense.drive_state["motor_speed_rad_s"])
        envelope = envelope_torque(speed, motor.peak_torque_Nm, motor.base_speed_rpm * RPM)
        torque = np.abs(dense.drive_state["motor_torque_Nm"]) * motor.peak_torque_Nm / envelope  # the envelope's use
        figures += [
            ("drive.motor.peak_torque_Nm", torque, motor.peak_torque_Nm),
            ("drive.motor.max_speed_rpm", speed / RPM, motor.max_speed_rpm),
        ]
    return [
        name
        for name, values, limit in figures
        if limit is not None and window.any() and np.max(values[window]) >= limit * (1 - CAP_SHARE)
    ]


def _draw_words(r: dict[str, Any]) -> str:
    """Whose the draw speed is: the case's, or the planner's choice up to the highest the limits allow (a draw at
    constant slide speed: the crank's speed at theta3)."""
    if r.get("draw_slide_speed"):
        return " (at theta3: the slide's speed is set)"
    if r.get("draw_speed_given", True):
        return " (given)"
    if r["draw_speed_rpm"] >= r["draw_speed_highest_rpm"] * (1 - BINDING_SHARE):
        return " (the highest the limits allow)"
    return f" (the planner's choice; the limits allow up to {rounded_down(r['draw_speed_highest_rpm'])})"


def _key_point_lines(r: dict[str, Any]) -> list[str]:
    lines = [
        "",
        f"  {'key point':<11} {'angle deg':>9} {'time s':>8} {'height mm':>9} {'slider mm/s':>11} {'crank rpm':>9}",
    ]
    for k in r["key_points"]:
        lines.append(
            f"  {k['name']:<11} {k['angle_deg']:9.2f} {k['time_s']:8.4f} {k['height_mm']:9.1f} "
            f"{k['slider_speed_mm_s']:8.1f} {k['direction']:<2} {k['crank_speed_rpm']:9.3f}"
        )
    return lines


def _stage_lines(r: dict[str, Any]) -> list[str]:
    if not r.get("stages"):
        return []
    lines = ["", f"  {'stage':<11} {'from deg':>9} {'to deg':>8} {'time s':>9} {'peak rpm':>9}  binding there"]
    for st in r["stages"]:
        lines.append(
            f"  {st['name']:<11} {st['start_angle_deg']:9.2f} {st['end_angle_deg']:8.2f} "
            f"{st['duration_s']:9.4f} {st['peak_crank_speed_rpm']:9.3f}  {', '.join(st['binding']) or '-'}"
        )
    if r["binding_over_cycle"]:
        lines.append(f"  {'the cycle':<11} {'':>9} {'':>8} {'':>9} {'':>9}  {', '.join(r['binding_over_cycle'])}")
    return lines


def _drive_lines(r: dict[str, Any]) -> list[str]:
    """The motor's figures and, with the drive's electrical side, the grid's."""
    lines = []
    if "drive" in r:
        d = r["drive"]
        lines += [
            "",
            f"  drive: peak motor torque {d['peak_motor_torque_Nm'] / 1e3:.2f} kN m "
            f"at {d['peak_motor_torque_angle_deg']:.1f} deg "
            f"({d['peak_torque_use_pct']:.1f} % of the envelope), RMS {d['rms_motor_torque_Nm'] / 1e3:.2f} kN m "
            f"({d['rms_torque_use_pct']:.1f} % of rated), peak power {d['peak_motor_power_kW']:.0f} kW, "
            f"top motor speed {d['peak_motor_speed_rpm']:.0f} rpm",
            f"  energy per stroke: drawn {d['energy_drawn_kJ']:.1f} kJ, returned {d['energy_returned_kJ']:.1f} kJ, "
            f"net {d['energy_net_kJ']:.1f} kJ; forming work {d['forming_work_kJ']:.1f} kJ "
            f"(crank work {d['crank_work_kJ']:.1f} kJ)",
        ]
    if "power" in r:
        p = r["power"]
        shaved = (
            f", with the storage {p['grid_peak_kW']:.0f} kW (it swings {p['storage_swing_kJ']:.1f} of "
            f"{p['storage_usable_kJ']:.1f} kJ)"
            if p["storage_usable_kJ"] > 0
            else ""
        )
        limit = f"; grid limit {p['grid_limit_kW']:g} kW" if p["grid_limit_kW"] is not None else ""
        lines += [
            f"  grid: {p['grid_energy_kJ']:.1f} kJ per stroke ({p['grid_energy_kWh_per_1000_strokes']:.1f} kWh per "
            f"1000 strokes), mean {p['mean_grid_power_kW']:.0f} kW; peak without storage {p['bus_peak_kW']:.0f} kW"
            + shaved
            + limit,
            f"  losses per stroke: copper {p['copper_loss_kJ']:.1f}, converter {p['converter_loss_kJ']:.1f}, gear "
            f"{p['gear_loss_kJ']:.1f}, storage {p['storage_loss_kJ']:.1f}, braking resistor "
            f"{p['resistor_loss_kJ']:.1f} kJ",
        ]
    return lines


ENERGY_AT = {"bus": "at the DC bus, losses counted", "shaft": "at the motors' shaft"}


def _objective_lines(r: dict[str, Any]) -> list[str]:
    """At the line's rate: the objective's figures against the baseline's."""
    if not r.get("baseline"):
        return []
    b, saving, d = r["baseline"], r["saving_pct"], r["drive"]
    where = "robot's window" if r.get("motion_law") == "optimal" else "transfer dwell"  # (the optimal law: no dwell)
    return [
        "",
        f"  objective {r['objective']} at {r['target_spm']:g} strokes/min (the limits allow up to "
        f"{r['fastest_spm']:.3f}): RMS motor torque {d['rms_motor_torque_Nm'] / 1e3:.2f} kN m, "
        f"energy from the supply {r['energy_kJ']:.1f} kJ per stroke ({ENERGY_AT[r['energy_at']]})",
        f"  baseline (max-SPM plan, spare time in the {where}; window {b['transfer_window_s']:.3f} s): "
        f"RMS {b['rms_motor_torque_Nm'] / 1e3:.2f} kN m, energy {b['energy_kJ']:.1f} kJ; "
        f"saving {saving['rms_torque']:.1f} % "
        f"RMS torque, {saving['energy']:.1f} % energy"
        + (
            f", {saving['grid_peak']:.1f} % grid peak ({b['grid_peak_kW']:.0f} -> {r['power']['grid_peak_kW']:.0f} kW)"
            if "grid_peak" in saving
            else ""
        )
        + ("" if r["improved_on_baseline"] else " (no solve beat the baseline: it is the plan)"),
    ]
