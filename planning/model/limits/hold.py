"""The slide stands at its hold height (``process.hold_height_mm``) for the hold time (``process.hold_time_s``).

The plan holds it by its structure (``planning.model.cycle``: the crank brakes after the draw and stands at the
hold's angle for the hold time); the dense check measures it on the re-simulated motion instead: the longest
run of samples (the uniform grid and every knot) with the crank standing (``|omega| <=``
:data:`~planning.tolerances.HOLD_STILL_RAD_S`) and the slide within :data:`~planning.tolerances.HOLD_STILL_MM` of
the hold height, from its first sample to its last, must last at least the hold time. The crank's standstill,
not the slide's height alone: near BDC the slide stays within a micrometre while the crank still creeps, which
would count a shorter standstill as the hold.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.laws import LAWS
from planning.model.limits.base import Check, Dense, Draw, Impossible, Limit, runs
from planning.tolerances import HOLD_STILL_MM, HOLD_STILL_RAD_S, TIME_TOL_S


def longest_run_s(t: np.ndarray, inside: np.ndarray) -> tuple[float, float]:
    """``(duration [s], start [s])`` of the longest run of consecutive samples at times ``t`` where ``inside``
    holds (its first sample to its last; a run that ends the period continues into the run that starts it)."""
    if not inside.any():
        return 0.0, float(t[0])
    period = t[-1] - t[0]
    if inside.all():
        return float(period), float(t[0])
    k = int(np.argmin(inside))  # a sample outside: unroll the period from there
    order = np.r_[np.arange(k, t.size), np.arange(1, k + 1)]  # t[-1] is t[0] a period on
    times = np.r_[t[k:], t[1 : k + 1] + period]
    first, last = max(runs(inside[order]), key=lambda run: times[run[1]] - times[run[0]])
    return float(times[last] - times[first]), float(times[first] % period)


def hold_check(dense: Dense, within: np.ndarray, name: str) -> Check:
    """The hold among the samples ``within`` (a mask of ``dense.t``: the cycle, or one swing of a pendulum
    stroke, ``planning.solver.pendulum_check``): the longest run with the crank standing and the slide within
    ``HOLD_STILL_MM`` of its hold height lasts at least the hold time; located where it starts."""
    case = dense.case
    still = (np.abs(dense.h - case.hold_height_mm) <= HOLD_STILL_MM) & (np.abs(dense.omega) <= HOLD_STILL_RAD_S)
    t = dense.t[within]
    stood, start = longest_run_s(t, still[within]) if still[within].any() else (0.0, float(t[0]))
    limit = case.process.hold_time_s
    check = Check.of(HoldLimit.id, name, stood, limit, HoldLimit.unit, "min", TIME_TOL_S)
    theta = float(np.interp(start, dense.t, dense.theta))
    return check.located(np.array([start]), np.array([theta]), np.array([stood]), limit)


def least_rate(case: Any) -> float:
    """The least peak acceleration of a half of ``case``'s law in units of ``|dv| / D``: at its fixed shape
    parameter, else over :data:`RATE_GRID` values of the parameter's range."""
    law = LAWS[case.planner.motion_law]
    if not hasattr(law, "peak_rate"):  # the optimal law brakes in any shape: at least w^2 / (2 D), rate 1
        return 1.0
    if law.parameter is None:
        return float(law.peak_rate())
    fixed = case.planner.law_parameter
    values = [fixed] if fixed is not None else np.linspace(law.parameter.low, law.parameter.high, RATE_GRID)
    return min(float(law.peak_rate(float(v))) for v in values)


RATE_GRID = 101  # shape parameters over which a law's least peak acceleration is taken (least_rate)


class HoldLimit(Limit):
    """The hold at the bottom: the crank stands, the slide within a micrometre of its hold height, for the hold
    time."""

    id = "hold"
    name = "crank standing, the slide at its hold height"
    unit = "s"
    field = "process.hold_time_s"
    order = 115

    def applies(self, case: Any) -> bool:
        return case.process.hold_time_s is not None

    def check(self, dense: Dense) -> list[Check]:
        return [hold_check(dense, np.ones(dense.t.size, dtype=bool), self.name)]

    def draw_speed_bound(self, draw: Draw) -> float | None:
        """The highest draw speed [rad/s] the crank can brake from with the case's law under
        ``limits.crank_accel_rad_s2`` = A: the brake is one half of the law from ``w`` to rest over
        ``dtheta = theta_h - theta3`` (duration ``2 dtheta / w``), its peak acceleration ``rate w^2 / (2 dtheta)``
        with the law's ``rate`` (the least over its shape parameter's range when the planner chooses it):
        ``w <= sqrt(2 A dtheta / rate)``. None without a crank-acceleration limit."""
        case = draw.case
        top = case.limits.crank_accel_rad_s2
        if top is None:
            return None
        brake = case.hold_angle - float(case.key_angles[2])
        return math.sqrt(2 * top * brake / least_rate(case))

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """A given draw speed ``w`` [rad/s] the crank cannot brake from: any motion from ``w`` to rest over the
        brake's angle ``theta_h - theta3`` reaches ``|alpha| >= w^2 / (2 (theta_h - theta3))`` (from
        ``d(omega^2)/dtheta = 2 alpha``), above ``limits.crank_accel_rad_s2``."""
        top = case.limits.crank_accel_rad_s2
        if given is None or top is None:
            return None
        brake = case.hold_angle - float(case.key_angles[2])
        needed = given**2 / (2 * brake)
        if needed <= top:
            return None
        reason = (
            f"limits.crank_accel_rad_s2 = {top:g} cannot brake the crank from the draw speed "
            f"{case.process.draw_speed_rpm:g} rpm to the hold over the {math.degrees(brake):.2f} deg from theta3: "
            f"that takes at least {needed:.4g} rad/s^2"
        )
        return Impossible(reason, "limits.crank_accel_rad_s2", top, needed)

    def limit(self, case: Any) -> float:
        return case.process.hold_time_s
