"""The NLP of the optimal law: the fastest jerk-limited cycle as a free profile (no fixed motion law).

Outside the constant-speed draw the crank follows segments of constant jerk ``|j_k| <= J`` (``J`` =
``limits.crank_jerk_rad_s3``, required for this law) in three phases
(``planning.model.free_profile.PHASES``): the return theta3 -> theta4, the robot's window theta4 ->
theta1 and the feed theta1 -> theta2, each of equal steps ``h`` [s] of its own. A draw at constant slide speed
is a fourth phase, theta2 -> theta3 (``free_profile.FREE_DRAW``): the speed and the acceleration at theta3 are
variables the cycle closes on, the draw's samples (the last) hold the slide's speed and every limit. Multiple
shooting: the state (angle, speed, acceleration) at every knot is a variable, and each segment's closed form ties
it to the next, so the NLP is sparse and the acceleration continuous everywhere. Fixed: theta3, w2
and zero acceleration at the start, theta4 and theta1 at the phase boundaries, theta2 + 2 pi, w2 and
zero acceleration at the end. Minimised: the cycle time. The jerk limit is the bounds of the
segments' jerks; the die-height crossings have times of their own (as in the laws' NLP). The limits
(``planning.model.limits``) hold at every knot and at evenly spaced points inside each segment (the
crank speed and the minimum crank speed there, refined against the dense verification like the slider
acceleration), the crank acceleration at the knots (it is piecewise linear), the die zone at every
sample below the die height; with a drive, the motor's limits as for the laws. Placement has no
meaning: theta1 and theta4 are where the phases meet.
"""

from __future__ import annotations

import math
from functools import cache, partial
from typing import Any

import casadi as ca
import numpy as np

from planning.model.case import RPM, Case
from planning.model.free_profile import (
    BRAKE_PHASE,
    FREE_DRAW,
    PHASES,
    REST_PHASES,
    RISE_PHASE,
    STAND_PHASE,
    STOP_PHASES,
    Layout,
    draws_freely,
    first_layout,
    holds,
)
from planning.model.limits.base import Extremes, Transcription
from planning.model.plan import Plan, SolverInfo, plan_of
from planning.model.profile import advance
from planning.solver.halves_nlp import ROBOT_VARIABLES
from planning.solver.ipopt import NLPSolver
from planning.solver.nlp import (
    CYCLE_OPTIONS,
    DRIVE_OPTIONS,
    RATE_OPTIONS,
    CycleNLP,
    Rows,
    add_limit_rows,
    clipped_advance,
    draw_states,
    nlp_limits,
    objective_terms,
    sample_states,
)
from planning.solver.parameters import (
    DRAW_SAMPLES_DRIVE,
    FORMING_SAMPLES,
    ParameterLayout,
    drive_links,
    time_limit,
)
from planning.tolerances import (
    IPOPT_CONSTR_VIOL_TOL,
    IPOPT_FREE_RATE_ACCEPTABLE,
    IPOPT_FREE_RATE_COMPL,
    IPOPT_FREE_RATE_OBJ_CHANGE,
    IPOPT_FREE_WARM_MU_INIT,
)
from press.mechanism import Formula

# the limits are held at every knot and at evenly spaced points inside each segment, this many per
# segment (knot included) in each phase: the robot's window has the longest segments and the highest
# speeds (around TDC, where the slider acceleration peaks), so it is sampled finer
SAMPLES_PER_SEGMENT = {"return": 4, "transfer": 8, "feed": 4, "draw": 8, "brake": 4, "stand": 2, "rise": 4}
STATES = ("angle", "speed", "accel")
TOP_SPEED = 1e3  # [rad/s] upper bound of the crank speeds (far above any press)
# at a rate: the rate NLPs' tolerance, and IPOPT's acceptable level where its line search cycles near the
# optimum (planning.tolerances: IPOPT_FREE_RATE_ACCEPTABLE)
FREE_RATE_OPTIONS = {
    **RATE_OPTIONS,
    "ipopt.acceptable_tol": IPOPT_FREE_RATE_ACCEPTABLE,
    "ipopt.acceptable_iter": 10,
    "ipopt.acceptable_obj_change_tol": IPOPT_FREE_RATE_OBJ_CHANGE,
    "ipopt.acceptable_compl_inf_tol": IPOPT_FREE_RATE_COMPL,
    "ipopt.acceptable_constr_viol_tol": IPOPT_CONSTR_VIOL_TOL,
}
# with robots the rows tie every segment of the profile together (the slide's height at a robot's time sums them):
# its exact Hessian is dense over them, about 0.1 s an iteration, 6-20 s an IPOPT call alone on 2 cores and twice
# that beside another solve; its calls may take this long [s] (the wrapper's guard is for calls of under a second)
ROBOTS_WALL_S = 150.0
# a re-solve with a refined limit starts nearer the optimum than the laws' (about half the iterations
# with this barrier parameter; the laws keep the wrapper's, which finds their optima as before)
WARM_OPTIONS = {"ipopt.mu_init": IPOPT_FREE_WARM_MU_INIT}


@cache
def variables_of(phases: Layout = PHASES, robots: bool = False) -> tuple[tuple[str, str], ...]:
    """The NLP's variables and the kind of scale of each, for the phases' ``layout``; with ``robots`` their
    starts last (``planning.solver.halves_nlp.ROBOT_VARIABLES``)."""
    # the die-height crossings outside the draw: going up in the return (time from theta3), going down in
    # the feed (time from theta1)
    out: list[tuple[str, str]] = [("draw_speed", "speed"), ("die_up_time", "time"), ("die_down_time", "time")]
    out += [("draw_accel", "accel")] if draws_freely(phases) else []  # at theta3: a free draw's end and start
    for phase, n in phases:
        out.append((f"{phase}_step", "step"))
        out += [(f"{phase}_jerk_{k}", "jerk") for k in range(n)]
        # the knots inside the phase and its end (the start is the previous phase's end, or theta3)
        for k in range(1, n + 1):
            out += [
                (f"{phase}_{name}_{k}", kind) for name, kind in zip(STATES, ("angle", "speed", "accel"), strict=True)
            ]
    return tuple(out) + (ROBOT_VARIABLES if robots else ())


VARIABLES = variables_of(PHASES)


@cache
def index_of(phases: Layout = PHASES, robots: bool = False) -> dict[str, int]:
    """Each variable's position for the phases' ``layout`` (with the robots' starts)."""
    return {name: i for i, (name, _) in enumerate(variables_of(phases, robots))}


def variable_scales(case: Case, phases: Layout = PHASES) -> np.ndarray:
    """Scales from the press's characteristic time and speed (as the laws' NLP) and the jerk limit."""
    m, A = case.machine, case.limits.slider_accel_mm_s2
    t_star = math.sqrt(m.length_scale / A)
    w_star = math.sqrt(A / m.peak_curvature)
    unit = {
        "speed": 0.42 * w_star,
        "step": 0.05 * t_star,
        "angle": 1.0,
        "accel": w_star / t_star,
        "jerk": case.limits.crank_jerk_rad_s3,
        "time": t_star,
    }
    return np.array([unit[kind] for _, kind in variables_of(phases, case.robots is not None)])


def variable_bounds(
    case: Case,
    layout: ParameterLayout,
    w2_lo: float,
    w2_hi: float,
    parameters: np.ndarray,
    phases: Layout = PHASES,
) -> tuple[np.ndarray, np.ndarray]:
    """The segments' jerks within the jerk limit, the steps within the longest cycle, the speeds positive,
    the draw speed within its bounds, a die crossing's time fixed where it lies in the draw."""
    J = case.limits.crank_jerk_rad_s3
    longest = time_limit(case)
    variables, index = variables_of(phases, case.robots is not None), index_of(phases, case.robots is not None)
    lo, hi = np.full(len(variables), -np.inf), np.full(len(variables), np.inf)
    for name, kind in variables:
        i = index[name]
        if kind == "jerk" and name.startswith(f"{STAND_PHASE[0]}_"):  # the crank stands: no jerk
            lo[i], hi[i] = 0.0, 0.0
        elif kind == "jerk":
            lo[i], hi[i] = -J, J
        elif kind == "step" and name == f"{STAND_PHASE[0]}_step":  # a hold's standstill: its time
            lo[i], hi[i] = case.standstill_s, case.standstill_s
        elif kind == "step":
            phase = name.removesuffix("_step")
            lo[i], hi[i] = 0.0, longest / dict(phases)[phase]
        elif kind == "speed":
            lo[i], hi[i] = 0.0, TOP_SPEED
        elif name.endswith("_start"):  # a robot's start: within a period either side of theta3
            lo[i], hi[i] = -longest, longest
    lo[index["draw_speed"]], hi[index["draw_speed"]] = w2_lo, w2_hi
    if draws_freely(phases):  # the speed at theta3 of a free draw: any the limits allow at the samples
        w_min = case.limits.min_crank_speed_rpm * RPM
        lo[index["draw_speed"]], hi[index["draw_speed"]] = w_min, TOP_SPEED
    for k in ("die_down", "die_up"):
        i = index[f"{k}_time"]
        active = parameters[layout.index(f"{k}_active")] != 0.0
        lo[i], hi[i] = (0.0, longest) if active else (0.0, 0.0)
    return lo, hi


def make_plan(case: Case, values: dict[str, float], placement: str, info: SolverInfo, phases: Layout = PHASES) -> Plan:
    """The plan of the NLP's values (``planning.model.plan.plan_of``): the profile propagated from theta3
    through the segments' closed forms (the NLP's knot states agree with it to its tolerance), then the draw;
    the optimal law's placement is free."""
    return plan_of(case, values, "free", info, phases)


def _shooting(phases: Layout, physical: ca.MX, v: dict, unit: dict, q: dict, index: dict) -> dict[str, Any]:
    """Multiple shooting over the phases from theta3 (each phase's segments at once, MX vectors): the rows
    joining the segments in closed form and meeting each phase's end angle, the samples (every knot and
    points inside each segment, in time order) and their times, the knot accelerations, the die-height
    crossings in closed form (clip), the last state and the time at the feed's end."""
    ends = {"return": q["theta4"], "transfer": q["theta1"] + 2 * np.pi, "feed": q["theta2"] + 2 * np.pi}
    ends["draw"] = q["theta3"] + 2 * np.pi  # a free draw (a draw at constant slide speed)
    if holds(phases):  # the brake to the hold's angle and the standstill there
        ends |= {phase: q["hold_angle"] for phase in REST_PHASES}
    start = (q["theta3"], v["draw_speed"], v.get("draw_accel", ca.MX(0.0)))
    t0 = ca.MX(0.0)
    shooting, boundary, samples, times, knot_accels, pieces = [], [], [], [], [], []
    crossings, rest, rise, monotone = {}, None, None, []
    for phase, n in phases:
        h = v[f"{phase}_step"]
        first = index[f"{phase}_jerk_0"]
        jerk = physical[first : first + n]
        # the knots 1 .. n of the phase: n rows of (angle, speed, accel), stored row after row
        states = ca.reshape(physical[first + n : first + 4 * n], 3, n).T
        nxt = [states[:, i] for i in range(3)]
        th0, om0, al0 = (ca.vertcat(start[i], nxt[i][: n - 1]) if n > 1 else start[i] for i in range(3))
        piece = (t0, h, n, start, om0, al0, jerk)
        if phase in ("return", "feed", "brake"):  # the die-height crossing of this phase, in closed form (clip)
            when = v["die_up_time" if phase == "return" else "die_down_time"]
            crossings[phase] = _crossing(when, piece, rise if phase == "return" else None)
        rise = piece if phase == RISE_PHASE[0] else rise
        if phase == RISE_PHASE[0]:  # the rise from rest speeds the crank up all the way (it cannot crawl there)
            monotone.append(nxt[2] / unit[f"{phase}_accel_1"])
        pieces.append(piece)
        th1, om1, al1, _ = advance(th0, om0, al0, jerk, 0.0, h)
        shooting.append(
            ca.vertcat(th1 - nxt[0], (om1 - nxt[1]) / unit["draw_speed"], (al1 - nxt[2]) / unit[f"{phase}_accel_1"])
        )
        end = tuple(states[n - 1, i] for i in range(3))
        boundary += [end[0] - ends[phase]] if ends.get(phase) is not None else []  # (a rise's end: the planner's)
        if phase == BRAKE_PHASE[0]:
            rest = (end[1] / unit["draw_speed"], end[2] / unit[f"{phase}_accel_1"])  # at rest at the hold
        # samples in time order: every knot of the phase and the points inside each segment
        fractions = [k / SAMPLES_PER_SEGMENT[phase] for k in range(1, SAMPLES_PER_SEGMENT[phase])]
        parts = [advance(th0, om0, al0, jerk, 0.0, h * f) for f in fractions]
        samples.append(tuple(_interleave([(th0, om0, al0)[i], *(part[i] for part in parts)]) for i in range(3)))
        if phase == BRAKE_PHASE[0]:  # the brake may speed up first, never turn back
            monotone.append(samples[-1][1] / unit["draw_speed"])
        local = ca.DM(np.arange(n))
        times.append(_interleave([t0 + local * h, *(t0 + (local + f) * h for f in fractions)]))
        knot_accels.append(ca.vertcat(al0, end[2]))
        t0 = t0 + n * h
        start = end
        if phase == "feed":
            feed_end = t0  # theta2: the draw starts (a free draw's phase follows)
    return {
        "shooting": shooting,
        "boundary": boundary,
        "samples": samples,
        "times": times,
        "knot_accels": knot_accels,
        "crossings": crossings,
        "end": start,
        "t_end": t0,
        "free_draw": draws_freely(phases),
        "t_draw_start": feed_end,
        "pieces": pieces,
        "rest": rest,
        "monotone": monotone,
        "phases": phases,
    }


def _crossing(when: ca.MX, piece: tuple, rise: tuple | None) -> tuple:
    """The die-height crossing ``when`` [s] after a phase's start (``piece``: its start time, step, segments, start
    state, the segments' start speeds and accelerations, jerks): ``((angle, speed), when, span)`` in closed form
    (clip); after a hold's ``rise`` (its piece) counted from the rise's start, over both phases."""
    _, h, n, start, om0, al0, jerk = piece
    if rise is None:
        tau = ca.fmin(ca.fmax(when - h * ca.DM(np.arange(n)), 0), h)
        return clipped_advance(tau, start[0], start[1], om0, al0, jerk, 0.0), when, n * h
    _, h_r, n_r, start_r, om0_r, al0_r, jerk_r = rise
    tau_r = ca.fmin(ca.fmax(when - h_r * ca.DM(np.arange(n_r)), 0), h_r)
    th_r, om_r = clipped_advance(tau_r, start_r[0], start_r[1], om0_r, al0_r, jerk_r, 0.0)
    tau = ca.fmin(ca.fmax(when - n_r * h_r - h * ca.DM(np.arange(n)), 0), h)
    th, om = clipped_advance(tau, 0.0, 0.0, om0, al0, jerk, 0.0)
    return (th_r + th, om_r + om), when, n_r * h_r + n * h


def _structure_rows(rows: Rows, s: dict[str, Any], v: dict, unit: dict, q: dict) -> tuple[ca.MX, ca.MX]:
    """The segments joined, the key angles met, the cycle closed, the key points in order, the die-height
    crossings at their angles; the crossings' speeds (rising, falling)."""
    w2, start = v["draw_speed"], s["end"]
    rows.add("segments join (closed form)", ca.vertcat(*s["shooting"]), 0.0, 0.0, "planner.motion_law")
    closing = 2 if s["free_draw"] else 1  # the feed's end (and a free draw's) closes the cycle
    rows.add("key angles", ca.vertcat(*s["boundary"][:-closing]), 0.0, 0.0, "key_points")
    if s["rest"] is not None:
        rows.add("the crank at rest at the hold", ca.vertcat(*s["rest"]), 0.0, 0.0, "process.hold_time_s")
        monotone = ca.vertcat(*s["monotone"])
        rows.add("forward in the brake, speeding up in the rise", monotone, 0.0, np.inf, "process.hold_time_s")
    end_accel = start[2] - v["draw_accel"] if "draw_accel" in v else start[2]  # a free draw's at theta3, else 0
    closes = ca.vertcat(
        *s["boundary"][-closing:], (start[1] - w2) / unit["draw_speed"], end_accel / unit["feed_accel_1"]
    )
    rows.add("cycle closes", closes, 0.0, 0.0, "key_points")
    (thu, omu), t_up, span_up = s["crossings"]["return"]
    (thd, omd), t_down, span_down = s["crossings"]["feed"]
    if "brake" in s["crossings"]:  # a descending crossing in a hold's brake (its angle a turn back, < 0)
        braking = q["die_down_angle"] < 0
        (thb, omb), _, span_brake = s["crossings"]["brake"]
        thd, omd = ca.if_else(braking, thb, thd), ca.if_else(braking, omb, omd)
        span_down = ca.if_else(braking, span_brake, span_down)
    rows.add("key points in order", ca.vertcat(span_up - t_up, span_down - t_down), 0.0, np.inf, "key_points")
    crossing = ca.vertcat(
        q["die_up_active"] * (thu - q["die_up_angle"]),
        q["die_down_active"] * (thd - (q["die_down_angle"] + 2 * np.pi)),
    )
    rows.add("die crossing angles", crossing, 0.0, 0.0, "limits.die_height_mm")
    return omu, omd


def _all_samples(s: dict[str, Any], q: dict, w2: ca.MX, drive: bool) -> tuple[tuple, ca.MX, int, ca.MX]:
    """The free profile's samples, then, with a drive and a draw at the constant w2, the draw's (the forming force
    is given at them; every limit holds in the draw by the draw speed's bounds; a free draw's samples are the
    profile's own): the states, their times, the draw's count, and the free profile's speeds alone."""
    th = ca.vertcat(*[sm[0] for sm in s["samples"]])
    om = ca.vertcat(*[sm[1] for sm in s["samples"]])
    al = ca.vertcat(*[sm[2] for sm in s["samples"]])
    states, t_all, count = (th, om, al), ca.vertcat(*s["times"]), 0
    if s["free_draw"]:  # a free draw's end, theta3 (a turn on), is a sample too: the last
        end = s["end"]
        states, t_all = tuple(ca.vertcat(x, e) for x, e in zip(states, end, strict=True)), ca.vertcat(t_all, s["t_end"])
    elif drive:
        count = DRAW_SAMPLES_DRIVE + 1
        th_d, om_d, al_d, since = draw_states(q, w2, ca.DM(np.linspace(0.0, 1.0, count)))
        states = (ca.vertcat(th, th_d), ca.vertcat(om, om_d), ca.vertcat(al, al_d))
        t_all = ca.vertcat(t_all, s["t_end"] + since)
    return states, t_all, count, om


def _moving_speeds(s: dict[str, Any], speeds: ca.MX) -> ca.MX:
    """The free profile's sample ``speeds`` where the least crank speed holds: all but, with a hold, the stop's
    (the brake, the standstill and the rise from rest)."""
    if not holds(s["phases"]):
        return speeds
    stopped = STOP_PHASES
    kept = [sm[1] for sm, (phase, _) in zip(s["samples"], s["phases"], strict=True) if phase not in stopped]
    return ca.vertcat(*kept)


def _free_draw_forming(theta: ca.MX, count: int, layout: ParameterLayout, p_case: ca.MX, q: dict) -> ca.MX:
    """The forming force [N] at every sample of a free draw (its last ``count`` samples; zero before them): the
    case's force at the draw's fixed angles (the parameters ``layout.forming``, theta2 ... theta3 evenly), read
    at each sample's share of the draw's angle by linear interpolation (the dense check reads the case's own)."""
    drawn = theta[theta.shape[0] - count :]
    share = ca.fmin(ca.fmax((drawn - drawn[0]) / (q["theta3"] - q["theta2"]), 0.0), 1.0)
    table = ca.interpolant("forming_force", "linear", [np.linspace(0.0, 1.0, FORMING_SAMPLES)], 1)
    force = table.map(count)(share.T, ca.repmat(p_case[layout.forming], 1, count)).T
    return ca.vertcat(ca.DM.zeros(theta.shape[0] - count), force)


def _robot_terms(
    shot: dict[str, Any], period: ca.MX, w2: ca.MX, physical: ca.MX, robots: bool, layout: ParameterLayout, q: dict
) -> dict:
    """The robots' part of the transcription (``halves_nlp._robot_terms``'s, for the shooting): the slide's height
    at any time, each phase's segments in closed form from its start state (clip), then the draw, at the time
    within the period."""
    if not robots:
        return {}
    geometry = layout.geometry(q)

    def height_at(times: list) -> ca.MX:
        t = ca.vertcat(*times)
        t = t - period * ca.floor(t / period)  # within the period (h(theta(t)) is periodic: a smooth wrap)
        ones = ca.DM.ones(1, len(times))
        theta = shot["pieces"][0][3][0] + w2 * ca.fmin(ca.fmax(t - shot["t_end"], 0), period - shot["t_end"])
        for t0, h, n, _, om0, al0, jerk in shot["pieces"]:  # a phase's segments at once: times x segments
            knots = t0 + h * ca.DM(np.arange(n))
            tau = ca.fmin(ca.fmax(ca.repmat(t, 1, n) - (knots @ ones).T, 0), h)
            swept = tau * (ones.T @ om0.T) + tau**2 * (ones.T @ al0.T) / 2 + tau**3 * (ones.T @ jerk.T) / 6
            theta = theta + ca.sum2(swept)
        return layout.formula.jets(theta, geometry)[0]

    first = physical.shape[0] - len(ROBOT_VARIABLES)
    starts = {name.removesuffix("_start"): physical[first + k] for k, (name, _) in enumerate(ROBOT_VARIABLES)}
    return {"height_at": height_at, "robot_starts": starts, "draw_start_time": shot["t_draw_start"]}


def _objective(  # noqa: ANN202 - an MX expression
    q: dict, times_s: tuple[ca.MX, ca.MX, ca.MX], torque: Any, states: tuple, times: ca.MX, rate: bool
):
    """The cycle time; at a rate (its ``target_period`` held by the cycle-time row) the weighted period, the
    motor's heat and supply energy (with a drive; ``planning.solver.nlp.objective_terms``, the losses' terms
    exact where the case gives none: ``k = 0``, ``eta_c = 1``), the draw's time (a draw at constant slide speed
    first: the slide at its set speed wherever the crank allows, as at the most strokes) and, subtracted, the
    robot's window's time (the optimal law's analogue of a law's transfer dwell: a press run slower spends its
    spare time there). ``times_s``: the period, the window's and the draw's time."""
    period, window_time, draw_time = times_s
    if not rate:
        return period
    objective = q["weight_period"] * period - q["weight_dwell"] * window_time + q["weight_draw"] * draw_time
    if torque is not None:
        heat, energy = objective_terms(q, torque, states[2], times, losses=True)
        objective = objective + q["weight_heat"] * heat + q["weight_energy"] * energy
    return objective


def _build(
    formula: Formula,
    limit_ids: tuple[str, ...],
    drive: bool,
    links: tuple[str, ...] = (),
    phases: Layout = PHASES,
    rate: bool = False,
) -> CycleNLP:
    # MX with vector operations (every segment of a phase at once): CasADi derives the Jacobian and the
    # Hessian of this graph in a fraction of the time a scalar SX graph of the same problem takes, and
    # evaluates them about as fast
    layout = ParameterLayout(formula, limit_ids, drive, rate, links if drive else (), hold=holds(phases))
    robots = "robots" in limit_ids
    variables, index = variables_of(phases, robots), index_of(phases, robots)
    x = ca.MX.sym("x", len(variables))
    p_case = ca.MX.sym("p", layout.size)
    p_scale = ca.MX.sym("scale", len(variables))
    physical = x * p_scale
    v = {name: physical[i] for name, i in index.items()}
    unit = {name: p_scale[i] for name, i in index.items()}
    q = layout.symbols(p_case)
    w2 = v["draw_speed"]
    rows = Rows()
    shot = _shooting(phases, physical, v, unit, q, index)
    omu, omd = _structure_rows(rows, shot, v, unit, q)
    states, t_all, count, speeds = _all_samples(shot, q, w2, drive)
    free = draws_freely(phases)  # the draw a phase (sampled: its samples the last) or at the constant w2
    free_count = dict(phases).get("draw", 0) * SAMPLES_PER_SEGMENT["draw"] + int(free)  # a free draw's, and its end
    forming = _free_draw_forming(states[0], free_count, layout, p_case, q) if free and drive else None
    samples, torque, lift = sample_states(formula, layout, q, p_case, states, t_all, count, forming)
    period = shot["t_end"] if free else shot["t_end"] + (q["theta3"] - q["theta2"]) / w2
    window_time = dict(phases)["transfer"] * v["transfer_step"]
    nlp = Transcription(
        **samples,
        **_robot_terms(shot, period, w2, physical, robots, layout, q),
        period=period,
        window_time=window_time,
        speeds=Extremes(speeds, signed=False, sampled=True),
        accelerations=Extremes(ca.vertcat(*shot["knot_accels"]), signed=True),
        jerks=None,  # the bounds of the segments' jerks
        lowest_speeds=_moving_speeds(shot, speeds),
        crossings=[(omu, q["die_up_slope"]), (omd, q["die_down_slope"])],
        zone=True,
        rate=rate,
        free_draw_count=free_count,
        speed_unit=unit["draw_speed"],
    )
    refinable = add_limit_rows(rows, nlp, layout)

    draw_time = period - shot["t_draw_start"]  # from theta2 to theta3 (a free draw's phase or at w2)
    objective = _objective(q, (period, window_time, draw_time), torque, states, t_all, rate)
    problem = {"x": x, "p": ca.vertcat(p_case, p_scale), "f": objective, "g": ca.vertcat(*rows.g)}
    options = {**CYCLE_OPTIONS, **DRIVE_OPTIONS}  # MUMPS's AMD ordering: the same iterations, 5-10 % faster here
    options |= FREE_RATE_OPTIONS if rate else {}
    options |= {"ipopt.max_wall_time": ROBOTS_WALL_S} if robots else {}
    fine = phases not in (PHASES, FREE_DRAW, first_layout(False, True), first_layout(True, True))  # (a name's part)
    name = "press_cycle_optimal" + ("_fine" if fine else "") + ("_slide" if free else "") + ("_drive" if drive else "")
    name += ("_hold" if holds(phases) else "") + ("_rate" if rate else "")
    program = NLPSolver(name, problem, options, None, WARM_OPTIONS, lift)
    return CycleNLP(
        program,
        *rows.bounds(),
        tuple(rows.blocks),
        layout,
        variables,
        partial(variable_scales, phases=phases),
        partial(variable_bounds, phases=phases),
        partial(make_plan, phases=phases),
        refinable=refinable,
        complete=partial(complete_robots, phases) if robots else None,
    )


def layout_of(nlp: CycleNLP) -> Layout:
    """The phases' layout of an optimal law's NLP, read off its variables (each phase's step, then its jerks)."""
    names = [name for name, _ in nlp.variables]
    phases = [name.removesuffix("_step") for name in names if name.endswith("_step")]
    return tuple((phase, sum(1 for name in names if name.startswith(f"{phase}_jerk_"))) for phase in phases)


def complete_robots(phases: Layout, values: dict[str, float]) -> dict[str, float]:
    """``values`` with the robots' starts where a start lacks them: the unloader at theta4, the loader
    halfway to theta1 (the transfer phase's ends)."""
    if "unloader_start" in values:
        return values
    steps = dict(phases)
    t4 = sum(values[f"{phase}_step"] * steps[phase] for phase in (*STOP_PHASES, "return") if phase in steps)
    t1 = t4 + values["transfer_step"] * steps["transfer"]
    return {**values, "unloader_start": t4, "loader_start": 0.5 * (t4 + t1)}


def _interleave(columns: list) -> ca.MX:
    """``a0, b0, ..., a1, b1, ...`` of column vectors of one length."""
    return ca.reshape(ca.horzcat(*columns).T, -1, 1)


@cache
def free_nlp(
    formula: Formula,
    limit_ids: tuple[str, ...],
    drive: bool = False,
    links: tuple[str, ...] = (),
    phases: Layout = PHASES,
    rate: bool = False,
) -> CycleNLP:
    """The compiled NLP of the optimal law for a mechanism's ``formula`` and the limits ``limit_ids``, with
    the motor's torque when ``drive`` (the mechanism's massive ``links`` in it), on the phases' ``layout``, at a
    ``rate`` (:func:`_objective`); built on first use in a process, then reused."""
    return _build(formula, limit_ids, drive, links, phases, rate)


def free_nlp_for(case: Case, phases: Layout | None = None, drive: bool = True, rate: bool = False) -> CycleNLP:
    """The optimal law's NLP of ``case``'s mechanism and limits on the phases' ``layout`` (the case's first by
    default), with the motor's rows when it has a drive (and ``drive``), at a ``rate`` (its cycle time held by a
    search with ``fixed_period``, the objective's weights its parameters)."""
    phases = phases or first_layout(case.free_draw, case.hold_angle is not None)
    drive = drive and case.drive is not None
    links = drive_links(case) if drive else ()
    return free_nlp(case.machine.formula, nlp_limits(case, drive), drive, links, phases, rate)
