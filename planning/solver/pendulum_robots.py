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
The slide's height at any time is the NLP's closed form: the crank angle over the whole cycle's segments in the
crank's own angle from the forward swing's theta3 (the forward return, the turn at theta_e, the backward
swing's segments with their jerks and speed changes negated, the turn at theta_s, the forward feed and draw),
``h(theta(t))`` at ``t`` within the period. The clearance is held at ``ROBOT_SAMPLES`` times of each
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
    worst_refined,
)
from planning.model.pendulum import PendulumPlan
from planning.tolerances import TIME_TOL_S
from press.robot import Robot, sample_points, time_to_clear_s

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
    outside those, at most the slide's height); ``offset_s``: each window's theta3 [s from the forward swing's
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
    out, clearances = [], []
    k = plan.time_scale
    for robot in case.robots_on_path:
        for w in WINDOWS:
            schedule = replace(robot_schedule(window_view(dense, w), robot), name=f"{robot.name} {w}")
            check = clearance_check(dense, schedule)
            clearances.append((check, schedule.least_ratio))
            out.append(check)
        out += path_checks(robot, k)
        out.append(_apart_check(robot, plan))
    out = worst_refined(out, clearances)
    return out + _order_checks(case, plan, windows)


def _apart_check(robot: Robot, plan: PendulumPlan) -> Check:
    """The robot's two occupancies apart: the shorter time from one start to the next, at least its occupancy
    [s as run]."""
    k, period = plan.time_scale, plan.period
    e, s = (plan.robot_starts_s[robot.name][w] / k for w in WINDOWS)
    gap = min(float(np.mod(s - e, period)), float(np.mod(e - s, period)))
    name = f"{robot.name}: in and out within each window's share of the cycle"
    return Check.of("robots_order", name, gap, robot.occupancy_s / k, "s", "min", TIME_TOL_S)


def _order_checks(case: Any, plan: PendulumPlan, windows: dict[str, tuple[float, float]]) -> list[Check]:
    """In each window: each robot at the die between its theta3 and the next theta2, the loader after the
    unloader (in the case's order); in turns the loader back before the next window's unloader leaves."""
    k, period = plan.time_scale, plan.period
    robots = robots_by_name(case)
    starts = {name: {w: plan.robot_starts_s[name][w] / k for w in WINDOWS} for name in robots}
    out = []
    for w, other in zip(WINDOWS, WINDOWS[::-1], strict=True):
        t3, t2 = windows[w]
        free = t2 - t3

        def since(time_s: float, t3: float = t3) -> float:
            rel = float(np.mod(time_s - t3, period))
            return rel - period if rel > period - TIME_TOL_S else rel

        at_die = {}
        for name, robot in robots.items():
            arrives = since(starts[name][w] + robot.move.duration_s / k)
            leaves = arrives + robot.dwell_s / k
            at_die[name] = arrives if name == "unloader" else leaves  # it grips; it has dropped the blank
            what = "grips" if name == "unloader" else "drops the blank"
            margin = min(arrives, free - leaves)
            name_w = f"{name} {w}: {what} at the die centre after theta3 and leaves it before theta2"
            out.append(Check.of("robots_order", name_w, margin, 0.0, "s", "min", TIME_TOL_S))
        if len(robots) < 2:
            continue
        u, ld = robots["unloader"], robots["loader"]
        grip, dropped = at_die["unloader"], at_die["loader"]
        if case.robots.order == "in-turns":
            back = grip + (u.dwell_s + u.move.duration_s) / k
            leaves = dropped - (ld.dwell_s + ld.move.duration_s) / k
            gap, name = leaves - back, f"the loader leaves after the unloader is back {w}"
            next_leaves = float(np.mod(starts["unloader"][other] - starts["loader"][w], period))
            wrap = next_leaves - ld.occupancy_s / k
            back_name = f"the loader back before the unloader {other}"
            out.append(Check.of("robots_order", back_name, wrap, 0.0, "s", "min", TIME_TOL_S))
        else:
            gap = (dropped - ld.dwell_s / k) - (grip + (u.dwell_s + time_to_clear_s(u)) / k)
            name = f"the loader reaches the die {w} once the unloader is clear of it"
        out.append(Check.of("robots_order", name, gap, 0.0, "s", "min", TIME_TOL_S))
    return out
