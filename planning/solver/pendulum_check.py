"""Independent verification of a pendulum plan: its profile re-simulated densely in the crank's own angle.

The plan's profile (``planning.model.pendulum``: the backward swing's speeds negative) is evaluated in closed
form on the grid of at most 1 ms plus every knot, as a rotary plan's, and the slide follows from the
mechanism at the crank's own angle (not from the NLP's path coordinate). The checks: the cycle finite and
closed (back at theta_s at rest), continuous at every knot; each swing turning one way only (forward, then
backward), standing at its ends, never past TDC; each swing's draw between its theta2 and theta3 at one crank
speed; the robot's two windows (the forward swing's theta4 through the turn to the backward swing's theta1, and
back) each at least the transfer time with the slide at or above the safety height, or with robots each robot
on its interference curve in both windows between the draws (``planning.solver.pendulum_robots``); the least
crank speed in the draws; the die speed at and below the die height and where each swing crosses it; the slide's
speed at each swing's theta2; and every other limit of the case by its own dense check (``Limit.check``, on
|crank speed|).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from planning.model.case import RPM, Case
from planning.model.drive import cycle_integrals, drive_figures
from planning.model.limits import limits_of
from planning.model.limits.base import Check, Dense
from planning.model.limits.hold import HoldLimit, hold_check
from planning.model.pendulum import SWINGS, PendulumPlan, swing_forming_N, swing_of, time_at, windows_of
from planning.model.profile import sample_times
from planning.solver.peak_shaving import power_columns, power_figures
from planning.solver.pendulum_robots import WINDOWS, robot_checks
from planning.solver.verify import (
    CheckId,
    Evaluation,
    Verification,
    continuity_checks,
    energy_balance,
    power_checks,
)
from planning.tolerances import (
    ACCEL_CLOSE_TOL_RAD_S2,
    ANGLE_TOL_RAD,
    HOLD_STILL_RAD_S,
    LIMIT_REL_TOL,
    SPEED_TOL_RAD_S,
    TIME_TOL_S,
)
from press.dynamics import drive_state
from press.mechanism import slider_motion

OWN_CHECKS = (  # held here
    "transfer_time",
    "safety_height",
    "min_crank_speed",
    "die_speed",
    "draw_start_speed",
    "robots",
    "hold",
)


def evaluate_pendulum(plan: PendulumPlan, case: Case, cam: bool = False) -> Evaluation:
    """The dense re-simulation of ``plan`` against ``case`` and every check (module docstring). ``cam``: the
    profile is a cam as its controller runs it (``planning.solver.cam_proof``): the law's own checks (continuous
    at its knots, one way per swing and at rest at the turns to ``SPEED_TOL_RAD_S`` and ``HOLD_STILL_RAD_S``,
    each draw at one speed) are not the cam's; the cycle closes, never passes TDC, and every limit of the press
    and the process holds."""
    prof = plan.profile
    kinks = _breakpoints(plan, case) if case.drive is not None else prof.knot_times  # (the forming force's too)
    t, uniform = sample_times(plan.period, kinks)
    th, om, al, je = prof.at_time(t)
    h, d1, d2, d3 = case.machine.jets(th)
    _, v, a, slide_jerk = slider_motion(h, d1, d2, d3, om, al, je)
    try:
        keys = plan.key_times("forward")
    except ValueError:  # a swing that turns before a key angle: _swing_checks fails it
        keys = np.full(4, np.nan)
    dense = Dense(case, plan, t, th, om, al, je, h, v, a, keys, slide_jerk=slide_jerk, slope=d1, curvature=d2)
    checks = _cycle_checks(dense, cam) + _swing_checks(dense, cam)
    figures, columns = None, None
    if case.drive is not None:  # the drive on either swing (``press.dynamics``: signed speeds)
        dense.drive_state = drive_state(th, om, al, case.machine, case.drive_model, swing_forming_N(case, th, om, h))
        swings = (kinks, _forming(case))
        dense.integrals = cycle_integrals(prof, case, swings)
        checks.append(energy_balance(dense.integrals))
        figures = drive_figures(prof, case, dense.integrals, (th, dense.drive_state))
        if case.electrical:  # the power chain to the grid, a cycle's (``planning.solver.peak_shaving``)
            dense.power = power_figures(prof, case, t, dense.drive_state, True, swings)
            checks += power_checks(dense.power, dense.integrals, case.drive.storage is not None)
            columns = power_columns(dense.power.schedule, dense.drive_state, t, case)
            figures = replace(figures, power=dense.power)
    magnitude = replace(dense, omega=np.abs(om))  # the limits of the crank's speed read its magnitude
    for limit in limits_of(case):
        if limit.id not in OWN_CHECKS:
            checks += limit.check(magnitude)
    verification = Verification(tuple(checks), float(np.max(np.diff(t))), int(t.size))
    return Evaluation(dense, uniform, verification, figures, columns)


def _forming(case: Case) -> Any:
    """The forming force [N] at crank states ``(theta, omega)`` on either swing."""

    def forming(theta: np.ndarray, omega: np.ndarray) -> np.ndarray:
        return swing_forming_N(case, theta, omega, case.machine.height(theta))

    return forming


def _breakpoints(plan: PendulumPlan, case: Case) -> np.ndarray:
    """Where the drive's integrands may kink [s]: every knot, and on each swing where it passes theta2, BDC and
    the forming table's heights (the forming force starts, ends and kinks there)."""
    m, spans = case.machine, plan.swing_spans()
    times = list(plan.profile.knot_times)
    heights = [h for h, _ in (case.process.forming_force_kN or []) if 0 < h < m.stroke]
    for swing, (lo, hi) in spans.items():
        keys = plan.forward_keys if swing == "forward" else plan.backward_keys
        angles = [keys[1], float(m.bdc_angle)]
        for hh in heights:  # where each swing comes down through the height
            side = m.angles_at_height(hh)
            angles.append(float(side[0] if swing == "forward" else side[1]))
        for angle in angles:
            try:
                times.append(time_at(plan.profile, angle, lo, hi))
            except ValueError:  # the swing does not reach it
                continue
    return np.unique(np.asarray(times, dtype=float))


def _cycle_checks(d: Dense, cam: bool) -> list[Check]:
    """Finite, closed (at theta_s at rest again), continuous at every knot, never past TDC."""
    plan = d.plan
    finite = bool(np.all(np.isfinite(np.concatenate([d.theta, d.omega, d.alpha, d.h, d.v, d.a]))))
    out = [Check.of(CheckId.FINITE, "trajectory finite", 1.0 if finite else math.nan, 1.0, "", "equal", 0.0)]
    end = plan.profile.at_time(np.array([0.0, plan.period]))
    gap = math.degrees(end[0][1] - end[0][0])
    out.append(
        Check.of(
            CheckId.CYCLE_ANGLE, "back at the swing's start", gap, 0.0, "deg", "equal", math.degrees(ANGLE_TOL_RAD)
        )
    )
    if cam:  # a cam repeats: its speed closes (a table's ramps need not stand still at a point)
        speeds, name = float(end[1][1] - end[1][0]) / RPM, "speed closes"
    else:
        speeds, name = float(np.max(np.abs(end[1]))) / RPM, "at rest at the swing's start"
    out.append(Check.of(CheckId.SPEED_CLOSES, name, speeds, 0.0, "rpm", "equal", SPEED_TOL_RAD_S / RPM))
    accel = float(end[2][1] - end[2][0])
    out.append(
        Check.of(CheckId.ACCEL_CLOSES, "acceleration closes", accel, 0.0, "rad/s^2", "equal", ACCEL_CLOSE_TOL_RAD_S2)
    )
    out += [] if cam else continuity_checks(plan.profile)
    tol = math.degrees(ANGLE_TOL_RAD)
    low, high = math.degrees(float(np.min(d.theta))), math.degrees(float(np.max(d.theta)))
    out.append(Check.of("swing_after_tdc", "lowest crank angle (never back past TDC)", low, 0.0, "deg", "min", tol))
    out.append(Check.of("swing_before_tdc", "highest crank angle (never on past TDC)", high, 360.0, "deg", "max", tol))
    return out


def _swing_checks(d: Dense, cam: bool) -> list[Check]:
    """Each swing one way, the draws, the windows, the least crank speed, the die and draw-start speeds (a
    cam: the law's own, one way, at rest at the turns and the draws at one speed, left out)."""
    plan, case = d.plan, d.case
    spans = plan.swing_spans()
    try:
        times = {swing: plan.key_times(swing) for swing in SWINGS}
    except ValueError:  # a swing that turns before one of its key angles: nothing more to check of it
        tol = math.degrees(ANGLE_TOL_RAD)
        return [Check.of(CheckId.KEY_ANGLES, "each swing passes its key angles", math.nan, 0.0, "deg", "equal", tol)]
    out = [] if cam else _law_checks(d, spans, times)
    if case.robots is None:
        out += _window_checks(d, times)
    else:  # each window from a swing's theta3 to the next swing's theta2 (``planning.solver.pendulum_robots``)
        f, b = times["forward"], times["backward"]
        windows = {WINDOWS[0]: (f[2], b[1]), WINDOWS[1]: (b[2], f[1] + d.plan.period)}
        out += robot_checks(d, windows)
    least = case.limits.min_crank_speed_rpm
    draws = [np.abs(d.omega[(d.t >= t[1]) & (d.t <= t[2])]) for t in times.values()]
    slowest = min(float(np.min(w, initial=np.inf)) for w in draws)
    name = "crank speed in the draws (the swings turn at rest)"
    out.append(Check.of("min_crank_speed", name, slowest / RPM, least, "rpm", "min", LIMIT_REL_TOL * least))
    out.append(_draw_start_check(d, times))
    out.append(_die_check(d, spans))
    if case.process.hold_time_s is not None:
        out += _hold_checks(d, spans)
    return out


def _hold_checks(d: Dense, spans: dict[str, tuple[float, float]]) -> list[Check]:
    """The hold on each swing: the longest run of samples within the swing with the crank standing and the slide
    within ``HOLD_STILL_MM`` of its hold height lasts at least the hold time (``planning.model.limits.hold``)."""
    name = "{} swing: " + HoldLimit.name
    return [hold_check(d, (d.t >= lo) & (d.t <= hi), name.format(swing)) for swing, (lo, hi) in spans.items()]


def _law_checks(d: Dense, spans: dict[str, tuple[float, float]], times: dict[str, np.ndarray]) -> list[Check]:
    """The plan's own: each swing turning one way only, its draw at one crank speed, the crank at rest where
    the plan turns."""
    out = []
    for swing, sign in zip(SWINGS, (1.0, -1.0), strict=True):
        lo, hi = spans[swing]
        inside = (d.t >= lo) & (d.t <= hi)
        wrong_way = float(np.max(-sign * d.omega[inside], initial=0.0)) / RPM
        name = f"{swing} swing turning {'back' if sign < 0 else 'forward'} only"
        out.append(Check.of("swing_direction", name, wrong_way, 0.0, "rpm", "equal", SPEED_TOL_RAD_S / RPM))
        out.append(_draw_check(d, swing, times[swing]))
    standing = np.array([swing_of(s.name) == "turn" for s in d.plan.profile.segments])
    out.append(_standstill_check(d, standing))
    return out


def _draw_check(d: Dense, swing: str, keys: np.ndarray) -> Check:
    """The swing's draw, theta2 to theta3, at one crank speed."""
    _, t2, t3, _ = keys
    draw = (d.t >= t2) & (d.t <= t3)
    w = np.abs(d.omega[draw])
    off = float(np.max(w) - np.min(w)) / RPM
    return Check.of(
        CheckId.DRAW_CONSTANT, f"{swing} draw at constant crank speed", off, 0.0, "rpm", "equal", SPEED_TOL_RAD_S / RPM
    )


def _standstill_check(d: Dense, standing: np.ndarray) -> Check:
    """The crank stands where the plan turns (its ``turn:standstill`` segments)."""
    tk = d.plan.profile.knot_times
    moving = 0.0
    for k in np.flatnonzero(standing):
        inside = (d.t >= tk[k]) & (d.t <= tk[k + 1])
        moving = max(moving, float(np.max(np.abs(d.omega[inside]), initial=0.0)))
    return Check.of(
        "swing_turn", "crank at rest at the swings' ends", moving / RPM, 0.0, "rpm", "equal", HOLD_STILL_RAD_S / RPM
    )


def _window_checks(d: Dense, times: dict[str, np.ndarray]) -> list[Check]:
    """The robot's two windows, each through a turn: at least the transfer time, the slide at or above the
    safety height all through it (the ends exactly)."""
    case, period = d.case, d.plan.period
    windows = windows_of(times["forward"], times["backward"], period)
    out = []
    shortest, lowest = math.inf, math.inf
    for start, end in windows.values():
        shortest = min(shortest, end - start)
        inside = ((d.t >= start) & (d.t <= end)) | (d.t + period <= end)
        lowest = min(lowest, float(np.min(d.h[inside], initial=np.inf)))
    ends = case.machine.height(np.array([*d.plan.forward_keys[::3], *d.plan.backward_keys[::3]]))
    lowest = min(lowest, float(np.min(ends)))
    transfer, safety = case.process.transfer_time_s, case.process.safety_height_mm
    out.append(
        Check.of(
            "transfer_time",
            "transfer time theta4 -> turn -> theta1 (both turns)",
            shortest,
            transfer,
            "s",
            "min",
            TIME_TOL_S,
        )
    )
    out.append(
        Check.of(
            "safety_height",
            "slider at or above the safety height through both windows",
            lowest,
            safety,
            "mm",
            "min",
            LIMIT_REL_TOL * safety,
        )
    )
    return out


def _draw_start_check(d: Dense, times: dict[str, np.ndarray]) -> Check:
    """The slide's speed where each swing's draw starts."""
    t2 = np.array([times[s][1] for s in SWINGS])
    th, om, al, je = d.plan.profile.at_time(t2)
    v2 = float(np.max(np.abs(d.case.machine.slider(th, om, al, je)[1])))
    limit = d.case.limits.draw_start_speed_mm_s
    return Check.of(
        "draw_start_speed", "slider speed at each swing's draw start", v2, limit, "mm/s", "max", LIMIT_REL_TOL * limit
    )


def _die_check(d: Dense, spans: dict[str, tuple[float, float]]) -> Check:
    """|slide speed| at and below the die height, at the samples and where each swing crosses it."""
    m, lim = d.case.machine, d.case.limits
    low = d.h <= lim.die_height_mm
    speeds = [float(np.max(np.abs(d.v[low]), initial=0.0))]
    for angle in (float(a) for a in m.angles_at_height(min(lim.die_height_mm, m.stroke))):
        for lo, hi in spans.values():
            t = time_at(d.plan.profile, angle, lo, hi)
            th, om, al, je = d.plan.profile.at_time(np.array([t]))
            speeds.append(float(np.abs(m.slider(th, om, al, je)[1][0])))
    limit = lim.die_speed_mm_s
    return Check.of(
        "die_speed", "slider speed at or below the die height", max(speeds), limit, "mm/s", "max", LIMIT_REL_TOL * limit
    )
