"""The optimal law's swings in a pendulum NLP (``planning.solver.pendulum_nlp``): a free jerk profile per swing.

Each swing is ``planning.model.free_swing``'s: the feed's and the return's steps and their segments' jerks are the
swing's variables (the jerks bounded by the crank-jerk limit, :func:`variable_bounds`), with the draw speed, the
times ``t1`` (from the swing's start to theta1), ``t4`` (from theta3 to theta4) and the return's die-zone times as
a law with halves has them. Rows per swing: the feed arrives at theta2 with the draw speed and no acceleration, the
return at the swing's end at rest with no acceleration; theta1 and theta4 at ``t1`` and ``t4`` (within the feed and
the return); the crank's acceleration at every knot within its limit (it is linear between); the crank speed at or
above 0 (the swing turns one way) and at or below the crank's and the motor's top speed all through every segment
(the speed is quadratic in a segment's time: its Bernstein control points ``w0``, ``w0 + a0 h / 2``, ``w1`` within
the bounds hold it so, the convex hull; the top a parameter, lowered should the dense check find it passed); the
slide's acceleration and speed and the die zone as every swing's, and the die speed at every sample at or below the
die height (``planning.solver.pendulum_swing.sampled_rows``). The cycle's rows (the windows or the robots, the
drive, the objective, to which :func:`jerk_tie_break` is added) are the pendulum NLP's.

A start: a plan of the case under the first law of :data:`SEED_LAWS` that finds one (a jerk-limited law with
halves; the cycloidal, smooth at any jerk, where it finds none), each part's profile sampled on its uniform grid, a
segment's jerk the change of acceleration across it, the jerks then closed onto the part's ends
(:func:`~planning.model.free_swing.closed_part_jerks`); its key times, turns and robots' starts as they were.
"""

from __future__ import annotations

import math
from typing import Any

import casadi as ca
import numpy as np

from planning.model.case import Case
from planning.model.free_swing import (
    FEED_SEGMENTS,
    RETURN_SEGMENTS,
    FreeSwingParameters,
    closed_part_jerks,
)
from planning.model.pendulum import DIE_ZONE_POINTS, SWINGS, PendulumPlan, SwingSetup
from planning.model.profile import Profile
from planning.solver.halves_nlp import VARIABLE_INDEX, angle_at, variable_scales
from planning.solver.nlp import Rows
from planning.solver.pendulum_swing import SwingSymbols, sampled_rows, segments_from
from planning.tolerances import JERK_TIE_BREAK

SEED_LAWS = ("seven-segment", "cycloidal")  # the laws whose pendulum plan starts the optimal swings, the first found
MIN_STEP_S = 1e-3  # [s] a segment's step at least (a part of 24 segments at least 24 ms)
STEP_SCALE = 12.0  # a step's scale: the halves NLP's half duration over this (a part ~ two halves)
JERK_SCALE_CAP = 100.0  # a jerk's scale: the jerk limit, at most this many of the press's own W* / T*^2
FREE_SWING_VARIABLES = (  # per swing, prefixed ``forward_`` / ``backward_``: (name, scale kind)
    ("draw_speed", "draw_speed"),
    ("feed_step", "step"),
    ("return_step", "step"),
    *((f"feed_jerk_{k}", "jerk") for k in range(FEED_SEGMENTS)),
    *((f"return_jerk_{k}", "jerk") for k in range(RETURN_SEGMENTS)),
    ("closing_time", "closing_time"),
    ("opening_time", "closing_time"),
    *((f"die_time_{k}", "closing_time") for k in range(DIE_ZONE_POINTS)),  # from theta3 to the die zone's angles
)
KEYS = "key_points"
ACCEL, SPEED = "limits.crank_accel_rad_s2", "limits.crank_speed_rpm"
TOP_SPEED_PARAMETER = "top_speed"  # [rad/s] the top crank speed of the rows (lowered should the dense check pass it)


def jerk_names(part: str, count: int) -> tuple[str, ...]:
    """The names of a part's jerk variables (``feed`` or ``return``) without the swing's prefix."""
    return tuple(f"{part}_jerk_{k}" for k in range(count))


def free_swing(setup: SwingSetup, v: dict[str, Any], ends: tuple[Any, Any]) -> SwingSymbols:
    """One swing's symbols under the optimal law (``v``: its physical variables by name, ``ends``: u at its start
    and end)."""
    p = FreeSwingParameters(
        v["draw_speed"],
        v["feed_step"],
        v["return_step"],
        tuple(v[n] for n in jerk_names("feed", FEED_SEGMENTS)),
        tuple(v[n] for n in jerk_names("return", RETURN_SEGMENTS)),
        ends[0],
        setup.keys[1],
        setup.keys[2],
        ends[1],
    )
    feed, feed_end = segments_from(p.feed_segments(), ends[0], 0.0)
    ret, return_end = segments_from(p.return_segments(), setup.keys[2], p.draw_speed)
    return SwingSymbols(setup, p, v, feed, ret, feed_end, return_end)


def free_swing_rows(rows: Rows, s: SwingSymbols, case: Case, limits: dict[str, float], units: dict[str, float]) -> None:
    """One swing's rows under the optimal law (module docstring); ``units``: the speed's and a half's scales;
    ``limits``: the sampled limits' parameters, the crank's top speed :data:`TOP_SPEED_PARAMETER` [rad/s] among
    them."""
    p, v, keys = s.params, s.v, s.setup.keys
    w_unit, top = units["speed"], limits[TOP_SPEED_PARAMETER]
    accel_unit = case.limits.crank_accel_rad_s2 or case.limits.crank_jerk_rad_s3 * units["half"]
    (th2, w2f, a2), (the, we, ae) = s.feed_end, s.return_end
    rows.add("theta2 and the swing's end reached", ca.vertcat(th2 - keys[1], the - p.end), 0.0, 0.0, KEYS)
    speeds = ca.vertcat(w2f - p.draw_speed, we) / w_unit
    rows.add("the draw speed at theta2, at rest at the end", speeds, 0.0, 0.0, "planner.motion_law")
    rows.add(
        "no acceleration at theta2 and at the end", ca.vertcat(a2, ae) / accel_unit, 0.0, 0.0, "planner.motion_law"
    )
    th1, _ = angle_at(v["closing_time"], *s.feed)
    th4, _ = angle_at(v["opening_time"], *s.ret)
    rows.add("key angles", ca.vertcat(th1 - keys[0], th4 - keys[3]), 0.0, 0.0, KEYS)
    order = ca.vertcat(p.feed_time - v["closing_time"], p.return_time - v["opening_time"]) / units["half"]
    rows.add("key points in order", order, 0.0, math.inf, KEYS)
    knots = ca.vertcat(*[st[2] for _, states, _ in (s.feed, s.ret) for st in states[1:]])
    if case.limits.crank_accel_rad_s2 is not None:  # (the parts' first knots: 0 by their starts)
        rows.add("crank acceleration", knots / case.limits.crank_accel_rad_s2, -1.0, 1.0, ACCEL)
    for part, (_, states, segs) in enumerate((s.feed, s.ret)):
        for k, (seg, st) in enumerate(zip(segs, states, strict=True)):
            # its speed, a quadratic in the segment's time, has in Bernstein form the control points w0,
            # w0 + a0 h / 2, w1, and lies in their convex hull: 0 <= each <= top holds it so all through the segment
            # (w0 is the segment before's w1). The feed's first segment, j t^2 / 2 from rest, needs its w1 only; the
            # return's last, the same arriving at rest, none. (The feed's last and the return's first, monotone
            # between w2 and a neighbour's knot, keep rows their equalities make redundant: without them IPOPT ended
            # in poorer optima on the shallow bracket, 64.081 strokes/min against 64.107)
            middle, end = st[1] + st[2] * seg.duration / 2, st[1] + st[2] * seg.duration + seg.j0 * seg.duration**2 / 2
            last = len(segs) - 1
            points = {(0, 0): [end], (1, last): []}.get((part, k), [middle, end])
            if points:
                rows.add("crank speed one way, within the top", ca.vertcat(*points) / top, 0.0, 1.0, SPEED)
    sampled_rows(rows, s, case, limits, zone=True)


def free_parameters(
    values: dict[str, float], swing: str, setup: SwingSetup, ends: tuple[float, float]
) -> FreeSwingParameters:
    """A swing's :class:`FreeSwingParameters` of the NLP's ``values``, each part's jerks closed onto its ends."""
    n = swing
    w2 = float(values[f"{n}_draw_speed"])
    hf, hr = float(values[f"{n}_feed_step"]), float(values[f"{n}_return_step"])
    feed = tuple(float(values[f"{n}_{k}"]) for k in jerk_names("feed", FEED_SEGMENTS))
    ret = tuple(float(values[f"{n}_{k}"]) for k in jerk_names("return", RETURN_SEGMENTS))
    feed = closed_part_jerks(hf, feed, (ends[0], 0.0, 0.0), (setup.keys[1], w2, 0.0))
    ret = closed_part_jerks(hr, ret, (setup.keys[2], w2, 0.0), (ends[1], 0.0, 0.0))
    return FreeSwingParameters(w2, hf, hr, feed, ret, ends[0], setup.keys[1], setup.keys[2], ends[1])


def _part_jerks(profile: Profile, count: int) -> tuple[float, tuple[float, ...]]:
    """A part's profile on ``count`` equal steps: the step [s] and each segment's jerk (its change of
    acceleration over the step)."""
    step = profile.duration / count
    alpha = profile.at_time(profile.t0 + step * np.arange(count + 1))[2]
    return step, tuple((np.diff(alpha) / step).tolist())


def seed_start(seed: PendulumPlan, names: tuple[str, ...]) -> dict[str, float]:
    """The start of the optimal law's pendulum NLP (variables ``names``) from ``seed``, a plan of the case under
    a law with halves (module docstring)."""
    values = {name: float(x) for name, x in seed.nlp_values.items() if name in names}
    for swing, p in zip(SWINGS, (seed.parameters.forward, seed.parameters.backward), strict=True):
        w2 = float(p.draw_speed)
        ends = (float(p.start), float(p.end))
        hf, feed = _part_jerks(Profile(tuple(p.feed_segments()), ends[0], 0.0), FEED_SEGMENTS)
        hr, ret = _part_jerks(Profile(tuple(p.return_segments()), float(p.draw_end), w2), RETURN_SEGMENTS)
        feed = closed_part_jerks(hf, feed, (ends[0], 0.0, 0.0), (float(p.draw_start), w2, 0.0))
        ret = closed_part_jerks(hr, ret, (float(p.draw_end), w2, 0.0), (ends[1], 0.0, 0.0))
        values |= {f"{swing}_draw_speed": w2, f"{swing}_feed_step": hf, f"{swing}_return_step": hr}
        values |= dict(zip((f"{swing}_{k}" for k in jerk_names("feed", FEED_SEGMENTS)), feed, strict=True))
        values |= dict(zip((f"{swing}_{k}" for k in jerk_names("return", RETURN_SEGMENTS)), ret, strict=True))
    values["law_parameter"] = 0.0
    return values


def variable_bound(case: Case, name: str) -> tuple[float, float] | None:
    """An optimal swing's own variable's bounds: a jerk within the crank-jerk limit, a step at least
    :data:`MIN_STEP_S` (None: not such a variable)."""
    if "_jerk_" in name:
        jerk = case.limits.crank_jerk_rad_s3
        return -jerk, jerk
    if name.endswith("_step"):
        return MIN_STEP_S, math.inf
    return None


def jerk_scale(case: Case) -> float:
    """[rad/s^3] the jerk variables' scale: the jerk limit, but at most :data:`JERK_SCALE_CAP` times the press's own
    jerk ``W* / T*^2`` (``planning.solver.halves_nlp.variable_scales``' speed over its half's duration squared), so
    that the scaled jerks stay O(1) and the tie-break weighs them where the limit is far above any jerk the press
    can use (1e9: the shipped cases' limits are below the cap, their scale the limit)."""
    scales = variable_scales(case)
    own = scales[VARIABLE_INDEX["draw_speed"]] / scales[VARIABLE_INDEX["feed_accel_duration"]] ** 2
    return min(case.limits.crank_jerk_rad_s3, JERK_SCALE_CAP * own)


def jerk_tie_break(case: Case, phys: dict[str, Any]) -> Any:
    """:data:`~planning.tolerances.JERK_TIE_BREAK` times the mean of each jerk variable's square over its scale's
    (:func:`jerk_scale`): added to the objective, it picks the smoothest of the equally fast profiles (the cycle
    time alone leaves a swing's jerks free wherever no limit binds), one answer."""
    jerks = [x for name, x in phys.items() if "_jerk_" in name]
    return JERK_TIE_BREAK * ca.sumsqr(ca.vertcat(*jerks) / jerk_scale(case)) / len(jerks)
