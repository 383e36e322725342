"""The robots' part of the outputs (``robots:``): their columns of ``trajectory.csv``, the ``robots`` block of
``result.json``, the summary's lines and their cam table on the crank's virtual master.

The master is the crank cam's (``planning.reports.cam_table``): one stroke one master turn, master 0 at TDC,
``master_deg = 360 t / period``. A robot's position [mm] counts from the die centre (0) to its waiting point
(its path length); its derivatives are taken against the master in degrees.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from planning.model.limits.robots import RobotSchedule, robot_schedule
from planning.solver.pendulum_robots import WINDOWS, window_view
from planning.solver.solution import Solution
from press.robot import Robot

ROBOT_PARTS = ("position_mm", "needed_height_mm", "clearance_mm")  # a robot's trajectory columns, after its name
EVENTS = ("leaves_waiting_point", "at_die_centre", "leaves_die_centre", "back_at_waiting_point")


def robot_columns(case: Any) -> tuple[str, ...]:
    """The robots' columns of ``trajectory.csv``: ``unloader_position_mm``, ... per robot of ``case``."""
    return tuple(f"{robot.name}_{part}" for robot in case.robots_on_path for part in ROBOT_PARTS)


def robot_values(dense: Any, case: Any) -> list[np.ndarray]:
    """The robots' columns (:func:`robot_columns`) at the dense samples: each tool's position, the height it
    needs there and the slide's height above that (the clearance; where the tool needs nothing, the slide's
    height itself)."""
    plan, out = dense.plan, []
    for robot in case.robots_on_path:
        position = robot.position_of_starts(dense.t, starts_of(plan, robot.name), plan.period)
        need = robot.curve.need(position)
        out += [position, need, dense.h - need]
    return out


def starts_of(plan: Any, name: str) -> tuple[float, ...]:
    """The robot ``name``'s starts in a cycle of ``plan`` [s]: a rotary cycle's one, a pendulum cycle's one in
    each window (``planning.solver.pendulum_robots``)."""
    starts = plan.robot_starts_s[name]
    return tuple(starts[w] for w in WINDOWS) if isinstance(starts, dict) else (starts,)


def schedules(solution: Solution, case: Any) -> list[tuple[Robot, str, RobotSchedule]]:
    """Each robot's schedule in the plan, with the window it runs in (``""`` in a rotary cycle's one)."""
    dense = solution.evaluation.samples
    if not case.pendulum:
        return [(robot, "", robot_schedule(dense, robot)) for robot in case.robots_on_path]
    return [(robot, w, robot_schedule(window_view(dense, w), robot)) for robot in case.robots_on_path for w in WINDOWS]


def master_deg(time_s: float, period_s: float) -> float:
    """The virtual master's angle [deg] at ``time_s`` [s from TDC]."""
    return float(np.mod(time_s, period_s) / period_s * 360.0)


def robots_block(solution: Solution, case: Any) -> dict[str, Any]:
    """``result.json``'s ``robots`` block: the order, and per robot its moves' times and master angles (it
    leaves its waiting point, reaches the die centre, leaves it, is back), the time its tool spends over the
    die, its least clearance and where it occurs."""
    period = solution.plan.period
    robots = []
    for robot, window, s in schedules(solution, case):
        needs = bool(np.isfinite(s.least_clearance_mm))
        events = {
            name: {"time_s": t, "master_deg": master_deg(t, period)} for name, t in zip(EVENTS, s.events_s, strict=True)
        }
        robots.append(
            {
                "name": robot.name,
                **({"window": window} if window else {}),
                "move_s": robot.move.duration_s,
                "dwell_s": robot.dwell_s,
                "occupancy_s": robot.occupancy_s,
                "events": events,
                "over_die_s": s.over_die_s,
                # None where the tool never needs height (no clearance to keep)
                "least_clearance_mm": s.least_clearance_mm if needs else None,
                "least_clearance_time_s": s.least_at_s if needs else None,
                "least_clearance_master_deg": master_deg(s.least_at_s, period) if needs else None,
                "needed_there_mm": s.tightest_need_mm if needs else None,
            }
        )
    master = "master 0 at the forward swing's start, 360 a cycle of two swings" if case.pendulum else MASTER
    return {"order": case.robots.order, "master": master, "robots": robots}


MASTER = "master 0 at TDC, 360 a stroke"  # a rotary cycle's virtual master (``cam_table.csv``'s)


def robot_lines(result: dict[str, Any]) -> list[str]:
    """The summary's lines on the robots (none without them)."""
    block = result.get("robots")
    if not block:
        return []
    names = [f"{r['name']} {r['window']}" if "window" in r else r["name"] for r in block["robots"]]
    width = max(18, *(len(n) + 1 for n in names))  # (a pendulum cycle's names carry their window)
    head = f"  {'robot [master deg]':<{width}}  leaves    at die  leaves die      back  over die s  least clearance"
    order = f"{block['order']}; " if len({r["name"] for r in block["robots"]}) == 2 else ""  # (one robot: no order)
    lines = ["", f"{head} ({order}{block.get('master', MASTER)})"]
    for r, name in zip(block["robots"], names, strict=True):
        e = r["events"]
        degs = "".join(f"{e[k]['master_deg']:>{w}.1f}" for k, w in zip(EVENTS, (8, 10, 12, 10), strict=True))
        clearance = r["least_clearance_mm"]
        where = (
            "-"
            if clearance is None
            else f"{round(clearance, 3) + 0.0:.3f} mm at {r['least_clearance_master_deg']:.1f} deg"
        )
        lines.append(f"  {name:<{width}}{degs}  {r['over_die_s']:>10.4f}  {where}")
    return lines


CAM_PARTS = ("position_mm", "dposition_dmaster", "d2position_dmaster2")  # [mm], [mm/deg], [mm/deg^2]


def robot_cam_columns(case: Any) -> tuple[str, ...]:
    """``master_deg`` and each robot's position and its first two derivatives against the master."""
    return ("master_deg",) + tuple(f"{robot.name}_{part}" for robot in case.robots_on_path for part in CAM_PARTS)


def robot_cam_table(solution: Solution, case: Any, points: int) -> np.ndarray:
    """``points`` rows over one stroke of the master; columns :func:`robot_cam_columns`. The derivatives are
    the robot's own speed and acceleration (its move's closed form) over the master speed ``360 / period``."""
    plan = solution.plan
    period = plan.period
    master = np.arange(points) * (360.0 / points)
    t = master / 360.0 * period
    rate = 360.0 / period  # [deg/s] of the master
    columns = [master]
    for robot in case.robots_on_path:
        x, v, a = _robot_state(robot, t, starts_of(plan, robot.name), period)
        columns += [x, v / rate, a / rate**2]
    return np.column_stack(columns)


def _robot_state(robot: Robot, t: np.ndarray, starts: tuple[float, ...], period: float) -> tuple[np.ndarray, ...]:
    """Position [mm], speed [mm/s] and acceleration [mm/s^2] along the path at cycle times ``t`` [s] of a robot
    leaving its waiting point at each of ``starts`` [s] (speed negative on the way in, towards the die centre)."""
    move = robot.move
    out_start = move.duration_s + robot.dwell_s
    v, a = np.zeros_like(t), np.zeros_like(t)
    for start in starts:
        tau = np.mod(t - start, period)
        _, v_in, a_in = move.state(tau)
        _, v_out, a_out = move.state(tau - out_start)
        inward, moving = tau < out_start, tau < robot.occupancy_s
        v = np.where(moving, np.where(inward, -v_in, v_out), v)
        a = np.where(moving, np.where(inward, -a_in, a_out), a)
    return robot.position_of_starts(t, starts, period), v, a


def robot_cam_header(solution: Solution, case: Any, points: int) -> str:
    """The ``#`` lines that head ``robot_cams.csv``."""
    plan = solution.plan
    zero = "the forward swing's start (a cycle of two swings)" if case.pendulum else "TDC"
    return "\n".join(
        [
            f"# pressplan robot cams for {case.name} ({case.robots.order})",
            f"# period_s = {plan.period:.9f}; spm = {plan.spm:.6f}; master speed = {360 / plan.period:.6f} deg/s",
            f"# points = {points}; master 0 = {zero}, the crank cam's master (cam_table.csv); master 0 ... <360 deg",
            "# units: position_mm [mm from the die centre, the path length at the waiting point]; "
            "dposition_dmaster [mm/deg]; d2position_dmaster2 [mm/deg^2]",
        ]
    )
