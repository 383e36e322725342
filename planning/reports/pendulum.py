"""The files of a pendulum plan (``planner.mode: pendulum``): ``result.json``, ``summary.txt``,
``trajectory.csv`` (the crank's own angle and its signed speed, time 0 at the forward swing's start) and the
figure ``swing.png`` (or ``--format``'s) (the swings against time and against crank angle); with robots the
figure ``interference.png`` (the slide above each tool's need in both windows) and ``robot_cams.csv``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from planning.model.case import RPM, Case
from planning.model.pendulum import SWINGS, TWO_PI, hold_angles
from planning.reports.folder import write_json, write_table
from planning.reports.report import MAX_ROWS, columns_at, drive_block, trajectory_columns
from planning.reports.robots import robot_lines, robots_block
from planning.solver.pendulum import PendulumSolution
from planning.solver.solution import ENERGY, GRID_PEAK

KEY_NAMES = ("closing", "draw_start", "draw_end", "opening")
PENDULUM_FILES = (  # what a pendulum solve owns
    "result.json",
    "summary.txt",
    "trajectory.csv",
    "swing.*",
    "interference.*",
    "robot_cams.csv",
)


def pendulum_result(solution: PendulumSolution, case: Case) -> dict[str, Any]:
    """``result.json``'s data: the rate, the swing's ends and standstills, each swing's speeds and key points,
    the rotary stroke's rate under the same limits and the gain, every check."""
    plan, verification = solution.plan, solution.evaluation.verification
    p = plan.parameters
    swings = {}
    for name, params in zip(SWINGS, (p.forward, p.backward), strict=True):
        keys = plan.forward_keys if name == "forward" else plan.backward_keys
        times = plan.key_times(name)
        h = case.machine.height(np.array(keys))
        swings[name] = {
            "time_s": float(params.duration),
            "draw_speed_rpm": float(params.draw_speed) / RPM,
            "feed_peak_rpm": float(params.feed_peak_speed) / RPM,
            "return_peak_rpm": float(params.return_peak_speed) / RPM,
            "key_points": [
                {"name": k, "angle_deg": math.degrees(a), "time_s": float(t), "height_mm": float(hh)}
                for k, a, t, hh in zip(KEY_NAMES, keys, times, h, strict=True)
            ],
        }
    rotary = {"spm": solution.rotary_spm, "gain_percent": None if solution.gain is None else 100 * solution.gain}
    drive = solution.evaluation.drive
    if solution.rotary_spm is None:
        rotary["reason"] = solution.rotary_reason
    return {
        "case": case.name,
        "title": case.title,
        "mode": "pendulum",
        "motion_law": plan.motion_law,
        "status": "verified" if verification.passed else "unverified",
        "spm": plan.spm,
        "cycle_time_s": plan.period,
        "strokes_per_cycle": 2,
        "swing": {
            "start_deg": math.degrees(float(p.swing_start)),
            "end_deg": math.degrees(float(p.swing_end)),
            "turn_end_s": float(p.turn_end_s),
            "turn_start_s": float(p.turn_start_s),
            "safety_height_mm": case.process.safety_height_mm,
            "die_height_mm": case.limits.die_height_mm,
            **({"hold": _hold(case)} if case.hold_angle is not None else {}),
        },
        "swings": swings,
        "rotary": rotary,
        **({"drive": {**drive_block(solution, case), "per": "cycle of two strokes"}} if drive is not None else {}),
        **({"power": {**drive.power.as_dict(), "per": "cycle of two strokes"}} if drive and drive.power else {}),
        **({"at_rate": _at_rate(solution)} if solution.at_rate is not None else {}),
        **({"robots": robots_block(solution, case)} if case.robots is not None else {}),
        "verification": {
            "passed": verification.passed,
            "samples": verification.samples,
            "step_s": verification.step_s,
            "binding": [c.name for c in verification.binding()],
            "checks": [c.as_dict() for c in verification.checks],
        },
        "solver": {
            "iterations": plan.solver.iterations,
            "starts": plan.solver.starts,
            "wall_time_s": plan.solver.wall_time_s,
        },
    }


def _hold(case: Case) -> dict[str, Any]:
    """A hold on each swing: its time [s], height [mm above BDC] and crank angle on each swing [deg]."""
    forward, backward = (TWO_PI - u if k else u for k, u in enumerate(hold_angles(case)))
    return {
        "time_s": case.process.hold_time_s,
        "height_mm": case.hold_height_mm,
        "forward_deg": math.degrees(forward),
        "backward_deg": math.degrees(backward),
    }


def _at_rate(solution: PendulumSolution) -> dict[str, Any]:
    """``result.json``'s ``at_rate`` block: the objective, the rate, the fastest swing's, the figure weighed (the
    RMS motor torque [N m], the supply energy a stroke [kJ], or the grid's peak [kW]) of the plan and of the
    baseline."""
    at = solution.at_rate
    key = {"min-rms-torque": "rms_motor_torque_Nm", "min-grid-peak": GRID_PEAK}.get(at.objective, ENERGY)
    return {
        "objective": at.objective,
        "target_spm": at.target_spm,
        "fastest_spm": at.fastest_spm,
        "figure": key,
        "value": solution.figure(key),
        "baseline_value": at.baseline.figure(key),
        "baseline": "the fastest swings, then the crank standing at theta_s for the spare time",
        "saving_pct": solution.saving_pct(key),
        "improved_on_baseline": at.improved,
        "baseline_failed": [c.name for c in at.baseline.evaluation.verification.failures()],
    }


def _rate_line(a: dict[str, Any]) -> str:
    """The summary's line of a plan at the line's rate."""
    what, unit = {
        "rms_motor_torque_Nm": ("RMS motor torque", "N m"),
        GRID_PEAK: ("grid peak", "kW"),
    }.get(a["figure"], ("supply energy", "kJ a stroke"))
    failed = a["baseline_failed"]
    return (
        f"  {a['objective']} at {a['target_spm']:g} strokes/min (the swings make at most {a['fastest_spm']:.3f}): "
        f"{what} {a['value']:.1f} {unit} against {a['baseline_value']:.1f} of the fastest swings then standing, "
        f"{a['saving_pct']:.1f} % less"
        + (f" (the baseline's own check fails {', '.join(failed)}: a comparison only)" if failed else "")
    )


def pendulum_summary(r: dict[str, Any]) -> str:
    """The summary ``pressplan solve`` prints for a pendulum plan."""
    s, f, b = r["swing"], r["swings"]["forward"], r["swings"]["backward"]
    lines = [
        f"{r['case']}: {r['spm']:.3f} strokes/min in pendulum strokes, two swings in {r['cycle_time_s']:.4f} s "
        f"({r['motion_law']}, {r['status']})",
        f"  the crank swings from {s['start_deg']:.2f} deg through BDC to {s['end_deg']:.2f} deg and back "
        f"({s['end_deg'] - s['start_deg']:.2f} deg), standing {s['turn_end_s']:.4f} s and {s['turn_start_s']:.4f} s "
        "at the ends",
    ]
    if "hold" in s:
        hold = s["hold"]
        lines.append(
            f"  each swing holds {hold['time_s']:g} s at {hold['height_mm']:g} mm above BDC, the crank standing at "
            f"{hold['forward_deg']:.2f} deg forward and {hold['backward_deg']:.2f} deg backward"
        )
    for name, sw in (("forward", f), ("backward", b)):
        keys = ", ".join(f"{k['name']} {k['angle_deg']:.2f} deg" for k in sw["key_points"])
        lines.append(
            f"  {name} swing {sw['time_s']:.4f} s: draw {sw['draw_speed_rpm']:.3f} rpm, peaks "
            f"{sw['feed_peak_rpm']:.3f} / {sw['return_peak_rpm']:.3f} rpm; {keys}"
        )
    rot = r["rotary"]
    if "at_rate" in r:
        lines.append(_rate_line(r["at_rate"]))
    elif rot["spm"] is not None:
        lines.append(
            f"  the rotary stroke under the same limits: {rot['spm']:.3f} strokes/min; the swing makes "
            f"{abs(rot['gain_percent']):.1f} % {'more' if rot['gain_percent'] >= 0 else 'fewer'} strokes"
        )
    else:
        lines.append(f"  the rotary stroke under the same limits: no plan ({rot['reason']})")
    d = r.get("drive")
    if d:
        lines.append(
            f"  motor: peak torque {d['peak_motor_torque_Nm']:.0f} N m ({d['peak_torque_use_pct']:.1f} % of its "
            f"envelope), RMS {d['rms_motor_torque_Nm']:.0f} N m ({d['rms_torque_use_pct']:.1f} % of rated), peak power "
            f"{d['peak_motor_power_kW']:.1f} kW; per stroke {d['energy_drawn_kJ'] / 2:.2f} kJ drawn, "
            f"{-d['energy_returned_kJ'] / 2:.2f} kJ returned"
        )
    lines += _power_lines(r) + robot_lines(r)
    v = r["verification"]
    lines.append(f"  binding: {', '.join(v['binding']) or 'none'}")
    failed = [c for c in v["checks"] if not c["passed"]]
    lines.append(
        f"  verified on {v['samples']} points (step {1e3 * v['step_s']:.3f} ms): "
        + ("all checks pass" if not failed else f"{len(failed)} checks fail: " + ", ".join(c["name"] for c in failed))
    )
    sv = r["solver"]
    lines.append(f"  solver: {sv['iterations']} iterations, {sv['starts']} starts, {sv['wall_time_s']:.3f} s")
    return "\n".join(lines)


def _power_lines(r: dict[str, Any]) -> list[str]:
    """With the drive's electrical side: the grid's energy and peak and the losses, a stroke's (a cycle's over
    its two strokes)."""
    p = r.get("power")
    if not p:
        return []
    storage = (
        f", with the storage {p['grid_peak_kW']:.1f} kW (it swings {p['storage_swing_kJ']:.2f} of "
        f"{p['storage_usable_kJ']:.2f} kJ)"
        if p["storage_usable_kJ"] > 0
        else ""
    )
    return [
        f"  grid: {p['grid_energy_kJ'] / 2:.2f} kJ a stroke ({p['grid_energy_kWh_per_1000_strokes']:.2f} kWh per "
        f"1000 strokes), mean {p['mean_grid_power_kW']:.1f} kW; peak without storage {p['bus_peak_kW']:.1f} kW"
        + storage,
        f"  losses a stroke: copper {p['copper_loss_kJ'] / 2:.2f}, converter {p['converter_loss_kJ'] / 2:.2f}, gear "
        f"{p['gear_loss_kJ'] / 2:.2f}, storage {p['storage_loss_kJ'] / 2:.2f}, braking resistor "
        f"{p['resistor_loss_kJ'] / 2:.2f} kJ",
    ]


def pendulum_columns(solution: PendulumSolution, case: Case) -> dict[str, np.ndarray]:
    """``trajectory.csv``'s columns: the crank's own angle and signed speed over one cycle of two swings."""
    evaluation = solution.evaluation
    return columns_at(evaluation, case, evaluation.rows(MAX_ROWS))


def pendulum_writers(solution: PendulumSolution, case: Case, figure_format: str | None) -> dict[str, Any]:
    """The pendulum plan's files: name -> writer; the figure ``swing.<figure_format>`` (None: no figure)."""
    result = pendulum_result(solution, case)
    columns = pendulum_columns(solution, case)
    table = np.column_stack(list(columns.values()))
    writers = {
        "result.json": lambda p: write_json(p, result),
        "summary.txt": lambda p: p.write_text(pendulum_summary(result) + "\n", encoding="utf-8"),
        "trajectory.csv": lambda p: write_table(p, table, trajectory_columns(case)),
    }
    if figure_format is not None:
        writers[f"swing.{figure_format}"] = lambda p: _save_swing(result, columns, p)
        if case.robots is not None:
            writers[f"interference.{figure_format}"] = lambda p: _save_interference(result, columns, p)
    return writers


def _save_interference(result: dict[str, Any], columns: dict[str, np.ndarray], path: Path) -> None:
    from planning.reports.plots import interference_figure, save

    save(interference_figure(result, columns), path)


def _save_swing(result: dict[str, Any], columns: dict[str, np.ndarray], path: Path) -> None:
    from planning.reports.plots import save, swing_figure

    save(swing_figure(result, columns), path)


def pendulum_laws(case: Case) -> dict[str, Any]:
    """``pressplan laws`` of a pendulum case: each law with halves plans the swings (the optimal law says why not);
    per law the strokes, the cycle, the peak crank jerk and what binds, or why there is no plan."""
    from planning.model.case import CaseError
    from planning.model.laws import LAWS
    from planning.solver.outcomes import PlanningError
    from planning.solver.pendulum import solve_pendulum

    rows = []
    for law in LAWS:
        try:
            solution = solve_pendulum(case.with_law(law), compare=False)
        except (CaseError, PlanningError) as exc:
            reason = exc.message if isinstance(exc, CaseError) else exc.reason
            rows.append({"law": law, "status": "no plan", "message": reason})
            continue
        check = solution.evaluation.verification.check("crank_jerk")
        jerk = check.value if check is not None else None
        rows.append(
            {
                "law": law,
                "status": "verified",
                "spm": solution.plan.spm,
                "cycle_time_s": solution.plan.period,
                "peak_crank_jerk_rad_s3": jerk,
                "binding": [c.name for c in solution.evaluation.verification.binding()],
            }
        )
    return {"case": case.name, "mode": "pendulum", "laws": rows}


def pendulum_laws_text(data: dict[str, Any]) -> str:
    """The laws' table of a pendulum case."""
    lines = [
        f"{data['case']}: pendulum strokes under each motion law",
        "",
        f"  {'law':<18} {'strokes/min':>11}  binding",
    ]
    for r in data["laws"]:
        if r["status"] != "verified":
            lines.append(f"  {r['law']:<18} {'-':>11}  {r['message']}")
            continue
        lines.append(f"  {r['law']:<18} {r['spm']:11.3f}  {', '.join(r['binding']) or '-'}")
    return "\n".join(lines)


def pendulum_page_result(solution: PendulumSolution, case: Case) -> dict[str, Any]:
    """What the web page reads of a pendulum plan: ``result.json``'s data and the page's own fields (its key
    points with the slide's and the crank's speed, both swings' as ``name`` and ``name_back``; the swings and the
    standstills as the stage table's rows; the robot's windows and the draws as spans against time and crank
    angle; ``placement`` in words; the case's process and limits for the charts' limit lines)."""
    r = pendulum_result(solution, case)
    plan, d = solution.plan, solution.evaluation.samples
    points = []
    for swing, suffix in (("forward", ""), ("backward", "_back")):
        keys = plan.forward_keys if swing == "forward" else plan.backward_keys
        times = plan.key_times(swing)
        th, om, al, je = plan.profile.at_time(times)
        h, v, _, _ = case.machine.slider(th, om, al, je)
        for name, angle, t, hh, vv, w in zip(KEY_NAMES, keys, times, h, v, om, strict=True):
            points.append(
                {
                    "name": name + suffix,
                    "angle_deg": math.degrees(angle),
                    "time_s": float(t),
                    "height_mm": float(hh),
                    "slider_speed_mm_s": float(abs(vv)),
                    "direction": "down" if vv < 0 else "up",
                    "crank_speed_rpm": float(w) / RPM,
                }
            )
    f, b = (plan.key_times(s) for s in ("forward", "backward"))
    s = r["swing"]
    windows_time = [[float(f[3]), float(b[0])], [float(b[3]), plan.period], [0.0, float(f[0])]]
    low = min(math.degrees(plan.forward_keys[3]), math.degrees(plan.backward_keys[0]))
    high = max(math.degrees(plan.forward_keys[0]), math.degrees(plan.backward_keys[3]))
    return {
        **r,
        "placement": "pendulum",
        "binding_constraints": r["verification"]["binding"],
        "binding_over_cycle": [],
        "key_points": points,
        "stages": _swing_stages(solution, d),
        "transfer_window_s": plan.transfer_window(),
        "windows": {"time": windows_time, "angle": [[low, s["end_deg"]], [s["start_deg"], high]]},
        "draws": {
            "time": [[float(f[1]), float(f[2])], [float(b[1]), float(b[2])]],
            "angle": [sorted(math.degrees(k[i]) for i in (1, 2)) for k in (plan.forward_keys, plan.backward_keys)],
        },
        "process": {"safety_height_mm": case.process.safety_height_mm, "transfer_time_s": case.process.transfer_time_s},
        "limits": case.limits.model_dump(),
    }


def _swing_stages(solution: PendulumSolution, d: Any) -> list[dict[str, Any]]:
    """The stage table's rows of a pendulum plan: each swing and each standstill, with its peak crank speed."""
    plan = solution.plan
    spans = plan.swing_spans()
    rows = []
    edges = [
        ("forward swing", spans["forward"]),
        ("turn at theta_e", (spans["forward"][1], spans["backward"][0])),
        ("backward swing", spans["backward"]),
        ("turn at theta_s", (spans["backward"][1], plan.period)),
    ]
    for name, (t0, t1) in edges:
        inside = (d.t >= t0) & (d.t <= t1)
        th = plan.profile.at_time(np.array([t0, t1]))[0]
        peak = float(np.max(np.abs(d.omega[inside]), initial=0.0)) / RPM
        rows.append(
            {
                "name": name,
                "start_angle_deg": math.degrees(th[0]),
                "end_angle_deg": math.degrees(th[1]),
                "start_time_s": t0,
                "duration_s": t1 - t0,
                "peak_crank_speed_rpm": peak,
                "binding": [],
            }
        )
    return rows
