"""The optimal law: the fastest jerk-limited cycle, planned as a free profile (no fixed motion law).

Outside the constant-speed draw the crank follows segments of constant jerk ``|j_k| <= J`` (``J`` =
``limits.crank_jerk_rad_s3``, required for this law) in three phases
(``planning.model.free_profile.PHASES``): the return theta3 -> theta4, the robot's window theta4 ->
theta1 and the feed theta1 -> theta2, each of equal steps ``h`` [s] of its own. Multiple shooting: the
state (angle, speed, acceleration) at every knot is a variable, and each segment's closed form ties
it to the next, so the NLP is sparse and the acceleration continuous everywhere. Fixed: theta3, w2
and zero acceleration at the start, theta4 and theta1 at the phase boundaries, theta2 + 2 pi, w2 and
zero acceleration at the end. Minimised: the cycle time. Subject to: the window phase lasts at least
the transfer time; |slider acceleration| <= the limit at every knot and quarter of a segment (refined
against the dense verification like the laws', as are the sampled die-speed and crank-speed limits);
the die speed at the die-height crossings (times of their own, as in the laws' NLP) and wherever the
slide is at or below the die height (same samples); the draw speed within its bounds; the crank
speed between the minimum and the top speed; |crank acceleration| <= its limit at the knots (it is
piecewise linear); with a drive, the motor's limits as for the laws. Placement has no meaning: theta1
and theta4 are where the phases meet.

Initial guess: a seven-segment plan of the case under the same jerk limit (the first start of its NLP
that converges, neither verified nor confirmed as the optimum: a start needs no more), sampled on the
phases' grids (the bound's profile has no jerk limit and is a poorer start); a neighbouring case's
optimal plan (a sweep, a looser limit) starts first and, when it holds here, is a candidate answer.
The plans are verified densely like every other.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cache

import casadi as ca
import numpy as np

from planning.model.case import RPM, Case
from planning.model.free_profile import OPTIMAL, PHASES, FreeProfileParameters
from planning.model.plan import Plan, SolverInfo, rotate_to_tdc
from planning.model.profile import Segment, advance
from planning.solver.ipopt import NLPSolver
from planning.solver.nlp import (
    CYCLE_OPTIONS,
    DRAW_SAMPLES_DRIVE,
    DRIVE_OPTIONS,
    DRIVE_PARAMETERS,
    FORMING_SAMPLES,
    PARAMETER_INDEX,
    PARAMETERS,
    SAMPLES_CONSTANT,
    CycleNLP,
    Rows,
    _drive_constraints,
    clipped_advance,
    draw_states,
)
from planning.solver.optimize import MAX_TIME_S, Solution, _prepare, _Search, converged_plan, solve
from planning.solver.outcomes import Infeasible
from planning.solver.verify import verify
from press.kinematics import height, height_derivatives

SEED_LAW = "seven-segment"  # a jerk-limited law whose plan starts the NLP
# the limits are held at every knot and at evenly spaced points inside each segment, this many per
# segment (knot included) in each phase: the robot's window has the longest segments and the highest
# speeds (around TDC, where the slider acceleration peaks), so it is sampled finer
SAMPLES_PER_SEGMENT = {"return": 4, "transfer": 8, "feed": 4}
STATES = ("angle", "speed", "accel")
# relative: the sampled minimum crank speed is held this much above the limit (the speed is cubic between
# the samples and may dip below them; the slowest point, near TDC, is usually at the limit)
MIN_SPEED_BACKOFF = 1e-2
# a re-solve with a refined limit starts nearer the optimum than the laws' (about half the iterations
# with this barrier parameter; the laws keep the wrapper's, which finds their optima as before)
WARM_OPTIONS = {"ipopt.mu_init": 1e-8}


def _variables() -> tuple[tuple[str, str], ...]:
    # the die-height crossings outside the draw: going up in the return (time from theta3), going down in
    # the feed (time from theta1)
    out: list[tuple[str, str]] = [("draw_speed", "speed"), ("die_up_time", "time"), ("die_down_time", "time")]
    for phase, n in PHASES:
        out.append((f"{phase}_step", "step"))
        out += [(f"{phase}_jerk_{k}", "jerk") for k in range(n)]
        # the knots inside the phase and its end (the start is the previous phase's end, or theta3)
        for k in range(1, n + 1):
            out += [
                (f"{phase}_{name}_{k}", kind) for name, kind in zip(STATES, ("angle", "speed", "accel"), strict=True)
            ]
    return tuple(out)


VARIABLES = _variables()
INDEX = {name: i for i, (name, _) in enumerate(VARIABLES)}


def variable_scales(case: Case) -> np.ndarray:
    """Scales from the press's characteristic time and speed (as the laws' NLP) and the jerk limit."""
    R, L, A = case.press.crank_radius_mm, case.press.rod_length_mm, case.limits.slider_accel_mm_s2
    t_star = math.sqrt(R / A)
    w_star = math.sqrt(A / (R + R**2 / L))
    unit = {
        "speed": 0.42 * w_star,
        "step": 0.05 * t_star,
        "angle": 1.0,
        "accel": w_star / t_star,
        "jerk": case.limits.crank_jerk_rad_s3,
        "time": t_star,
    }
    return np.array([unit[kind] for _, kind in VARIABLES])


def _build(drive: bool) -> CycleNLP:
    # MX with vector operations (every segment of a phase at once): CasADi derives the Jacobian and the
    # Hessian of this graph in a fraction of the time a scalar SX graph of the same problem takes, and
    # evaluates them about as fast
    x = ca.MX.sym("x", len(VARIABLES))
    p_case = ca.MX.sym("p", len(PARAMETERS) + (len(DRIVE_PARAMETERS) + FORMING_SAMPLES if drive else 0))
    p_scale = ca.MX.sym("scale", len(VARIABLES))
    physical = x * p_scale
    v = {name: physical[i] for name, i in INDEX.items()}
    unit = {name: p_scale[i] for name, i in INDEX.items()}
    q = {name: p_case[i] for i, name in enumerate(PARAMETERS)}
    w2 = v["draw_speed"]

    rows = Rows()
    add = rows.add

    ends = {"return": q["theta4"], "transfer": q["theta1"] + 2 * np.pi, "feed": q["theta2"] + 2 * np.pi}
    start = (q["theta3"], w2, ca.MX(0.0))
    t0 = ca.MX(0.0)
    shooting, boundary, samples, times, knot_accels = [], [], [], [], []
    crossings = {}
    for phase, n in PHASES:
        h = v[f"{phase}_step"]
        first = INDEX[f"{phase}_jerk_0"]
        jerk = physical[first : first + n]
        # the knots 1 .. n of the phase: n rows of (angle, speed, accel), stored row after row
        states = ca.reshape(physical[first + n : first + 4 * n], 3, n).T
        nxt = [states[:, i] for i in range(3)]
        th0, om0, al0 = (ca.vertcat(start[i], nxt[i][: n - 1]) for i in range(3))
        if phase in ("return", "feed"):  # the die-height crossing of this phase, in closed form (clip)
            when = v["die_up_time" if phase == "return" else "die_down_time"]
            tau = ca.fmin(ca.fmax(when - h * ca.DM(np.arange(n)), 0), h)
            crossings[phase] = (clipped_advance(tau, start[0], start[1], om0, al0, jerk, 0.0), when, n * h)
        th1, om1, al1, _ = advance(th0, om0, al0, jerk, 0.0, h)
        shooting.append(
            ca.vertcat(th1 - nxt[0], (om1 - nxt[1]) / unit["draw_speed"], (al1 - nxt[2]) / unit[f"{phase}_accel_1"])
        )
        end = tuple(states[n - 1, i] for i in range(3))
        boundary.append(end[0] - ends[phase])
        # samples in time order: every knot of the phase and the points inside each segment
        fractions = [k / SAMPLES_PER_SEGMENT[phase] for k in range(1, SAMPLES_PER_SEGMENT[phase])]
        parts = [advance(th0, om0, al0, jerk, 0.0, h * f) for f in fractions]
        samples.append(tuple(_interleave([(th0, om0, al0)[i], *(part[i] for part in parts)]) for i in range(3)))
        local = ca.DM(np.arange(n))
        times.append(_interleave([t0 + local * h, *(t0 + (local + f) * h for f in fractions)]))
        knot_accels.append(ca.vertcat(al0, end[2]))
        t0 = t0 + n * h
        start = end
    add("segments join (closed form)", ca.vertcat(*shooting), 0.0, 0.0)
    add("key angles", ca.vertcat(*boundary[:2]), 0.0, 0.0)
    add(
        "cycle closes",
        ca.vertcat(boundary[2], (start[1] - w2) / unit["draw_speed"], start[2] / unit["feed_accel_1"]),
        0.0,
        0.0,
    )
    window = PHASES[1][1] * v["transfer_step"]
    add("transfer time", window - q["transfer_time"], 0.0, np.inf)
    (thu, omu), t_up, span_up = crossings["return"]
    (thd, omd), t_down, span_down = crossings["feed"]
    add("key points in order", ca.vertcat(span_up - t_up, span_down - t_down), 0.0, np.inf)
    add(
        "die crossing angles",
        ca.vertcat(
            q["die_up_active"] * (thu - q["die_up_angle"]),
            q["die_down_active"] * (thd - (q["die_down_angle"] + 2 * np.pi)),
        ),
        0.0,
        0.0,
    )
    add(
        "die-height speed",
        ca.vertcat(q["die_up_slope"] * omu, q["die_down_slope"] * omd) / q["die_speed"],
        -np.inf,
        1.0,
    )

    th = ca.vertcat(*[sm[0] for sm in samples])
    om = ca.vertcat(*[sm[1] for sm in samples])
    al = ca.vertcat(*[sm[2] for sm in samples])
    t_free = ca.vertcat(*times)
    d1, d2, _ = height_derivatives(th, q["R"], q["L"])
    zone = ca.fmax(
        (height(th, q["R"], q["L"]) - q["die_height"]) / q["R"], (q["die_speed"] - ca.fabs(d1 * om)) / q["die_speed"]
    )
    die_zone_rows = add("die-zone speed", zone, 0.0, np.inf)
    add("crank speed limit", om / q["crank_speed_max"], -np.inf, 1.0)
    add("minimum crank speed", (om - q["min_crank_speed"]) / unit["draw_speed"], 0.0, np.inf)
    add("crank acceleration limit", ca.vertcat(*knot_accels) / q["crank_accel_max"], -1.0, 1.0)

    # the draw's samples last (the drive's forming force is given at them)
    draw_time = (q["theta3"] - q["theta2"]) / w2
    count = DRAW_SAMPLES_DRIVE if drive else SAMPLES_CONSTANT
    th_d, om_d, al_d, since = draw_states(q, w2, ca.DM(np.linspace(0.0, 1.0, count + 1)))
    th_all, om_all, al_all = ca.vertcat(th, th_d), ca.vertcat(om, om_d), ca.vertcat(al, al_d)
    d1a, d2a, _ = height_derivatives(th_all, q["R"], q["L"])
    add("slider acceleration", (d2a * om_all**2 + d1a * al_all) / q["accel_limit"], -1.0, 1.0)
    period = t0 + draw_time
    if drive:
        t_all = ca.vertcat(t_free, t0 + since)
        _drive_constraints(add, p_case, th_all, om_all, al_all, d1a, d2a, t_all, period)

    nlp = {"x": x, "p": ca.vertcat(p_case, p_scale), "f": period, "g": ca.vertcat(*rows.g)}
    options = {**CYCLE_OPTIONS, **DRIVE_OPTIONS}  # MUMPS's AMD ordering: the same iterations, 5-10 % faster here
    program = NLPSolver("press_cycle_optimal" + ("_drive" if drive else ""), nlp, options, None, WARM_OPTIONS)
    return CycleNLP(
        program,
        *rows.bounds(),
        tuple(rows.blocks),
        published_rows=slice(0, 0),
        die_zone_rows=die_zone_rows,
        variables=VARIABLES,
        sampled_speed_limits=True,
    )


def _interleave(columns: list) -> ca.MX:
    """``a0, b0, ..., a1, b1, ...`` of column vectors of one length."""
    return ca.reshape(ca.horzcat(*columns).T, -1, 1)


@cache
def optimal_nlp(drive: bool = False) -> CycleNLP:
    """The compiled NLP of the optimal law (built on first use in a process, then reused)."""
    return _build(drive)


def _bounds(case: Case, search: _Search) -> tuple[np.ndarray, np.ndarray]:
    J = case.limits.crank_jerk_rad_s3
    w2_lo, w2_hi = search.draw_speed_range
    longest = max(MAX_TIME_S, 1.01 * 2 * math.pi / (case.limits.min_crank_speed_rpm * RPM))
    lo, hi = np.full(len(VARIABLES), -np.inf), np.full(len(VARIABLES), np.inf)
    for name, kind in VARIABLES:
        i = INDEX[name]
        if kind == "jerk":
            lo[i], hi[i] = -J, J
        elif kind == "step":
            phase = name.removesuffix("_step")
            lo[i], hi[i] = 0.0, longest / dict(PHASES)[phase]
        elif kind == "speed":
            lo[i], hi[i] = 0.0, 1e3
    lo[INDEX["draw_speed"]], hi[INDEX["draw_speed"]] = w2_lo, w2_hi
    for k in ("die_down", "die_up"):
        i = INDEX[f"{k}_time"]
        active = search.parameters[PARAMETER_INDEX[f"{k}_active"]] != 0.0
        lo[i], hi[i] = (0.0, longest) if active else (0.0, 0.0)
    return lo, hi


def make_plan(case: Case, values: dict[str, float], placement: str, info: SolverInfo) -> Plan:
    """The plan of the optimal NLP's values: the profile propagated from theta3 through the segments'
    closed forms (the NLP's knot states agree with it to its tolerance), then the draw."""
    th1, th2, th3, th4 = (float(a) for a in case.key_angles)
    durations, jerks = [], []
    for phase, n in PHASES:
        durations += [values[f"{phase}_step"]] * n
        jerks += [values[f"{phase}_jerk_{k}"] for k in range(n)]
    params = FreeProfileParameters(tuple(durations), tuple(jerks), values["draw_speed"], th2, th3)
    segs = [seg for seg in params.segments() if seg.duration > 0]
    draw = Segment("draw:constant", params.draw_time, 0.0, 0.0)
    profile = rotate_to_tdc([*segs, draw], th3, params.draw_speed)
    plan = Plan(params, profile, (th1, th2, th3, th4), "free", info, motion_law=OPTIMAL)
    t = plan.key_times()
    structure = {"closing": plan.segment_at(float(t[0])), "opening": plan.segment_at(float(t[3]))}
    return replace(plan, structure=structure, nlp_values=dict(values))


def seed_values(seed: Plan) -> dict[str, float]:
    """A plan of another law as the optimal NLP's values: its profile sampled on each phase's uniform
    grid between the key points, the jerk of each segment from the change of acceleration across it."""
    prof, period = seed.profile, seed.period
    t1, t2, t3, t4 = (float(t) for t in seed.key_times())
    spans = {"return": (t3, t4), "transfer": (t4, t1 + period), "feed": (t1 + period, t2 + period)}
    values = {"draw_speed": float(seed.parameters.draw_speed), "die_up_time": seed.nlp_values["die_up_time"]}
    values["die_down_time"] = max(seed.nlp_values["die_down_time"] - seed.nlp_values["closing_time"], 0.0)
    for phase, n in PHASES:
        a, b = spans[phase]
        h = (b - a) / n
        t = a + h * np.arange(n + 1)
        wrapped = t >= period
        th, om, al, _ = prof.at_time(np.where(wrapped, t - period, t))
        th = th + np.where(wrapped | (phase == "feed"), 2 * np.pi, 0.0)
        values[f"{phase}_step"] = h
        for k in range(n):
            values[f"{phase}_jerk_{k}"] = float((al[k + 1] - al[k]) / h)
        for k in range(1, n + 1):
            values |= {f"{phase}_angle_{k}": float(th[k]), f"{phase}_speed_{k}": float(om[k])}
            values[f"{phase}_accel_{k}"] = float(al[k])
    return values


def solve_optimal(case: Case, neighbour: Plan | None = None) -> Solution:
    """The fastest verified cycle of ``case`` under the optimal law (needs ``limits.crank_jerk_rad_s3``).

    ``neighbour``: an optimal plan of a neighbouring case (a sweep, an edit on the web page, a looser
    limit). When it holds here it is a candidate; its values start the NLP, and when that start verifies
    the seed law is not solved at all (a warm re-solve)."""
    if case.limits.crank_jerk_rad_s3 is None:
        raise Infeasible(
            "the optimal law needs limits.crank_jerk_rad_s3 (the jerk it may use)", limit="limits.crank_jerk_rad_s3"
        )
    search = _prepare(case, "free", optimal_nlp(case.drive is not None))  # prechecks, parameters, w2 range
    search.scale, search.make_plan = variable_scales(case), make_plan
    search.lbx, search.ubx = _bounds(case, search)
    search.parameters = search.parameters.copy()
    search.parameters[PARAMETER_INDEX["min_crank_speed"]] *= 1 + MIN_SPEED_BACKOFF
    if neighbour is not None and neighbour.motion_law == OPTIMAL and neighbour.nlp_values:
        if np.allclose(neighbour.key_angles, case.key_angles, rtol=0, atol=1e-12):
            check = verify(neighbour, case)  # a neighbouring case's plan that holds here is an answer
            if check.passed:
                search.consider(Solution(neighbour, check), neighbour.period)
        if search.attempt(neighbour.nlp_values, "free") is not None:
            return search.answer()
    seeded = case.with_law(SEED_LAW)
    seed = converged_plan(seeded) or solve(seeded, "free").plan
    search.iterations += seed.solver.iterations
    search.starts += seed.solver.starts
    search.multi_start([seed_values(seed)], "free", confirm=False)
    return search.answer()
