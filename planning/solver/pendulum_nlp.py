"""The NLP of a pendulum stroke (``planning.model.pendulum``), built once a case.

Under a law with halves as below; under the optimal law each swing's variables and own rows are
``planning.solver.pendulum_free``'s (a free jerk profile), the cycle's rows (the windows or the robots, the drive,
the objective) as below.

Both swings in one NLP, each on its own path coordinate u (the forward swing's u is the crank angle, the
backward swing's ``2 pi - theta``, its mechanism ``h_b(u) = h(2 pi - u)``), each a forward motion with
speeds >= 0. Variables (scaled to O(1) like the halves NLP's, ``planning.solver.halves_nlp.variable_scales``):
per swing w2, wm1, wm2, the four halves' durations, the times ``t1`` (from the swing's start to theta1) and
``t4`` (from theta3 to theta4), the times from theta3 to the return's die-zone angles
(``planning.model.pendulum.die_zone``); the swing's ends theta_s and theta_e (bounded by
:func:`~planning.model.pendulum.swing_bounds`), the standstills there, the law's shape parameter; with robots
each robot's start in each window (``planning.solver.pendulum_robots``). Parameters: the sampled limits' values
(:func:`sampled_limit_values`; the search lowers one the dense check finds exceeded between samples, or raises
the robots' needs where a clearance is lost between them, and solves again, :meth:`PendulumNLP.at`).

Rows per swing: the feed reaches theta2 and the return the swing's end (the halves' closed forms from rest and
from theta3; the speeds there hold by construction), the peaks at or above the speeds they join (each half
monotone), one jerk per S-curve where the law says so (Eq. 14), t1 and t4 at their angles, the peak
acceleration and jerk of each half (closed form), the slide's acceleration and speed at ``law.samples`` points
of every segment of the halves (the acceleration held ``ACCEL_BACKOFF`` inside), the slide's speed at the
return's die-zone angles (with a hold, the brake and the standstill are the return's first segments). In the
draw the crank turns at the constant w2, so each limit there is a bound on w2
(``planning.model.pendulum.draw_speed_bound``), a variable bound. With a drive, the motor's and the crank's
torque rows and the grid's cap (``planning.solver.pendulum_drive``). Across the swings: the robot's two windows
(theta4 through the turn at theta_e to the backward swing's theta1, and the backward swing's theta4 through
theta_s to theta1) each at least the transfer time, or with robots their rows in both windows. The objective:
the cycle time (both swings and both standstills); at a target rate (``planner.objective`` with
``planner.target_spm``, a drive) the cycle held at that rate's time and the weighed heat and supply energy of
the motor (``planning.solver.pendulum_drive.rate_terms``) instead, their weights parameters
(:data:`RATE_PARAMETERS`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any

import casadi as ca
import numpy as np

from planning.model.case import RPM, Case
from planning.model.free_swing import FREE_LAW
from planning.model.laws import get_law
from planning.model.limits import limits_of
from planning.model.limits.capacity import torque_capacity_kNm
from planning.model.limits.grid import NO_STORAGE_J, GridPeakLimit
from planning.model.pendulum import (
    DIE_ZONE_POINTS,
    SWING_HALVES,
    SWINGS,
    TURN_SEGMENT,
    TWO_PI,
    PendulumParameters,
    PendulumPlan,
    SwingParameters,
    SwingSetup,
    backward_key_angles,
    profile_of,
    reversed_segment,
    swing_bounds,
    swing_setups,
)
from planning.model.plan import SolverInfo
from planning.model.profile import Profile, Segment
from planning.solver.halves_nlp import MIN_HALF_S, TOP_SPEED, VARIABLE_INDEX, angle_at, variable_scales
from planning.solver.ipopt import NLPSolver
from planning.solver.nlp import RATE_OPTIONS, Rows
from planning.solver.parameters import time_limit
from planning.solver.pendulum_drive import bus_peak_rows, drive_rows, rate_terms, swing_drive
from planning.solver.pendulum_free import (
    FREE_SWING_VARIABLES,
    STEP_SCALE,
    TOP_SPEED_PARAMETER,
    free_parameters,
    free_swing,
    free_swing_rows,
    jerk_scale,
    jerk_tie_break,
    variable_bound,
)
from planning.solver.pendulum_robots import (
    NEED_FACTOR,
    ROBOTS_CHECK,
    WINDOWS,
    CycleTimes,
    first_starts,
    plan_starts,
    robot_rows,
    start_variables,
)
from planning.solver.pendulum_swing import SwingSymbols, sampled_rows, segments_from
from planning.tolerances import ACCEL_BACKOFF, DRIVE_BACKOFF, IPOPT_CONSTR_VIOL_TOL, REFINE_MARGIN

SWING_VARIABLES = (  # per swing, prefixed ``forward_`` / ``backward_``: (name, scale kind of the halves NLP)
    ("draw_speed", "draw_speed"),
    ("feed_peak_speed", "draw_speed"),
    ("return_peak_speed", "draw_speed"),
    ("feed_accel_duration", "feed_accel_duration"),
    ("feed_decel_duration", "feed_accel_duration"),
    ("return_accel_duration", "feed_accel_duration"),
    ("return_decel_duration", "feed_accel_duration"),
    ("closing_time", "closing_time"),
    ("opening_time", "closing_time"),
    *((f"die_time_{k}", "closing_time") for k in range(DIE_ZONE_POINTS)),  # from theta3 to the die zone's angles
)
SHARED_VARIABLES = (
    ("swing_start", None),  # theta_s [rad]
    ("swing_end", None),  # theta_e [rad]
    ("turn_end_s", "closing_time"),
    ("turn_start_s", "closing_time"),
    ("law_parameter", "law_parameter"),
)
# held at samples (or, the RMS, by the trapezoidal rule): refined on a dense failure
SAMPLED_LIMITS = (
    "slider_accel",
    "slider_speed",
    "die_speed",
    "motor_peak_torque",
    "motor_rms_torque",
    "crank_torque",
    "grid_peak_power",
    "crank_speed",
    "motor_speed",
)
# a sampled limit's parameter where it is not the limit's id (the top speed: an optimal swing's rows' parameter)
SAMPLED_PARAMETER = {
    "grid_peak_power": "grid_cap",
    "crank_speed": TOP_SPEED_PARAMETER,
    "motor_speed": TOP_SPEED_PARAMETER,
}
ACCEL, JERK = "limits.crank_accel_rad_s2", "limits.crank_jerk_rad_s3"
OPTIONS = {"ipopt.constr_viol_tol": IPOPT_CONSTR_VIOL_TOL, "ipopt.max_iter": 600}
# at a target rate: the cycle's time [s] and the weights of the heat [1/(N^2 m^2 s)], the energy [1/J] and the
# bus power's peak [1/W] (min-grid-peak: its epigraph variable PEAK_VARIABLE)
RATE_PARAMETERS = ("target_period", "weight_heat", "weight_energy", "weight_peak")
PEAK_VARIABLE = "bus_peak"  # [W] min-grid-peak: at or above the bus power at every sample of both swings
TARGET = "planner.target_spm"


def _swing(
    setup: SwingSetup, v: dict[str, Any], ends: tuple[Any, Any], law: tuple[str, Any], hold_time: float
) -> SwingSymbols:
    """One swing's symbols (``law``: the law's name and its shape parameter; ``hold_time`` [s] at the setup's
    hold, where it has one)."""
    law_name, law_parameter = law
    p = SwingParameters(
        v["draw_speed"],
        v["feed_peak_speed"],
        v["return_peak_speed"],
        v["feed_accel_duration"],
        v["feed_decel_duration"],
        v["return_accel_duration"],
        v["return_decel_duration"],
        ends[0],
        setup.keys[1],
        setup.keys[2],
        ends[1],
        law_name,
        law_parameter,
        setup.hold,
        hold_time if setup.hold is not None else 0.0,
    )
    feed, feed_end = segments_from(p.feed_segments(), ends[0], 0.0)
    ret, return_end = segments_from(p.return_segments(), setup.keys[2], p.draw_speed)
    return SwingSymbols(setup, p, v, feed, ret, feed_end, return_end)


def _swing_rows(rows: Rows, s: SwingSymbols, case: Case, limits: dict[str, float], units: dict[str, float]) -> None:
    """One swing's rows (module docstring)."""
    p, v, keys = s.params, s.v, s.setup.keys
    law = get_law(p.motion_law)
    w_unit, t_unit = units["speed"], units["half"]
    end_feed, end_return = s.feed_end, s.return_end
    rows.add(
        "theta2 and the swing's end reached",
        ca.vertcat(end_feed[0] - keys[1], end_return[0] - p.end),
        0.0,
        0.0,
        "key_points",
    )
    # (the speeds at theta2 and at the end are w2 and 0 by construction: the halves' changes add up)
    w2, wm1, wm2, wr = p.draw_speed, p.feed_peak_speed, p.return_peak_speed, p.return_start_speed
    rows.add(
        "peak speeds above the draw speed", ca.vertcat(wm1 - w2, wm2 - wr) / w_unit, 0.0, math.inf, "planner.motion_law"
    )
    if law.one_jerk_per_curve:  # Eq. 14: one jerk for both halves of each S-curve
        d_fa, d_fd, d_ra, d_rd = (p.half(n)[0] for n in SWING_HALVES)
        one = ca.vertcat(wm1 * d_fd**2 - (wm1 - w2) * d_fa**2, (wm2 - wr) * d_rd**2 - wm2 * d_ra**2)
        rows.add("one jerk per S-curve (Eq. 14)", one / (t_unit**2 * w_unit), 0.0, 0.0, "planner.motion_law")
    th1, _ = angle_at(v["closing_time"], *s.feed)
    th4, _ = angle_at(v["opening_time"], *s.ret)
    rows.add("key angles", ca.vertcat(th1 - keys[0], th4 - keys[3]), 0.0, 0.0, "key_points")
    order = ca.vertcat(p.feed_time - v["closing_time"], p.return_time - v["opening_time"]) / t_unit
    rows.add("key points in order", order, 0.0, math.inf, "key_points")
    lim = case.limits
    if lim.crank_accel_rad_s2 is not None:
        rows.add(
            "crank acceleration", ca.vertcat(*p.peak_accelerations()) / lim.crank_accel_rad_s2, -math.inf, 1.0, ACCEL
        )
    if lim.crank_jerk_rad_s3 is not None:
        rows.add("crank jerk", ca.vertcat(*p.peak_jerks()) / lim.crank_jerk_rad_s3, -math.inf, 1.0, JERK)
    sampled_rows(rows, s, case, limits)


@dataclass
class PendulumNLP:
    """The compiled NLP of one case: the solver, the rows' bounds, the variables' names and scales; the sampled
    limits it takes as parameters (``limit_names``, in that order) and, for the values it is solved at
    (:meth:`at`), the variables' bounds and the swings' setups (each draw speed's bound follows them)."""

    case: Case
    solver: NLPSolver
    lbg: np.ndarray
    ubg: np.ndarray
    names: tuple[str, ...]
    scales: np.ndarray
    limit_names: tuple[str, ...]
    lbx: np.ndarray | None = None
    ubx: np.ndarray | None = None
    setups: tuple[SwingSetup, SwingSetup] | None = None
    limits: dict[str, float] | None = None
    rate: dict[str, float] | None = None

    def at(self, limits: dict[str, float], rate: dict[str, float] | None = None) -> PendulumNLP:
        """The NLP held at the sampled limits' values ``limits`` (by id, inside units); at a target rate ``rate``
        gives :data:`RATE_PARAMETERS`' values (kept from before when None)."""
        setups = swing_setups(self.case, limits)
        lbx, ubx = _bounds(self.case, self.names, setups)
        rate = self.rate if rate is None else dict(rate)
        return replace(self, lbx=lbx, ubx=ubx, setups=setups, limits=dict(limits), rate=rate)

    def parameters(self) -> np.ndarray:
        """The parameter vector: the sampled limits' values, then the rate's (at a target rate)."""
        values = [self.limits[name] for name in self.limit_names]
        return np.array(values + ([self.rate[name] for name in RATE_PARAMETERS] if self.rate else []))


def _variables(case: Case) -> tuple[tuple[str, ...], np.ndarray]:
    """The variables' names and scales (the halves NLP's scales by kind; the swing's ends in radians)."""
    halves_scale = variable_scales(case)
    own = {  # an optimal swing's jerks by the jerk limit (pendulum_free.jerk_scale), its steps a share of a half's
        "jerk": jerk_scale(case) if free(case) else 1.0,
        "step": halves_scale[VARIABLE_INDEX["feed_accel_duration"]] / STEP_SCALE,
    }
    names, scales = [], []
    for swing in SWINGS:
        for name, kind in swing_variables(case):
            names.append(f"{swing}_{name}")
            scales.append(own[kind] if kind in own else halves_scale[VARIABLE_INDEX[kind]])
    for name, kind in SHARED_VARIABLES:
        names.append(name)
        scales.append(1.0 if kind is None else halves_scale[VARIABLE_INDEX[kind]])
    for name in start_variables(case):  # the robots' starts (with robots: ``planning.solver.pendulum_robots``)
        names.append(name)
        scales.append(halves_scale[VARIABLE_INDEX["closing_time"]])
    if case.planner.objective == "min-grid-peak":  # the bus's peak [W], scaled by the motor's rated power
        names.append(PEAK_VARIABLE)
        scales.append(case.drive.motor.rated_torque_Nm * case.drive.motor.base_speed_rpm * RPM)
    return tuple(names), np.array(scales)


def free(case: Case) -> bool:
    """Whether the optimal law plans the swings (``planning.solver.pendulum_free``), not a law with halves."""
    return case.planner.motion_law == FREE_LAW


def swing_variables(case: Case) -> tuple[tuple[str, str], ...]:
    """A swing's variables (without its prefix) and their scale kinds under the case's law."""
    return FREE_SWING_VARIABLES if free(case) else SWING_VARIABLES


def build(case: Case, mirror: bool = False) -> PendulumNLP:
    """The NLP of ``case``, its sampled limits (``sampled_limit_values``' keys) parameters: built once a case and
    solved at each refinement's values (:meth:`PendulumNLP.at`); ``mirror``: the backward swing's variables tied to
    the forward's and the turns' standstills to each other (the optimal law's swings on a press whose two sides of
    BDC are one, ``planning.model.pendulum.mirror_symmetric``: a mirror-image plan, a KKT point of the untied NLP
    too). The backward swing keeps its rows, which the ties make copies of the forward's (IPOPT's regularisation
    takes the redundancy; with them left out it ended in a poorer optimum of the shallow bracket, 64.056
    strokes/min against 64.107)."""
    names, scales = _variables(case)
    x = ca.SX.sym("x", len(names))
    phys = {name: x[i] * scales[i] for i, name in enumerate(names)}
    limit_names = tuple(sampled_limit_values(case))
    rate = case.planner.objective != "max-spm"  # at a target rate: the heat or the energy weighed
    p = ca.SX.sym("limits", len(limit_names) + (len(RATE_PARAMETERS) if rate else 0))
    limits = {name: p[k] for k, name in enumerate(limit_names + (RATE_PARAMETERS if rate else ()))}
    setups = swing_setups(case, {})  # their key angles, mechanism and die exit (the bounds follow in ``at``)
    theta_s, theta_e = phys["swing_start"], phys["swing_end"]
    ends = {"forward": (theta_s, theta_e), "backward": (TWO_PI - theta_e, TWO_PI - theta_s)}
    law = case.planner.motion_law
    rows = Rows()
    half = variable_scales(case)[VARIABLE_INDEX["feed_accel_duration"]]
    units = {"speed": scales[0], "half": half}
    swings = {}
    for setup in setups:
        v = {name: phys[f"{setup.name}_{name}"] for name, _ in swing_variables(case)}
        if free(case):
            swings[setup.name] = free_swing(setup, v, ends[setup.name])
            free_swing_rows(rows, swings[setup.name], case, limits, units)
            continue
        hold = case.process.hold_time_s or 0.0
        swings[setup.name] = _swing(setup, v, ends[setup.name], (law, phys["law_parameter"]), hold)
        _swing_rows(rows, swings[setup.name], case, limits, units)
    f, b = swings["forward"], swings["backward"]
    if mirror:  # the swings as mirror images
        tied = [(f"forward_{k}", f"backward_{k}") for k in f.v] + [("turn_end_s", "turn_start_s")]
        ties = ca.vertcat(*[x[names.index(back)] - x[names.index(fore)] for fore, back in tied])
        rows.add("mirror swings", ties, 0.0, 0.0, "planner.motion_law")
    transfer = case.transfer_time_s
    turns = (phys["turn_end_s"], phys["turn_start_s"])
    period = PendulumParameters(f.params, b.params, *turns).period
    if case.robots is None:
        window_e = f.params.return_time - f.v["opening_time"] + turns[0] + b.v["closing_time"]
        window_s = b.params.return_time - b.v["opening_time"] + turns[1] + f.v["closing_time"]
        windows = ca.vertcat(window_e, window_s) / transfer - 1.0
        rows.add("robot windows", windows, 0.0, math.inf, "process.transfer_time_s")
    else:  # the robots on their curves in both windows (``planning.solver.pendulum_robots``)
        starts = {name: phys[name] for name in start_variables(case)}
        cycle = _cycle_times(case, f, b, turns)
        robot_rows(rows.add, case, cycle, starts, limits[NEED_FACTOR], units["half"])
    objective = period / transfer
    if case.drive is not None:  # the motor's torques at the swings' samples (``planning.solver.pendulum_drive``)
        drives = {name: swing_drive(case, swing) for name, swing in swings.items()}
        drive_rows(case, rows.add, drives, turns, period, limits)
        if rate:
            rows.add("the cycle at the target rate", period / limits["target_period"] - 1.0, 0.0, 0.0, TARGET)
            heat, energy = rate_terms(case, drives, turns)
            objective = limits["weight_heat"] * heat + limits["weight_energy"] * energy
        if PEAK_VARIABLE in phys:  # min-grid-peak: the bus's peak as an epigraph, weighed
            bus_peak_rows(case, rows.add, drives, phys[PEAK_VARIABLE], scales[names.index(PEAK_VARIABLE)])
            objective = objective + limits["weight_peak"] * phys[PEAK_VARIABLE]
    if free(case):  # of the equally good jerk profiles the smoothest (``planning.solver.pendulum_free``)
        objective = objective + jerk_tie_break(case, phys)
    problem = {"x": x, "p": p, "f": objective, "g": ca.vertcat(*rows.g)}
    solver = NLPSolver(
        "pendulum_rate" if rate else "pendulum", problem, {**OPTIONS, **(RATE_OPTIONS if rate else {})}, scales
    )
    return PendulumNLP(case, solver, *rows.bounds(), names, scales, limit_names)


def _cycle_times(case: Case, f: SwingSymbols, b: SwingSymbols, turns: tuple[Any, Any]) -> CycleTimes:
    """The cycle as the robots' rows read it (``planning.solver.pendulum_robots.CycleTimes``): each window's
    segments in the crank's own angle (the backward swing's negated) from the draw before it to the draw after
    it, the slide's height at times from the window's theta3; before the first draw's start and after the last
    draw's end BDC's, 0: never higher than the slide (a tool needing height there finds none)."""
    draw_f = Segment("draw:constant", f.params.draw_time, 0.0, 0.0)
    draw_b = Segment("draw:constant", b.params.draw_time, 0.0, 0.0)
    forward_feed, forward_return = [*f.params.feed_segments(), draw_f], [*f.params.return_segments()]
    backward_feed = [reversed_segment(seg) for seg in [*b.params.feed_segments(), draw_b]]
    backward_return = [reversed_segment(seg) for seg in b.params.return_segments()]
    at_e, at_s = (Segment(TURN_SEGMENT, turn, 0.0, 0.0) for turn in turns)
    windows = {  # the draw before, the return, the turn, the feed and the draw after; the state at the first
        WINDOWS[0]: ([draw_f, *forward_return, at_e, *backward_feed], f.setup.keys[1], f.params.draw_speed, f),
        WINDOWS[1]: (
            [backward_feed[-1], *backward_return, at_s, *forward_feed],
            TWO_PI - b.setup.keys[1],
            -b.params.draw_speed,
            b,
        ),
    }
    jets = case.machine.jets
    heights = {}
    for w, (segs, theta2, omega2, before) in windows.items():
        (starts, states, segs_w), _ = segments_from(segs, theta2, omega2)
        span = sum(seg.duration for seg in segs_w)
        heights[w] = (starts, states, segs_w, before.params.draw_time, span)

    def height_at(window: str, times: list) -> Any:
        starts, states, segs, lead, span = heights[window]
        inside = ca.vertcat(*[ca.logic_and(t + lead >= 0, t + lead <= span) for t in times])
        h = jets(ca.vertcat(*[angle_at(t + lead, starts, states, segs)[0] for t in times]))[0]
        return ca.if_else(inside, h, 0.0)  # (BDC, the lowest the slide goes, outside the window's segments)

    to_backward = f.params.return_time + turns[0] + b.params.feed_time
    offsets = {WINDOWS[0]: 0.0, WINDOWS[1]: to_backward + b.params.draw_time}
    spare = {WINDOWS[0]: to_backward, WINDOWS[1]: b.params.return_time + turns[1] + f.params.feed_time}
    return CycleTimes(height_at, offsets, spare, PendulumParameters(f.params, b.params, *turns).period)


def _bounds(case: Case, names: tuple[str, ...], setups: tuple[SwingSetup, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Variable bounds: speeds from the least crank speed (the draw) or 0 up to the top crank speed, the draw
    speed at most its swing's bound (the case's own when it gives one), durations above ``MIN_HALF_S``."""
    lo, hi = np.zeros(len(names)), np.full(len(names), np.inf)
    top = _top_speed(case)
    given = case.process.draw_speed_rpm
    (s_lo, s_hi), (e_lo, e_hi) = swing_bounds(case)
    robots = start_variables(case)
    for i, name in enumerate(names):
        own = variable_bound(case, name) if free(case) else None
        if own is not None:
            lo[i], hi[i] = own
        elif name.endswith("peak_speed"):
            hi[i] = top
        elif name.endswith("draw_speed"):
            bound = next(s.draw_speed_bound for s in setups if name.startswith(s.name))
            lo[i] = case.limits.min_crank_speed_rpm * RPM
            hi[i] = max(min(bound, top), lo[i])  # a refined limit below the least speed: the check says so
            if given is not None:
                lo[i] = hi[i] = given * RPM
        elif name.endswith("_duration"):
            lo[i] = MIN_HALF_S
        elif name == "swing_start":
            lo[i], hi[i] = s_lo, s_hi
        elif name == "swing_end":
            lo[i], hi[i] = e_lo, e_hi
        elif name == "law_parameter":
            lo[i], hi[i] = _law_parameter_bounds(case)
        elif name in robots:  # a robot's start: within a period either side of its window's theta3
            lo[i], hi[i] = -time_limit(case), time_limit(case)
    return lo, hi


def _top_speed(case: Case) -> float:
    """[rad/s] the crank's and the motor's top speed (:data:`TOP_SPEED` without either)."""
    tops = [t for limit in limits_of(case) if (t := limit.top_crank_speed(case)) is not None]
    return min(tops, default=TOP_SPEED)


def _law_parameter_bounds(case: Case) -> tuple[float, float]:
    law = get_law(case.planner.motion_law)
    fixed = case.planner.law_parameter
    if law.parameter is None:
        return 0.0, 0.0
    if fixed is not None:
        return fixed, fixed
    return law.parameter.low, law.parameter.high


def starts(case: Case, nlp: PendulumNLP) -> list[dict[str, float]]:
    """Starting points that meet the swings' own rows: the draw at its bound and at half of it, the peaks 1.5 and
    3 times the draw speed, each swing turning midway in its room; each S-curve with one jerk (Eq. 14) that sweeps
    its angle, the key points' times where that motion passes them."""
    if free(case):  # the optimal law's swings start from a plan of another law (``planning.solver.pendulum``)
        return []
    (s_lo, s_hi), (e_lo, e_hi) = swing_bounds(case)
    law = get_law(case.planner.motion_law)
    shape = 0.0 if law.parameter is None else (case.planner.law_parameter or law.parameter.start)
    out = []
    for draw_share, peak in ((1.0, 1.5), (0.5, 3.0), (1.0, 3.0), (0.5, 1.5)):
        values = {"swing_start": 0.5 * (s_lo + s_hi), "swing_end": 0.5 * (e_lo + e_hi), "law_parameter": shape}
        values.update({"turn_end_s": 0.0, "turn_start_s": 0.0})
        ends = {
            "forward": (values["swing_start"], values["swing_end"]),
            "backward": (TWO_PI - values["swing_end"], TWO_PI - values["swing_start"]),
        }
        for setup in nlp.setups:
            i = nlp.names.index(f"{setup.name}_draw_speed")
            w2 = max(nlp.lbx[i], min(nlp.ubx[i], draw_share * nlp.ubx[i]))
            hold = case.process.hold_time_s or 0.0
            values.update(_swing_start(setup, ends[setup.name], w2, peak * w2, (law.name, shape), hold))
        transfer = case.transfer_time_s  # (with robots their span: a start's window)
        turns = (("turn_end_s", ("forward", "backward")), ("turn_start_s", ("backward", "forward")))
        for turn, (first, second) in turns:
            window = _tail(values, first) + values[f"{second}_closing_time"]
            values[turn] = max(transfer - window, 0.0)
        out.append(values | _robot_starts(case, values))
    return out


def _robot_starts(case: Case, values: dict[str, float]) -> dict[str, float]:
    """The robots' starts of a start's ``values`` (``planning.solver.pendulum_robots.first_starts``): each
    window's theta4 and next theta1 [s from its theta3]."""
    if case.robots is None:
        return {}
    times = {}
    for w, (first, second), turn in zip(WINDOWS, (SWINGS, SWINGS[::-1]), ("turn_end_s", "turn_start_s"), strict=True):
        opening = values[f"{first}_opening_time"]
        times[w] = (opening, opening + _tail(values, first) + values[turn] + values[f"{second}_closing_time"])
    return first_starts(case, times)


def _tail(values: dict[str, float], swing: str) -> float:
    """[s] from the swing's theta4 to its end (a start's ``values``: with a hold, its brake and standstill
    :data:`STOPPED` after theta3 too)."""
    ret = values[f"{swing}_return_accel_duration"] + values[f"{swing}_return_decel_duration"]
    return ret + values.get(f"{swing}_{STOPPED}", 0.0) - values[f"{swing}_opening_time"]


STOPPED = "brake_and_hold_s"  # a start's time [s] braking to the hold and standing there (not a variable)


def _swing_start(
    setup: SwingSetup, ends: tuple[float, float], w2: float, wm: float, law: tuple[str, float], hold_time: float
) -> dict:
    """One swing's start values: S-curves of one jerk each (Eq. 14: ``dv = k J T^2`` per half of ``4 T``, the
    half sweeping ``D (v0 + v1) / 2``) through the draw speed ``w2`` with peaks ``wm`` (``law``: its name and
    shape parameter); with a hold the return rises from rest at the hold after ``hold_time`` [s]."""
    a, e = ends
    wr = 0.0 if setup.hold is not None else w2  # the return's start speed
    feed, ret = setup.keys[1] - a, e - (setup.keys[2] if setup.hold is None else setup.hold)
    # feed: 0 -> wm -> w2 sweeps 2 T_a wm + 2 T_d (wm + w2), T = sqrt(dv / (k J)): solve for sqrt(k J)
    root = 2 * (wm**1.5 + math.sqrt(wm - w2) * (wm + w2)) / feed
    fa, fd = 4 * math.sqrt(wm) / root, max(4 * math.sqrt(wm - w2) / root, MIN_HALF_S)
    root = 2 * (math.sqrt(wm - wr) * (wr + wm) + wm**1.5) / ret
    ra, rd = max(4 * math.sqrt(wm - wr) / root, MIN_HALF_S), 4 * math.sqrt(wm) / root
    keys = setup.keys
    hold = (setup.hold, hold_time) if setup.hold is not None else (None, 0.0)
    p = SwingParameters(w2, wm, wm, fa, fd, ra, rd, a, keys[1], keys[2], e, law[0], law[1], *hold)
    feed_profile = Profile(tuple(p.feed_segments()), a, 0.0)
    ret_profile = Profile(tuple(p.return_segments()), setup.keys[2], w2)
    n = setup.name
    zone = {f"{setup.name}_die_time_{k}": ret_profile.time_at_angle(u) for k, u in enumerate(setup.die_zone)}
    return {
        f"{n}_draw_speed": w2,
        f"{n}_feed_peak_speed": wm,
        f"{n}_return_peak_speed": wm,
        f"{n}_feed_accel_duration": fa,
        f"{n}_feed_decel_duration": fd,
        f"{n}_return_accel_duration": ra,
        f"{n}_return_decel_duration": rd,
        f"{n}_{STOPPED}": float(p.brake_duration + p.hold_time),
        f"{n}_closing_time": feed_profile.time_at_angle(setup.keys[0]),
        f"{n}_opening_time": ret_profile.time_at_angle(setup.keys[3]),
        **{f"{n}_die_time_{k}": 0.0 for k in range(DIE_ZONE_POINTS)},
        **zone,
    }


def plan_of_values(case: Case, values: dict[str, float], info: SolverInfo) -> PendulumPlan:
    """The plan of the NLP's variable ``values``."""
    law = case.planner.motion_law
    setups = swing_setups(case, {})
    theta_s, theta_e = values["swing_start"], values["swing_end"]
    ends = {"forward": (theta_s, theta_e), "backward": (TWO_PI - theta_e, TWO_PI - theta_s)}
    swings = {}
    for setup in setups:
        n = setup.name
        a, e = ends[n]
        if free(case):
            swings[n] = free_parameters(values, n, setup, (a, e))
            continue
        swings[n] = SwingParameters(
            *(float(values[f"{n}_{k}"]) for k, _ in SWING_VARIABLES[:7]),
            a,
            setup.keys[1],
            setup.keys[2],
            e,
            law,
            float(values["law_parameter"]),
            setup.hold,
            (case.process.hold_time_s or 0.0) if setup.hold is not None else 0.0,
        )
    params = PendulumParameters(swings["forward"], swings["backward"], values["turn_end_s"], values["turn_start_s"])
    fwd = tuple(float(a) for a in case.key_angles)
    plan = PendulumPlan(params, profile_of(params), fwd, backward_key_angles(case), info, dict(values))
    if case.robots is None:
        return plan
    f, b = params.forward, params.backward
    t3 = float(f.feed_time + f.draw_time)  # the forward swing's theta3 [s from its start]
    to_back3 = float(f.return_time + params.turn_end_s + b.feed_time + b.draw_time)
    offsets = {WINDOWS[0]: t3, WINDOWS[1]: t3 + to_back3}
    return replace(plan, robot_starts_s=plan_starts(case, values, offsets, plan.period))


def solve_once(case: Case, nlp: PendulumNLP, start: dict[str, float]) -> tuple[dict[str, float] | None, Any]:
    """One IPOPT solve from ``start``: the variable values when it converged (else None) and the result."""
    x0 = np.array([start[name] for name in nlp.names])
    res = nlp.solver.solve(x0, nlp.lbx, nlp.ubx, nlp.lbg, nlp.ubg, p=nlp.parameters())
    values = {name: float(res.x[i]) for i, name in enumerate(nlp.names)} if res.success else None
    return values, res


def sampled_limit_values(case: Case) -> dict[str, float]:
    """The sampled limits' values the first NLP holds (inside units; the acceleration ``ACCEL_BACKOFF`` and the
    motor's torques ``DRIVE_BACKOFF`` inside)."""
    lim = case.limits
    out = {"slider_accel": lim.slider_accel_mm_s2 * (1 - ACCEL_BACKOFF), "die_speed": lim.die_speed_mm_s}
    if lim.slider_speed_mm_s is not None:
        out["slider_speed"] = lim.slider_speed_mm_s
    if case.drive is not None:
        motor = case.drive.motor
        out["motor_peak_torque"] = motor.peak_torque_Nm * (1 - DRIVE_BACKOFF)
        out["motor_rms_torque"] = motor.rated_torque_Nm * (1 - DRIVE_BACKOFF)
        cap = torque_capacity_kNm(case)
        if cap is not None:
            out["crank_torque"] = cap * (1 - DRIVE_BACKOFF)
        grid = GridPeakLimit()
        if grid.applies(case):  # the bus's cap (``planning.model.limits.grid``); with a storage its energy too
            values = grid.parameter_values(case)
            out["grid_cap"] = values["grid_cap"]
            if values["grid_allowance"] < NO_STORAGE_J:
                out["grid_allowance"] = values["grid_allowance"]
    if free(case):  # the optimal law's swings hold the crank's top speed at their samples
        out[TOP_SPEED_PARAMETER] = _top_speed(case)
    if case.robots is not None:
        out[NEED_FACTOR] = 1.0  # the robots' needs at the samples as the curves say (raised on a dense failure)
    return out


def refined(limits: dict[str, float], failures: list) -> dict[str, float] | None:
    """``limits`` with each sampled limit the dense check found exceeded lowered by its overshoot (None when a
    failure is no sampled limit's: refining cannot help)."""
    out = dict(limits)
    raised = any(c.refine_by is not None and c.refine_by[0] == NEED_FACTOR for c in failures)
    for check in failures:
        if check.refine_by is not None and check.refine_by[0] in limits:  # (the robots' needs: raised)
            name, factor, ceiling = check.refine_by
            out[name] = min(limits[name], ceiling) * factor
        elif check.id == ROBOTS_CHECK and raised:  # another clearance: the worst one's factor raises them all
            continue
        elif check.id in SAMPLED_LIMITS and SAMPLED_PARAMETER.get(check.id, check.id) in limits:
            name = SAMPLED_PARAMETER.get(check.id, check.id)  # lowered by its overshoot, the most of two checks
            out[name] = min(out[name], limits[name] * min(check.limit / check.value, 1.0) * (1 - REFINE_MARGIN))
        else:
            return None
    return out


def elapsed_info(t0: float, iterations: int, tried: int, status: str) -> SolverInfo:
    """The solver's report of a pendulum solve."""
    return SolverInfo(iterations, time.perf_counter() - t0, tried, status)
