"""What a planned line writes: its summary, its result JSON, its trajectory and cams on the line's master, the
timing chart (``planning.reports.plots.line_figure``); the files ``pressplan line`` owns (:data:`LINE_FILES`).

The line's master: time ``t`` [s] from 0 to the period, angle ``360 t / T`` [deg]. Station k's own master
(its ``cam_table.csv`` with ``pressplan solve`` at the line's rate) is the line's shifted by its phase offset:
``t_k = t - phi_k`` (a controller's ``MasterOffset`` of ``phi_k / T * 360`` deg). A line with a pendulum press
repeats every two master cycles (its swings alternate, ``planning.solver.pendulum_line``): its trajectory and
cams run over both, the master from 0 to 720 deg.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from planning.reports.folder import write_atomic, write_json, write_table
from planning.solver.line import LineSolution, horizon_s, own_period_s, robot_position_mm, station_starts_s

LINE_FILES = ("line_summary.txt", "line_result.json", "line_trajectory.csv", "line_cams.csv", "line_timing.png")
STEP_S = 1e-3  # [s] the line trajectory's step (the stations' verification grid's)
CAM_POINTS = 3600


def station_times(solution: LineSolution, k: int, t_s: np.ndarray) -> np.ndarray:
    """Station ``k``'s own time [s, within its cycle: two master cycles for a pendulum press] at the line's master
    times ``t_s``."""
    return np.mod(t_s - solution.offsets_s[k], solution.at_line[k].plan.period)


def station_state(solution: LineSolution, k: int, t_s: np.ndarray) -> dict[str, np.ndarray]:
    """Station ``k`` at line times ``t_s``: its crank angle [deg] and speed [rad/s], its slide height [mm], each
    robot's position on its path [mm], the highest need [mm] and the clearance [mm] (the slide minus that need;
    where no tool needs any, the slide's height, as in ``trajectory.csv``)."""
    station, plan = solution.line.stations[k], solution.at_line[k].plan
    local = station_times(solution, k, t_s)
    theta, omega, _, _ = plan.profile.at_time(local)
    slide = station.case.machine.height(theta)
    out = {"crank_deg": np.mod(np.degrees(theta), 360.0), "crank_speed": omega, "slide_mm": slide}
    needs = []
    for robot in station.case.robots_on_path:
        out[f"{robot.name}_mm"] = robot_position_mm(station, solution.at_line[k], robot.name, local)
        needs.append(robot.curve.need(out[f"{robot.name}_mm"]))
    out["needed_height_mm"] = np.max(needs, axis=0)
    out["clearance_mm"] = slide - out["needed_height_mm"]
    return out


def trajectory(solution: LineSolution, step_s: float = STEP_S) -> tuple[np.ndarray, tuple[str, ...]]:
    """One master cycle (two with a pendulum press) at ``step_s``: time, master angle, each station's crank
    angle, slide height, robots' positions and least clearance."""
    t = np.arange(0.0, horizon_s(solution.at_line, solution.period_s), step_s)
    columns = {"time_s": t, "master_deg": t / solution.period_s * 360.0}
    for k, station in enumerate(solution.line.stations):
        state = station_state(solution, k, t)
        columns[f"{station.name}_crank_angle_deg"] = state["crank_deg"]
        columns[f"{station.name}_slide_mm"] = state["slide_mm"]
        for robot in station.case.robots_on_path:
            columns[f"{station.name}_{robot.name}_position_mm"] = state[f"{robot.name}_mm"]
        columns[f"{station.name}_needed_height_mm"] = state["needed_height_mm"]
        columns[f"{station.name}_clearance_mm"] = state["clearance_mm"]
    return np.column_stack(list(columns.values())), tuple(columns)


def cams(solution: LineSolution, points: int = CAM_POINTS) -> tuple[np.ndarray, tuple[str, ...]]:
    """Each station's crank cam on the line's master (its angle modulo 360 deg and its slope [deg/deg]) over
    one master cycle, ``points`` points (two cycles with a pendulum press, twice the points)."""
    cycles = round(horizon_s(solution.at_line, solution.period_s) / solution.period_s)
    master = np.arange(cycles * points) * (360.0 / points)
    t = master / 360.0 * solution.period_s
    rate = 2 * math.pi / solution.period_s  # [rad/s] of the master
    columns = {"master_deg": master}
    for k, station in enumerate(solution.line.stations):
        state = station_state(solution, k, t)
        columns[f"{station.name}_crank_angle_deg"] = state["crank_deg"]
        columns[f"{station.name}_dcrank_dmaster"] = state["crank_speed"] / rate
    return np.column_stack(list(columns.values())), tuple(columns)


def result(solution: LineSolution, settings: dict[str, Any] | None = None) -> dict[str, Any]:
    """``line_result.json``: the line, each station (alone, at the line, its offset, its robots' starts on the
    line's master, its least clearance on the 1 ms grid, its case fields set for the run), each robot (its loop
    and its stretches), the bottleneck, the checks; ``settings``: the run's ``--set`` fields."""
    settings = settings or {}
    names = {s.name for s in solution.line.stations}
    sets: dict[str, dict[str, Any]] = {}
    for field, value in settings.items():
        first, _, rest = field.partition(".")
        if first in names:
            sets.setdefault(first, {})[rest] = value
    line, period = solution.line, solution.period_s
    t = np.arange(0.0, horizon_s(solution.at_line, period), STEP_S)
    stations = []
    for k, station in enumerate(line.stations):
        plan = solution.at_line[k].plan
        offset = solution.offsets_s[k]
        state = station_state(solution, k, t)
        clearance = np.where(state["needed_height_mm"] > 0, state["clearance_mm"], np.inf)  # where a tool needs any
        least = int(np.argmin(clearance))
        needed = bool(np.isfinite(clearance[least]))
        stations.append(
            {
                "name": station.name,
                "case": str(station.path),
                "mechanism": station.case.press.mechanism,
                "mode": station.case.planner.mode,
                "spm_alone": 60.0 / own_period_s(solution.alone[k]),
                "period_alone_s": own_period_s(solution.alone[k]),
                "phase_offset_s": offset,
                "phase_offset_deg": offset / period * 360.0,
                "robot_starts_s": {
                    r: float(np.mod(s + offset, period)) for r, s in station_starts_s(solution.at_line[k]).items()
                },
                "robot_starts_own_s": dict(plan.robot_starts_s),
                "least_clearance_mm": float(clearance[least]) if needed else None,
                "least_clearance_time_s": float(t[least]) if needed else None,
                "verified": solution.at_line[k].verification.passed,
                "set": dict(sets.get(station.name, {})),
            }
        )
    robots = [
        {
            "name": robot.name,
            "unloads": None if robot.unloads is None else line.stations[robot.unloads].name,
            "loads": None if robot.loads is None else line.stations[robot.loads].name,
            "away_s": robot.away_s,
            "loop_s": loop,
            "stretches": [vars(s) | {"start_master_deg": s.start_s / period * 360.0} for s in stretches],
        }
        for robot, loop, stretches in zip(line.robots, solution.loops_s, solution.schedules, strict=True)
    ]
    neck = solution.bottleneck
    return {
        "line": line.name,
        "title": line.title,
        "line_file": str(line.path),
        "set": {f: v for f, v in settings.items() if f.partition(".")[0] not in names},
        "status": "verified" if solution.passed else "unverified",
        "spm": solution.spm,
        "period_s": period,
        "horizon_s": horizon_s(solution.at_line, period),
        "bottleneck": {"kind": neck.kind, "name": neck.name, "period_s": neck.period_s, "spm": 60.0 / neck.period_s},
        "stations": stations,
        "robots": robots,
        "checks": [
            {"id": c.id, "name": c.name, "value": c.value, "limit": c.limit, "unit": c.unit, "passed": c.passed}
            for c in solution.checks
        ],
    }


def summary_text(solution: LineSolution) -> str:
    """The line's summary: its rate, the bottleneck, each station alone and at the line, each robot's loop."""
    line, period = solution.line, solution.period_s
    neck = solution.bottleneck
    what = f"press {neck.name} alone with its robots" if neck.kind == "press" else f"robot {neck.name}'s loop"
    if neck.kind == "robot":  # what the loop is made of: its stays in the presses, its moves between them
        stretches = solution.schedules[[r.name for r in line.robots].index(neck.name)]
        what += " = " + " + ".join(f"{s.what} {s.duration_s:.3f}" for s in stretches if s.what != "wait") + " s"
    lines = [
        f"{line.name}: {solution.spm:.3f} strokes/min, cycle {period:.4f} s "
        f"({len(line.stations)} presses on one master, verified)",
        f"  bottleneck: {what} ({60 / neck.period_s:.3f} strokes/min, {neck.period_s:.4f} s)",
        "",
        f"  {'station':<12}{'alone [spm]':>12}{'at the line':>13}{'offset [deg]':>14}{'offset [s]':>12}  case",
    ]
    for k, station in enumerate(line.stations):
        offset = solution.offsets_s[k]
        lines.append(
            f"  {station.name:<12}{60 / own_period_s(solution.alone[k]):>12.3f}{solution.at_line[k].plan.spm:>13.3f}"
            f"{offset / period * 360:>14.2f}{offset:>12.4f}  {station.path.name}"
            + (" (pendulum: a swing a master cycle)" if station.case.pendulum else "")
        )
    lines += ["", f"  {'robot':<16}{'loop [s]':>10}{'spare [s]':>11}  stretches (start on the line's master [s])"]
    for robot, loop, stretches in zip(line.robots, solution.loops_s, solution.schedules, strict=True):
        moves = ", ".join(f"{s.what} {s.start_s:.3f}" for s in stretches if s.what != "wait")
        lines.append(f"  {robot.name:<16}{loop:>10.4f}{period - loop:>11.4f}  {moves}")
    return "\n".join(lines)


def writers(solution: LineSolution, figures: bool, settings: dict[str, Any] | None = None) -> dict[str, Any]:
    """The files of :data:`LINE_FILES` this run writes (the figure with ``figures``; ``settings``: the run's
    ``--set`` fields, recorded)."""
    table, columns = trajectory(solution)
    cam_table, cam_columns = cams(solution)
    head = (
        f"# pressplan line cams for {solution.line.name}; period_s = {solution.period_s:.9f}; "
        f"master 0 ... <{360 * round(horizon_s(solution.at_line, solution.period_s) / solution.period_s)} deg; "
        f"each crank angle modulo 360 deg from its TDC; dcrank_dmaster [deg/deg]"
    )
    out = {
        "line_summary.txt": lambda p: Path(p).write_text(summary_text(solution) + "\n", encoding="utf-8"),
        "line_result.json": lambda p: write_json(p, result(solution, settings)),
        "line_trajectory.csv": lambda p: write_table(p, table, columns),
        "line_cams.csv": lambda p: write_table(p, cam_table, cam_columns, head),
    }
    if figures:
        from planning.reports.plots import line_figure, save

        data, traj = result(solution, settings), dict(zip(columns, table.T, strict=True))
        out["line_timing.png"] = lambda p: save(line_figure(data, traj), p)
    return out


def write_line_outputs(
    solution: LineSolution, out: str | Path, figures: bool = True, settings: dict[str, Any] | None = None
) -> list[Path]:
    """Every file of ``pressplan line`` into the folder ``out`` (replaced as a whole; :data:`LINE_FILES`)."""
    return write_atomic(Path(out), writers(solution, figures, settings), LINE_FILES, keep=solution.line.path)
