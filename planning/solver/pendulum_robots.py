"""The robots on their interference curves in a pendulum stroke (``robots:`` with ``planner.mode: pendulum``).

Each swing is a stroke, so each robot makes one occupancy (in, dwell, out; ``press.robot``) in each of the
cycle's two windows between the draws: the window **at theta_e**, from the forward swing's theta3 through the
turn at theta_e to the backward swing's theta2, and the window **at theta_s**, from the backward swing's theta3
through the turn at theta_s to the next forward swing's theta2. In each window the rotary cycle's rules hold
(``planning.model.limits.robots``): the slide at least as high as each tool needs where the tool is
(``c(t) = h(t) - n(x(t)) >= 0``), each robot's dwell at the die centre (the unloader gripping, the loader
dropping the blank) after theta3 and before theta2, the loader after the unloader in the case's order
(``overlapping``: it reaches the die centre once the unloader's tool is clear of the die; ``in-turns``: it leaves
its waiting point once the unloader is back at its own).
Across the windows each robot's two occupancies do not overlap, and in turns the loader is back before the
next window's unloader leaves. The planner decides each robot's start in each window: on an asymmetric press
the swings, and so the windows, differ.

In the NLP (``planning.solver.pendulum_nlp``) each start is a variable, its time [s] from its window's theta3.
The slide's height in a window is the NLP's closed form: the crank angle over the window's segments in the
crank's own angle, from the draw before it through the return, the turn and the feed to the draw after it (the
backward swing's jerks and speed changes negated), ``h(theta(t))``; outside those, BDC's height (0, never above
the slide's). The clearance is held at ``ROBOT_SAMPLES`` times of each
occupancy (the curve's crossings among them), each need scaled by ``robots_need_factor`` (1 at first; raised
by the search by the worst shortfall when the dense check finds the clearance lost between the samples).

The dense check (:func:`robot_checks`) takes each occupancy as a rotary schedule of one window
(``planning.model.limits.robots.robot_schedule``: the clearance at every dense sample and at the crossings'
exact times), each robot's speed and acceleration along its path, and the order in each window and across them.
Times of a plan's robots are the planned ones, from the forward swing's start; a cam run ``k`` times as fast
(``PendulumPlan.time_scale``) runs the robots' cams ``k`` times as fast too.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from planning.model.limits.base import Check, Dense
from planning.model.limits.robots import (
    ROBOT_SAMPLES,
    RobotsLimit,
    clearance_check,
    order_terms,
    path_checks,
    robot_schedule,
    robots_by_name,
    since,
    window_order_checks,
    within_check,
    worst_refined,
)
from planning.model.pendulum import PendulumPlan
from planning.tolerances import TIME_TOL_S
from press.robot import Robot, sample_points

WINDOWS = ("at theta_e", "at theta_s")  # the cycle's two windows (``planning.model.pendulum.windows_of``'s names)
NEED_FACTOR = "robots_need_factor"  # the NLP's parameter that scales the needs at the samples
ROBOTS_CHECK = RobotsLimit.id  # the clearance checks' id (the worst failed one carries the refinement)


def start_variable(robot: str, window: str) -> str:
    """The NLP variable of ``robot``'s start in ``window`` [s from the window's theta3]."""
    return f"{robot}_start_{window.removeprefix('at ')}"


def start_variables(case: Any) -> tuple[str, ...]:
    """The robots' start variables of ``case``: each robot in each window."""
    return tuple(start_variable(r.name, w) for r in case.robots_on_path for w in WINDOWS)


@dataclass(frozen=True)
class CycleTimes:
    """What the robots' rows read of a pendulum cycle (symbols or numbers): ``height_at(window, times)`` the
    slide's height [mm] at times [s] from the window's theta3 (from the draw before it to the draw after it;
    outside those BDC's, never above the slide); ``offset_s``: each window's theta3 [s from the forward swing's
    theta3]; ``free_s``: each window's time from its theta3 to the next theta2 [s]; the ``period`` [s]."""

    height_at: Callable[[str, list], Any]
    offset_s: dict[str, Any]
    free_s: dict[str, Any]
    period: Any


def robot_rows(add: Callable, case: Any, cycle: CycleTimes, starts: dict[str, Any], factor: Any, unit: Any) -> None:
    """The robots' rows (module docstring) through ``add(name, expression, lower, upper, field)``: ``starts`` the
    start variables by name (:func:`start_variable`), ``factor`` the needs' scale, ``unit`` [s] the rows' time
    unit."""
    import casadi as ca

    stroke = float(case.machine.stroke)
    robots = robots_by_name(case)
    at: dict[tuple[str, str], Any] = {}
    for name, robot in robots.items():
        offsets, needs = sample_points(robot, ROBOT_SAMPLES)
        needing = needs > 0  # (where the tool needs nothing the slide is free: no row)
        offsets, needs = offsets[needing], needs[needing]
        for w in WINDOWS:
            s = starts[start_variable(name, w)]
            at[name, w] = cycle.offset_s[w] + s  # [s from the forward swing's theta3]
            height = cycle.height_at(w, [s + float(tau) for tau in offsets])
            clearance = (height - ca.DM(needs) * factor) / stroke
            add(f"{name} {w}: slide above its tool", clearance, 0.0, math.inf, "robots")
            arrives = s + robot.move.duration_s  # its dwell at the die centre within theta3 .. theta2
            between = ca.vertcat(arrives, cycle.free_s[w] - arrives - robot.dwell_s) / unit
            add(f"{name} {w}: at the die between the draws", between, 0.0, math.inf, "robots")
        e, s_ = (at[name, w] for w in WINDOWS)
        apart = ca.vertcat(s_ - e, e + cycle.period - s_) - robot.occupancy_s
        add(f"{name}: one occupancy in each window", apart / unit, 0.0, math.inf, f"robots.{name}.dwell_s")
    if len(robots) == 2:
        lead, clear = order_terms(case)
        loader_occupancy = robots["loader"].occupancy_s
        for w, other, wrap in ((WINDOWS[0], WINDOWS[1], 0.0), (WINDOWS[1], WINDOWS[0], cycle.period)):
            first = at["loader", w] + lead - at["unloader", w] - clear
            add(f"the loader after the unloader {w}", first / unit, 0.0, math.inf, "robots.order")
            if case.robots.order == "in-turns":  # back before the next window's unloader leaves
                back = at["unloader", other] + wrap - at["loader", w] - loader_occupancy
                add(f"the loader back before the unloader {other}", back / unit, 0.0, math.inf, "robots.order")


def first_starts(case: Any, window_times: dict[str, tuple[float, float]]) -> dict[str, float]:
    """Starting values of the robots' starts from each window's theta4 and next theta1 [s from its theta3]
    (``window_times``): the unloader leaving at theta4, the loader halfway to theta1 (a rotary start's)."""
    out = {}
    for robot in case.robots_on_path:
        for w in WINDOWS:
            opening, closing = window_times[w]
            share = 0.0 if robot.name == "unloader" else 0.5
            out[start_variable(robot.name, w)] = opening + share * (closing - opening)
    return out


def plan_starts(case: Any, values: dict[str, float], offsets_s: dict[str, float], period: float) -> dict:
    """Each robot's start in each window [s from the forward swing's start, within the period]: ``offsets_s``
    each window's theta3 there."""
    return {
        robot.name: {w: float(np.mod(values[start_variable(robot.name, w)] + offsets_s[w], period)) for w in WINDOWS}
        for robot in case.robots_on_path
    }


@dataclass(frozen=True)
class _OneWindow:
    """A pendulum plan seen as one window's rotary schedule (what ``robot_schedule`` reads of a plan)."""

    profile: Any
    period: float
    robot_time_scale: float
    robot_starts_s: dict[str, float]


def window_view(dense: Dense, window: str) -> Dense:
    """``dense`` with its plan seen as the robots' schedule of ``window`` alone (each robot's one occupancy
    there, at its waiting point the rest of the cycle)."""
    plan: PendulumPlan = dense.plan
    starts = {name: by_window[window] for name, by_window in plan.robot_starts_s.items()}
    return replace(dense, plan=_OneWindow(plan.profile, plan.period, plan.time_scale, starts))


def robot_checks(dense: Dense, windows: dict[str, tuple[float, float]]) -> list[Check]:
    """The robots' checks of a pendulum plan (module docstring); ``windows``: each window's theta3 and next
    theta2 [s from the forward swing's start]."""
    case, plan = dense.case, dense.plan
    missing = [r.name for r in case.robots_on_path if r.name not in plan.robot_starts_s]
    if missing:
        name = f"{', '.join(missing)}: scheduled in the plan"
        return [Check.of("robots_order", name, math.nan, 0.0, "s", "min", TIME_TOL_S)]
    k = plan.time_scale
    within = [within_check(r, 2 * r.occupancy_s / k, plan.period, "in and out twice") for r in case.robots_on_path]
    if not all(c.passed for c in within):  # two occupancies longer than the cycle: no schedule to check
        return within
    out, clearances = [], []
    for robot in case.robots_on_path:
        for w in WINDOWS:
            schedule = replace(robot_schedule(window_view(dense, w), robot), name=f"{robot.name} {w}")
            check = clearance_check(dense, schedule)
            clearances.append((check, schedule.least_ratio))
            out.append(check)
        out += path_checks(robot, k)
        out.append(_occupancies_apart(robot, plan))
    out = worst_refined(out, clearances)
    return out + _order_checks(case, plan, windows)


def _occupancies_apart(robot: Robot, plan: PendulumPlan) -> Check:
    """The robot's two occupancies apart: the shorter time from one start to the next, at least its occupancy
    [s as run]."""
    k, period = plan.time_scale, plan.period
    e, s = (plan.robot_starts_s[robot.name][w] / k for w in WINDOWS)
    gap = min(float(np.mod(s - e, period)), float(np.mod(e - s, period)))
    name = f"{robot.name}: in and out within each window's share of the cycle"
    return Check.of("robots_order", name, gap, robot.occupancy_s / k, "s", "min", TIME_TOL_S)


def _order_checks(case: Any, plan: PendulumPlan, windows: dict[str, tuple[float, float]]) -> list[Check]:
    """Each window's order (``planning.model.limits.robots.window_order_checks``): its arrivals from its theta3,
    the next window's unloader from this theta3 (across the turn)."""
    k, period = plan.time_scale, plan.period
    arrivals = {}
    for w, (t3, _) in windows.items():
        arrivals[w] = {
            r.name: since((plan.robot_starts_s[r.name][w] + r.move.duration_s) / k, t3, period)
            for r in case.robots_on_path
        }
    out = []
    for w, other in zip(WINDOWS, WINDOWS[::-1], strict=True):
        t3, t2 = windows[w]
        to_other = float(np.mod(windows[other][0] - t3, period))  # this theta3 to the other's
        next_unloader = to_other + arrivals[other].get("unloader", 0.0)
        out += window_order_checks(case, arrivals[w], t2 - t3, k, (f" {w}", next_unloader))
    return out
