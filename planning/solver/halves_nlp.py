"""The NLP of one press cycle under a motion law with halves (every law but the optimal one).

Built once per process and kind (``planning.solver.nlp``), then reused: every number of a case, and the
scale of every decision variable (:func:`variable_scales`, applied by the solver wrapper
``planning.solver.ipopt``), enters as a parameter and the placement structure is a pair of constraint rows
whose bounds are set per solve, so a sweep, a multi-start or the other placement only calls the compiled
solver again. Decision variables are scaled to O(1): the four speeds w1, w2, wm1, wm2, the durations of
the four halves, the transfer dwell, the law's shape parameter and the times of the key points.

Time 0 of the NLP is the end of the draw (theta3); the stages follow as in ``planning.model.cycle``. The
crank angle at any time t before the draw is evaluated in closed form as
``theta(t) = theta3 + sum_k D_k(clip(t - s_k, 0, T_k))``, with ``D_k`` the angle swept ``tau`` into
segment k. The clip makes theta(t) continuously differentiable in t and in every segment variable
(the kink of one term is cancelled by the next), so a key point may move across knots inside one
smooth NLP: that is the ``free`` placement. The ``published`` placement fixes the key points where
the relations under the paper's Fig. 6 put them: t1 = x1 + T1 (a quarter, one sub-segment, into the
feed acceleration), t4 = x3 + 3 T14 (three quarters into the return deceleration).

The cycle's own rows: the peaks lie above the speeds they join (each half is then monotone: the crank
speed is smallest at w1 or w2, which the variable bounds keep above the minimum crank speed), one jerk
per S-curve (Eq. 14, improved S-curve only), the cycle closes at 2 pi, the key angles theta1 and theta4
are met, the key points in order, the die-height crossings outside the draw at their angles. Then the
rows of every limit the case sets (``planning.model.limits``), from the states at sample points of every
segment before the draw (the slider acceleration, a target rate's die zone; the search lowers a sampled
limit until the dense verification holds between samples), the drive's torque at those and the draw's
samples, the die-height crossings, the robot's window t1 - t4, and the closed-form extremes of the
halves: the peak speeds, the peak acceleration and jerk of every half. In the draw the crank turns at
the constant w2, so each limit there is a bound on w2 (every limit's draw-speed bound), a variable
bound: the kinematic NLP has no samples in the draw.

The drive NLPs (motor torque rows, the RMS integral) sample the draw at its fixed angles theta2 ...
theta3 at the constant speed w2 instead of following the cycle's closed form there: the two agree
wherever the cycle closes (a constraint every solution meets), and the draw's rows then depend on w2
alone (sparse rows; on the side-panel drive a quarter fewer iterations and about half the time per
iteration, same optima). The rate NLP (``planning.solver.objectives``) adds the objectives' terms, the rows of
the die zone at every sample (a plan at a target rate may peak in speed there) and the cycle time.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cache, partial
from typing import Any

import casadi as ca
import numpy as np

from planning.model.case import RPM, Case, Placement
from planning.model.cycle import DRAW_SEGMENT, HALVES, CycleParameters, cycle_segments
from planning.model.laws import get_law
from planning.model.limits.base import Extremes, Transcription
from planning.model.plan import Plan, SolverInfo, plan_of
from planning.model.profile import Segment, advance_segment, knot_states, shape_part
from planning.solver.ipopt import NLPSolver
from planning.solver.nlp import (
    CYCLE_OPTIONS,
    DRIVE_OPTIONS,
    RATE_OPTIONS,
    CycleNLP,
    Rows,
    add_limit_rows,
    bus_power_samples,
    clipped_advance,
    draw_states,
    nlp_limits,
    objective_terms,
    sample_states,
)
from planning.solver.parameters import (
    DRAW_SAMPLES_DRIVE,
    EXIT_SAMPLES,
    ParameterLayout,
    drive_links,
    share_name,
    time_limit,
)
from press.mechanism import Formula

# Decision variables and the kind of scale each is measured in (see :func:`variable_scales`)
VARIABLES: tuple[tuple[str, str], ...] = (
    ("transfer_speed", "speed"),  # w1 [rad/s]
    ("draw_speed", "speed"),  # w2 [rad/s]
    ("feed_peak_speed", "speed"),  # wm1 [rad/s]
    ("return_peak_speed", "speed"),  # wm2 [rad/s]
    ("feed_accel_duration", "half"),  # [s] each half
    ("feed_decel_duration", "half"),
    ("return_accel_duration", "half"),
    ("return_decel_duration", "half"),
    ("transfer_dwell", "time"),  # [s]
    ("law_parameter", "shape"),  # the motion law's shape parameter (fixed at 0 when it has none)
    ("closing_time", "time"),  # t1 from the end of the draw [s]
    ("opening_time", "time"),  # t4
    ("die_down_time", "time"),  # time of the descending die-height crossing
    ("die_up_time", "time"),  # time of the ascending die-height crossing
)
VARIABLE_INDEX = {name: i for i, (name, _) in enumerate(VARIABLES)}
# the rate NLP of the least grid peak adds the bus power's peak at the samples [W] (an epigraph variable)
PEAK_VARIABLE = ("bus_peak", "power")
# the denser variant adds the times at which the crank passes the die exit's angles (from theta3) [s]
EXIT_VARIABLES = tuple((f"die_exit_time_{k}", "time") for k in range(EXIT_SAMPLES))
# with robots (``planning.model.limits.robots``) each robot's start [s from theta3], after every other variable
ROBOT_VARIABLES = (("unloader_start", "time"), ("loader_start", "time"))
SAMPLES_CONSTANT = 20  # samples on the constant-speed transfer dwell
MIN_HALF_S = 4e-3  # [s] lower bound on the duration of a half (1 ms per improved-S-curve sub-segment)
TOP_SPEED = 1e3  # [rad/s] upper bound of the crank speeds (far above any press)


def variable_scales(case: Case) -> np.ndarray:
    """Variable scales from the press's own characteristic time ``T* = sqrt(l / A)`` [s] and speed
    ``W* = sqrt(A / k)`` [rad/s] (A the slider-acceleration limit, l the mechanism's length unit, half the
    stroke, k its peak curvature ``max |d2h/dtheta2|``): speeds ~ W*, durations of the halves ~ T*, stage
    times ~ 10 T* (and a hold's time). The factors make the variables O(1) for a press cycle of the usual
    proportions; they span orders of magnitude from a small fast press to a heavy slow one."""
    m, A = case.machine, case.limits.slider_accel_mm_s2
    t_star = math.sqrt(m.length_scale / A)
    w_star = math.sqrt(A / m.peak_curvature)
    time = 2.8 * t_star + case.standstill_s  # a hold's time is in every time after the draw's end
    unit = {"speed": 0.42 * w_star, "half": 1.12 * t_star, "time": time, "shape": 1.0}
    return np.array([unit[kind] for _, kind in VARIABLES])


def variable_bounds(
    case: Case, layout: ParameterLayout, w2_lo: float, w2_hi: float, parameters: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of the variables: the speeds above the minimum crank speed (the halves are monotone, so the
    whole cycle is), the draw speed within its bounds, the halves at least :data:`MIN_HALF_S`, the law's
    shape parameter in its range (or fixed), a die crossing's time fixed where it lies in the draw."""
    w_min = case.limits.min_crank_speed_rpm * RPM
    lo = np.zeros(len(VARIABLES))
    hi = np.full(len(VARIABLES), time_limit(case))
    i = VARIABLE_INDEX
    lo[i["transfer_speed"]], hi[i["transfer_speed"]] = w_min, TOP_SPEED
    lo[i["draw_speed"]], hi[i["draw_speed"]] = w2_lo, w2_hi
    for k in ("feed_peak_speed", "return_peak_speed"):
        lo[i[k]], hi[i[k]] = w_min, TOP_SPEED
    for k in HALVES:
        lo[i[f"{k}_duration"]] = MIN_HALF_S
    law = get_law(case.planner.motion_law)
    fixed = case.planner.law_parameter
    if law.parameter is None:
        lo[i["law_parameter"]] = hi[i["law_parameter"]] = 0.0
    elif fixed is not None:
        lo[i["law_parameter"]] = hi[i["law_parameter"]] = fixed
    else:
        lo[i["law_parameter"]], hi[i["law_parameter"]] = law.parameter.low, law.parameter.high
    for k in ("die_down", "die_up"):
        if parameters[layout.index(f"{k}_active")] == 0.0:
            lo[i[f"{k}_time"]] = hi[i[f"{k}_time"]] = 0.0
    return lo, hi


def exit_variable_scales(case: Case) -> np.ndarray:
    """:func:`variable_scales` and the die exit's times' (the other times' scale)."""
    scales = variable_scales(case)
    return np.append(scales, np.full(EXIT_SAMPLES, scales[VARIABLE_INDEX["die_up_time"]]))


def exit_variable_bounds(
    case: Case, layout: ParameterLayout, w2_lo: float, w2_hi: float, parameters: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`variable_bounds` and the die exit's times: within the cycle, or 0 where it has no exit."""
    lo, hi = variable_bounds(case, layout, w2_lo, w2_hi, parameters)
    top = time_limit(case) if parameters[layout.index("die_exit_active")] else 0.0
    return np.append(lo, np.zeros(EXIT_SAMPLES)), np.append(hi, np.full(EXIT_SAMPLES, top))


def complete_exit(values: dict[str, float]) -> dict[str, float]:
    """``values`` with the die exit's times where a start lacks them: evenly up to the die-height crossing
    (the exit's angles lie evenly from theta3, time 0, to it)."""
    missing = [k for k in range(EXIT_SAMPLES) if f"die_exit_time_{k}" not in values]
    if not missing:
        return values
    up = values["die_up_time"]
    return {**values, **{f"die_exit_time_{k}": up * (k + 1) / (EXIT_SAMPLES + 1) for k in missing}}


def peak_variable_scales(case: Case) -> np.ndarray:
    """:func:`variable_scales` and the bus peak's: the motor's rated torque at its base speed [W]."""
    motor = case.drive.motor
    return np.append(variable_scales(case), motor.rated_torque_Nm * motor.base_speed_rpm * RPM)


def peak_variable_bounds(
    case: Case, layout: ParameterLayout, w2_lo: float, w2_hi: float, parameters: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`variable_bounds` and the bus peak's (free)."""
    lo, hi = variable_bounds(case, layout, w2_lo, w2_hi, parameters)
    return np.append(lo, -np.inf), np.append(hi, np.inf)


def make_plan(case: Case, values: dict[str, float], placement: Placement, info: SolverInfo) -> Plan:
    """The plan of the NLP's variable ``values`` (``planning.model.plan.plan_of``): the law's cycle rotated to
    start at TDC, with where theta1 and theta4 fall and the values themselves."""
    return plan_of(case, values, placement, info)


def angle_at(t: ca.SX, starts: list, states: list, segs: list[Segment]) -> tuple[ca.SX, ca.SX]:
    """Closed-form crank angle and speed at time ``t`` [s] over the segments (clip formulation): the
    linear-jerk parts as one vector, the shape terms of shaped segments added one by one."""
    T = ca.vertcat(*[seg.duration for seg in segs])
    omega0 = ca.vertcat(*[st[1] for st in states])
    alpha0 = ca.vertcat(*[st[2] for st in states])
    j0, j1 = ca.vertcat(*[seg.j0 for seg in segs]), ca.vertcat(*[seg.j1 for seg in segs])
    tau = ca.fmin(ca.fmax(t - ca.vertcat(*starts), 0), T)
    theta, omega = clipped_advance(tau, states[0][0], states[0][1], omega0, alpha0, j0, j1)
    for k, seg in enumerate(segs):
        if seg.shape is not None:
            dth, dom, _, _ = shape_part(seg, tau[k])
            theta, omega = theta + dth, omega + dom
    return theta, omega


@dataclass
class _Cycle:
    """The symbols of one halves NLP: variables ``x`` (scaled), the case's parameters ``p_case`` and the
    variables' scales ``p_scale``; the physical variables ``v`` and their ``unit`` (scale) by name; the
    case's numbers ``q`` by name; the law's cycle (``params``, its segments from theta3, their knot
    ``states`` and start times ``starts``; ``before``: the segments from theta3 to theta2, all but the
    draw, with their starts and states)."""

    x: ca.SX
    p_case: ca.SX
    p_scale: ca.SX
    v: dict[str, ca.SX]
    unit: dict[str, ca.SX]
    q: dict[str, ca.SX]
    params: CycleParameters
    segs: list[Segment]
    states: list
    starts: list
    n_before: int
    names: tuple[str, ...] = ()  # the variables' names, in order
    layout: ParameterLayout | None = None

    @property
    def geometry(self) -> list:
        """The mechanism's geometry parameters' symbols."""
        return self.layout.geometry(self.q)

    @property
    def formula(self) -> Formula:
        return self.layout.formula

    @property
    def before(self) -> tuple[list, list, list[Segment]]:
        n = self.n_before
        return self.starts[:n], self.states[:n], self.segs[:n]


def _cycle(law_name: str, layout: ParameterLayout, variables: tuple) -> _Cycle:
    """The NLP's symbols and the law's cycle laid out from theta3 (:class:`_Cycle`)."""
    x = ca.SX.sym("x", len(variables))
    p_case = ca.SX.sym("p", layout.size)
    p_scale = ca.SX.sym("scale", len(variables))  # physical value = scale * x, chosen per case
    v = {name: x[i] * p_scale[i] for i, (name, _) in enumerate(VARIABLES)}
    unit = {name: p_scale[i] for i, (name, _) in enumerate(VARIABLES)}
    q = layout.symbols(p_case)
    fields = [f for f in CycleParameters.__dataclass_fields__ if f in v]
    hold = {"hold_time": q["hold_time"], "hold_angle": q["hold_angle"]} if layout.hold else {}
    params = CycleParameters(
        **{f: v[f] for f in fields}, draw_start=q["theta2"], draw_end=q["theta3"], motion_law=law_name, **hold
    )
    segs = cycle_segments(params)
    states = knot_states(q["theta3"], params.draw_speed, 0.0, segs)
    starts = [0.0]
    for seg in segs[:-1]:
        starts.append(starts[-1] + seg.duration)
    names = tuple(name for name, _ in variables)
    return _Cycle(x, p_case, p_scale, v, unit, q, params, segs, states, starts, len(segs) - 1, names, layout)


def _shape_rows(rows: Rows, c: _Cycle, law) -> None:  # noqa: ANN001 - a Law
    """The halves monotone (the peaks above the speeds they join), one jerk per S-curve where the law says
    so (Eq. 14), the cycle closed at 2 pi."""
    p, unit = c.params, c.unit
    w1, w2, wr = p.transfer_speed, p.draw_speed, p.return_start_speed  # wr: w2, or 0 after a hold
    wm1, wm2 = p.feed_peak_speed, p.return_peak_speed
    peaks = ca.vertcat(wm1 - w1, wm1 - w2, wm2 - wr, wm2 - w1) / unit["draw_speed"]
    rows.add("peak speeds above their ends", peaks, 0, np.inf, "planner.motion_law")
    if law.one_jerk_per_curve:  # Eq. 14: one jerk J for both halves of each S-curve
        d_fa, d_fd = p.feed_accel_duration, p.feed_decel_duration
        d_ra, d_rd = p.return_accel_duration, p.return_decel_duration
        t2 = unit["feed_accel_duration"] ** 2 * unit["draw_speed"]
        one_jerk = ca.vertcat((wm1 - w1) * d_fd**2 - (wm1 - w2) * d_fa**2, (wm2 - wr) * d_rd**2 - (wm2 - w1) * d_ra**2)
        rows.add("one jerk per S-curve (Eq. 14)", one_jerk / t2, 0.0, 0.0, "planner.motion_law")
    # the cycle closes: theta at the draw start is theta2 + 2 pi
    rows.add("cycle closes", c.states[c.n_before][0] - (c.q["theta2"] + 2 * np.pi), 0.0, 0.0, "key_points")


def _key_point_rows(rows: Rows, c: _Cycle) -> tuple[int, tuple[ca.SX, ca.SX]]:
    """The key angles met in order, the published placement's rows (bounds switched per solve), the
    die-height crossings at their angles; the published rows' place and the crossings' speeds."""
    v, q, params = c.v, c.q, c.params
    t4, t1 = v["opening_time"], v["closing_time"]
    th4, _ = angle_at(t4, *c.before)
    th1, _ = angle_at(t1, *c.before)
    rows.add("key angles", ca.vertcat(th4 - q["theta4"], th1 - (q["theta1"] + 2 * np.pi)), 0.0, 0.0, "key_points")
    t_end = c.starts[c.n_before]
    order = ca.vertcat(t4, t1 - t4, t_end - t1, t_end - v["die_down_time"], t_end - v["die_up_time"])
    rows.add("key points in order", order, 0.0, np.inf, "key_points")
    # published structure (Fig. 6): theta4 at x3 + 3 T14 (three quarters into the return deceleration),
    # theta1 at x1 + T1 (a quarter into the feed acceleration); bounds switched per solve
    rd_start = params.return_accel_duration
    if params.has_hold:  # the brake and the standstill come first
        rd_start = rd_start + params.brake_duration + params.hold_time
    fa_start = rd_start + params.return_decel_duration + params.transfer_dwell
    published = ca.vertcat(
        t4 - (rd_start + 0.75 * params.return_decel_duration),
        t1 - (fa_start + 0.25 * params.feed_accel_duration),
    )
    published_rows = rows.add("key angles (published placement)", published, -np.inf, np.inf, "planner.placement")
    # the die-height crossings outside the draw (a crossing inside it: its row switched off, its time fixed)
    thd, omd = angle_at(v["die_down_time"], *c.before)
    thu, omu = angle_at(v["die_up_time"], *c.before)
    crossing = ca.vertcat(
        q["die_down_active"] * (thd - (q["die_down_angle"] + 2 * np.pi)),
        q["die_up_active"] * (thu - q["die_up_angle"]),
    )
    rows.add("die crossing angles", crossing, 0.0, 0.0, "limits.die_height_mm")
    return published_rows, (omd, omu)


def _exit_rows(rows: Rows, c: _Cycle, first: int) -> list[tuple[ca.SX, ca.SX]]:
    """The crank at the die exit's angles (their times the variables from ``first`` on): a row each that the
    time is the angle's (switched off without an exit); the crank speed there with ``|dh/dtheta|``, which the
    die-speed limit holds (``planning.model.limits.die_speed``)."""
    q = c.q
    out, angles = [], []
    for k in range(EXIT_SAMPLES):
        theta, omega = angle_at(c.x[first + k] * c.p_scale[first + k], *c.before)
        angles.append(q["die_exit_active"] * (theta - q[f"die_exit_angle_{k}"]))
        out.append((omega, q[f"die_exit_slope_{k}"]))
    rows.add("die exit angles", ca.vertcat(*angles), 0.0, 0.0, "limits.die_height_mm")
    return out


def _sampled(c: _Cycle, law, drive: bool) -> tuple[tuple[ca.SX, ca.SX, ca.SX], ca.SX, int, ca.SX]:  # noqa: ANN001
    """The states at sample points of every segment, one vector per quantity, and their times; the draw's
    samples last (``drive`` only: otherwise every limit holds in the draw by the draw speed's bounds); the
    share of the slide-acceleration limit at each sample outside the draw (its segment's parameter)."""
    th_s, om_s, al_s, t_s, shares = [], [], [], [], []
    draw_count = 0
    for seg, st, t0 in zip(c.segs, c.states[:-1], c.starts, strict=True):
        draw = seg.name == DRAW_SEGMENT
        if draw and not drive:
            continue  # every limit holds in the draw by the draw speed's bounds
        count = DRAW_SAMPLES_DRIVE if draw else SAMPLES_CONSTANT if seg.name == "transfer:dwell" else law.samples
        fractions = np.linspace(0.0, 1.0, count + 1)
        if not draw:
            fractions = fractions[:-1]  # the end is the next segment's start
        else:
            draw_count = fractions.size
        if draw:  # sparse rows (see the module docstring)
            th, om, al, since = draw_states(c.q, c.params.draw_speed, ca.DM(fractions))
            t_s.append(t0 + since)
        else:
            th, om, al, _ = advance_segment(seg, *st, ca.DM(fractions) * seg.duration)
            t_s.append(t0 + ca.DM(fractions) * seg.duration)
            shares.append(ca.repmat(c.q[share_name(seg.name)], fractions.size, 1))
        th_s.append(th)
        om_s.append(om)
        al_s.append(al)
    return (ca.vertcat(*th_s), ca.vertcat(*om_s), ca.vertcat(*al_s)), ca.vertcat(*t_s), draw_count, ca.vertcat(*shares)


def _objective(
    rows: Rows, c: _Cycle, torque: ca.SX, states: tuple, times: ca.SX, kind: tuple[bool, bool, bool]
) -> ca.SX:
    """The cycle time; at a rate the objectives' weighted terms; with ``peak`` the grid peak's epigraph.
    ``kind``: ``(rate, peak, losses)``."""
    rate, peak, losses = kind
    q, params = c.q, c.params
    objective = params.period
    if rate:  # without a drive (a kinematic case at a line's rate): the period and the dwell only
        objective = q["weight_period"] * params.period
        if torque is not None:
            heat, energy = objective_terms(q, torque, states[2], times, losses)
            objective = objective + q["weight_heat"] * heat + q["weight_energy"] * energy  # (the sum's old order)
        objective -= q["weight_dwell"] * params.transfer_dwell
    if peak:  # the least grid peak: bus power <= bus_peak at every sample, bus_peak weighed (weight_peak)
        k = len(VARIABLES)  # the peak variable follows the cycle's
        bus_peak, power_unit = c.x[k] * c.p_scale[k], c.p_scale[k]
        bus = bus_power_samples(q, torque)
        rows.add("bus power under its peak", (bus - bus_peak) / power_unit, -np.inf, 0.0, "planner.objective")
        objective += q["weight_peak"] * bus_peak
    return objective


def _transcription(
    c: _Cycle, samples: dict, crossings: tuple[ca.SX, ca.SX], exit_speeds: list, zone: bool, rate: bool
) -> Transcription:
    """What the limits' rows read of this NLP (``planning.model.limits.base.Transcription``): the samples'
    states, the period, the robot's window, the extremes of the halves, the die crossings' speeds; with robots
    the slide's height at any time and their starts (:func:`_robot_terms`)."""
    p = c.params
    omd, omu = crossings
    return Transcription(
        **_robot_terms(c),
        **samples,
        period=p.period,
        window_time=c.v["closing_time"] - c.v["opening_time"],
        # the halves are monotone in speed: its extremes are the speeds they join
        speeds=Extremes(ca.vertcat(p.feed_peak_speed, p.return_peak_speed, p.transfer_speed, p.draw_speed)),
        accelerations=Extremes(ca.vertcat(*p.peak_accelerations())),
        jerks=Extremes(ca.vertcat(*p.peak_jerks())),
        lowest_speeds=None,  # the variable bounds of w1, w2 (the halves are monotone)
        crossings=[(omd, c.q["die_down_slope"]), (omu, c.q["die_up_slope"])],
        exit_speeds=exit_speeds,
        zone=zone,
        rate=rate,
        speed_unit=c.unit["draw_speed"],
    )


def _robot_terms(c: _Cycle) -> dict:
    """The robots' part of the transcription where the NLP has their starts (the last variables): the slide's
    height at any time (the closed-form angle over every segment, the draw last, at the time within the period:
    ``h(theta(t))`` is periodic, so the wrap is smooth), their starts, theta2's time."""
    names = [name for name, _ in ROBOT_VARIABLES]
    first = len(c.names) - len(names)
    if tuple(c.names[first:]) != tuple(names):
        return {}
    period = c.params.period
    geometry = c.geometry

    def height_at(times: list) -> ca.SX:
        wrapped = [t - period * ca.floor(t / period) for t in times]
        theta = ca.vertcat(*[angle_at(t, c.starts, c.states[:-1], c.segs)[0] for t in wrapped])
        return c.formula.jets(theta, geometry)[0]

    starts = {name.removesuffix("_start"): c.x[first + k] * c.p_scale[first + k] for k, name in enumerate(names)}
    return {"height_at": height_at, "robot_starts": starts, "draw_start_time": c.starts[c.n_before]}


def robot_scales(scales: Callable[[Case], np.ndarray], case: Case) -> np.ndarray:
    """``scales(case)`` and the robots' starts' (the other times' scale)."""
    base = scales(case)
    return np.append(base, [base[VARIABLE_INDEX["closing_time"]]] * len(ROBOT_VARIABLES))


def robot_bounds(bounds: Callable[..., tuple], case: Case, *args: Any) -> tuple[np.ndarray, np.ndarray]:
    """``bounds(case, ...)`` and the robots' starts': within a period either side of theta3."""
    lo, hi = bounds(case, *args)
    top = time_limit(case)
    return np.append(lo, [-top] * len(ROBOT_VARIABLES)), np.append(hi, [top] * len(ROBOT_VARIABLES))


def complete_robots(complete: Callable | None, values: dict[str, float]) -> dict[str, float]:
    """``values`` (``complete`` applied first) with the robots' starts where a start lacks them: the unloader
    leaving at theta4, the loader halfway from theta4 to theta1."""
    values = dict(values if complete is None else complete(values))
    if "unloader_start" not in values:
        values["unloader_start"] = values["opening_time"]
        values["loader_start"] = 0.5 * (values["opening_time"] + values["closing_time"])
    return values


def _build(
    law_name: str,
    formula: Formula,
    limit_ids: tuple[str, ...],
    drive: bool,
    rate: bool,
    zone: bool,
    links: tuple[str, ...] = (),
    peak: bool = False,
    losses: bool = False,
    hold: bool = False,
) -> CycleNLP:
    law = get_law(law_name)
    die_exit = zone and not rate  # the denser variant: the die exit held at its angles (smooth rows)
    zone = rate  # the rate NLP: every sample in the die zone held (its crank speed may peak there)
    layout = ParameterLayout(formula, limit_ids, drive, rate, links if drive else (), die_exit, hold)
    robots = "robots" in limit_ids
    variables = VARIABLES + ((PEAK_VARIABLE,) if peak else ()) + (EXIT_VARIABLES if die_exit else ())
    variables += ROBOT_VARIABLES if robots else ()
    segments = _cycle(law_name, layout, variables).segs  # their names: one share of the slide's limit each
    layout = replace(layout, shared_segments=tuple(seg.name for seg in segments if seg.name != DRAW_SEGMENT))
    c = _cycle(law_name, layout, variables)
    rows = Rows()
    _shape_rows(rows, c, law)
    published_rows, (omd, omu) = _key_point_rows(rows, c)
    exit_speeds = _exit_rows(rows, c, len(VARIABLES) + int(peak)) if die_exit else []
    states, times, draw_count, shares = _sampled(c, law, drive)
    samples, torque, lift = sample_states(formula, layout, c.q, c.p_case, states, times, draw_count)
    samples["accel_shares"] = shares
    nlp = _transcription(c, samples, (omd, omu), exit_speeds, zone, rate)
    refinable = add_limit_rows(rows, nlp, layout)
    objective = _objective(rows, c, torque, states, times, (rate, peak, losses))
    problem = {"x": c.x, "p": ca.vertcat(c.p_case, c.p_scale), "f": objective, "g": ca.vertcat(*rows.g)}
    kind = ("_rate" if rate else "_drive" if drive else "") + ("_kinematic" if rate and not drive else "")
    kind += "_exit" if die_exit else ""
    kind += ("_peak" if peak else "") + ("_losses" if losses else "") + ("_hold" if hold else "")
    options = {**CYCLE_OPTIONS, **(DRIVE_OPTIONS if drive else {}), **(RATE_OPTIONS if rate else {})}
    program = NLPSolver("press_cycle_" + law_name.replace("-", "_") + kind, problem, options, lift=lift)
    scales = peak_variable_scales if peak else exit_variable_scales if die_exit else variable_scales
    bounds = peak_variable_bounds if peak else exit_variable_bounds if die_exit else variable_bounds
    denser = None
    if not (zone or die_exit):
        denser = partial(halves_nlp, law_name, formula, limit_ids, drive, rate, True, links, hold=hold)
    complete = complete_exit if die_exit else None
    if robots:
        scales, bounds = partial(robot_scales, scales), partial(robot_bounds, bounds)
        complete = partial(complete_robots, complete)
    return CycleNLP(
        program,
        *rows.bounds(),
        tuple(rows.blocks),
        layout,
        variables,
        scales,
        bounds,
        make_plan,
        published_rows,
        refinable,
        denser,
        complete,
    )


@cache
def halves_nlp(
    law: str,
    formula: Formula,
    limit_ids: tuple[str, ...],
    drive: bool = False,
    rate: bool = False,
    zone: bool = False,
    links: tuple[str, ...] = (),
    peak: bool = False,
    losses: bool = False,
    hold: bool = False,
) -> CycleNLP:
    """The compiled NLP of motion law ``law`` on a mechanism of closed form ``formula`` holding the limits
    ``limit_ids``, with the motor's torque when ``drive`` (the mechanism's massive ``links`` in it);
    ``rate``: the NLP of a target rate (see the module docstring; without ``drive``: the period held, the
    transfer dwell weighed, a kinematic case at a line's rate); ``zone``: the limits that hold in
    the die zone held at every sample there (the rate NLP's always; otherwise the denser variant a search
    turns to when a plan's crank speed peaks inside the die zone, between the crossings); ``peak``: the rate
    NLP with the bus power's peak as a variable (:data:`PEAK_VARIABLE`; the least grid peak); ``losses``: its
    supply energy through the copper loss and the converter (``planning.solver.nlp.objective_terms``);
    ``hold``: the crank brakes after the draw and stands (``planning.model.cycle``). Built on first use in a
    process, then reused for every case and start."""
    return _build(law, formula, limit_ids, drive, rate, zone, links, peak, losses, hold)


def halves_nlp_for(case: Case, drive: bool | None = None, rate: bool = False, peak: bool = False) -> CycleNLP:
    """The NLP of ``case``'s law, mechanism and limits; ``drive`` None: with the motor's rows when the case
    has a drive; ``rate``, ``peak``: see :func:`halves_nlp`."""
    drive = case.drive is not None if drive is None else drive
    limit_ids = nlp_limits(case, drive or rate)
    links = drive_links(case) if drive or rate else ()
    d = case.drive
    losses = rate and d is not None and d.has_losses
    law, formula, hold = case.planner.motion_law, case.machine.formula, case.hold_angle is not None
    return halves_nlp(law, formula, limit_ids, drive, rate, False, links, peak, losses, hold)


def fresh_build(case: Case) -> CycleNLP:
    """The NLP :func:`halves_nlp_for` gives ``case``, built anew (not from the cache): what a build costs."""
    drive = case.drive is not None
    limit_ids = nlp_limits(case, drive)
    links = drive_links(case) if drive else ()
    hold = case.hold_angle is not None
    return _build(case.planner.motion_law, case.machine.formula, limit_ids, drive, False, False, links, hold=hold)
