"""The CasADi nonlinear program of one press cycle under a motion law.

Built once per process and law, then reused: every number of a case, and the scale of every decision
variable (:func:`variable_scales`, applied by the solver wrapper ``planning.solver.ipopt``), enters as a
parameter and the placement structure is a pair of constraint rows whose bounds are set per solve, so a
sweep, a multi-start or the other placement only calls the compiled solver again. Decision variables are
scaled to O(1): the four speeds w1, w2, wm1, wm2, the durations of the four halves, the transfer dwell,
the law's shape parameter and the times of the key points.

Time 0 of the NLP is the end of the draw (theta3); the stages follow as in ``planning.model.cycle``. The
crank angle at any time t before the draw is evaluated in closed form as
``theta(t) = theta3 + sum_k D_k(clip(t - s_k, 0, T_k))``, with ``D_k`` the angle swept ``tau`` into
segment k. The clip makes theta(t) continuously differentiable in t and in every segment variable
(the kink of one term is cancelled by the next), so a key point may move across knots inside one
smooth NLP: that is the ``free`` placement. The ``published`` placement fixes the key points where
the relations under the paper's Fig. 6 put them: t1 = x1 + T1 (a quarter, one sub-segment, into the
feed acceleration), t4 = x3 + 3 T14 (three quarters into the return deceleration).

Constraints: the peaks lie above the speeds they join, one jerk per S-curve (Eq. 14, improved S-curve
only), the cycle closes at 2 pi, the key angles theta1 and theta4 are met, time(theta4 -> theta1) >=
transfer time, |slider acceleration| <= limit at sample points of every segment (the orchestrator
lowers that sampled limit until the dense verification holds between samples), slider speed at the
die-height crossings outside the draw, draw speed within its bounds, crank speed >= the minimum crank
speed (the halves are monotone), and the drive's limits: peak speeds, the closed-form peak
acceleration and jerk of every half.

The drive NLPs (motor torque rows, the RMS integral) sample the draw at its fixed angles theta2 ...
theta3 at the constant speed w2 instead of following the cycle's closed form there: the two agree
wherever the cycle closes (a constraint every solution meets), and the draw's rows then depend on w2
alone (sparse rows; on the side-panel drive a quarter fewer iterations and about half the time per
iteration, same optima). The kinematic NLP keeps the closed form: there the change saved nothing
(more iterations).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import casadi as ca
import numpy as np

from planning.model.case import Placement
from planning.model.cycle import CycleParameters, cycle_segments
from planning.model.laws import DEFAULT_LAW, get_law
from planning.model.profile import Segment, advance, advance_segment, knot_states, shape_part
from planning.solver.ipopt import NLPResult, NLPSolver
from press.dynamics import DriveModel, crank_torque, motor_speed, motor_torque
from press.kinematics import height, height_derivatives

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


def variable_scales(crank_radius_mm: float, rod_length_mm: float, slider_accel_mm_s2: float) -> np.ndarray:
    """Variable scales from the press's own characteristic time ``T* = sqrt(R / A)`` [s] and speed
    ``W* = sqrt(A / (R + R^2/L))`` [rad/s] (A the slider-acceleration limit): speeds ~ W*,
    durations of the halves ~ T*, stage times ~ 10 T*. The factors make the variables O(1) for a
    press cycle of the usual proportions; they span orders of magnitude from a small fast press to a
    heavy slow one."""
    R, L, A = crank_radius_mm, rod_length_mm, slider_accel_mm_s2
    t_star = math.sqrt(R / A)
    w_star = math.sqrt(A / (R + R**2 / L))
    unit = {"speed": 0.42 * w_star, "half": 1.12 * t_star, "time": 2.8 * t_star, "shape": 1.0}
    return np.array([unit[kind] for _, kind in VARIABLES])


# Parameters of a case, in inside units
PARAMETERS: tuple[str, ...] = (
    "R",  # crank radius [mm]
    "L",  # rod length [mm]
    "theta1",  # closing [rad]
    "theta2",  # draw start
    "theta3",  # draw end
    "theta4",  # opening
    "transfer_time",  # [s]
    "accel_limit",  # slider acceleration limit incl. back-off [mm/s^2]
    "die_speed",  # [mm/s]
    "die_down_angle",  # target angle of the descending crossing [rad] (theta2 when inside the draw)
    "die_down_slope",  # |dh/dtheta| there [mm/rad], 0 when the crossing lies in the draw
    "die_down_active",  # 1 when the crossing lies outside the draw, else 0 (its time is then fixed)
    "die_up_angle",
    "die_up_slope",
    "die_up_active",
    "crank_speed_max",  # motor limits [rad/s, rad/s^2, rad/s^3] (very large when the case sets none)
    "crank_accel_max",
    "crank_jerk_max",
    "die_height",  # [mm above BDC] (the drive NLP holds the die speed at every sample below it)
    "min_crank_speed",  # [rad/s] (the optimal law's samples; the laws' halves are monotone, bounded by w1, w2)
)
PARAMETER_INDEX = {name: i for i, name in enumerate(PARAMETERS)}
# Parameters of a drive (the NLP of a case with a ``drive:`` section has them after PARAMETERS), SI units
DRIVE_PARAMETERS: tuple[str, ...] = (
    "drive_M",  # slide-side mass [kg]
    "drive_J0",  # crank-side inertia [kg m^2]
    "drive_F_cb",  # counterbalance [N]
    "drive_i",  # gear ratio
    "drive_eta",  # gear efficiency
    "drive_J_m",  # motor-side inertia [kg m^2]
    "motor_peak",  # peak torque [N m] (the orchestrator lowers it if the dense check finds an overshoot)
    "motor_base_speed",  # [rad/s] at the motor
    "motor_rms",  # rated (RMS) torque [N m] (likewise)
    # the objective (``planning.solver.objectives``): f = weight_period * period + weight_heat * heat
    # + weight_energy * supply energy - weight_dwell * transfer dwell; max-SPM sets weight_period = 1, the rest 0
    "weight_period",  # [1/s]
    "weight_heat",  # [1/(N^2 m^2 s)] heat = integral T_m^2 dt over the cycle
    "weight_energy",  # [1/J] supply energy = integral (r P + (1 - r) smoothmax(P, 0)) dt
    "weight_dwell",  # [1/s] the constant-speed transfer dwell
    "regen",  # r, the share of the returned energy the supply takes back, 0 ... 1
    "power_smoothing",  # [W] epsilon of smoothmax(P, 0) = (P + sqrt(P^2 + epsilon^2)) / 2
    "target_period",  # [s] the cycle time of a target rate (the "cycle time" row; unbounded for max-SPM)
)
DRIVE_INDEX = {name: len(PARAMETERS) + i for i, name in enumerate(DRIVE_PARAMETERS)}

CYCLE_OPTIONS = {  # added to the wrapper's base options
    "ipopt.constr_viol_tol": 1e-10,
    "ipopt.max_iter": 400,  # a start that has not converged by then is dropped (others remain)
}
# the rate NLP's objectives (heat, energy; normalised to 1 at the baseline) are wanted to about a millionth:
# a tighter optimality tolerance only lengthens IPOPT's crawl where a law's half degenerates (hundreds of
# iterations for the last digits); the constraints keep CYCLE_OPTIONS' tolerance and the dense verification
RATE_OPTIONS = {"ipopt.tol": 1e-6}
# the drive NLPs' rows (the motor torque at every sample, the RMS integral) depend on every variable: with
# MUMPS's approximate-minimum-degree ordering an iteration takes 20-30 % less time than with its automatic
# choice (measured; the optimal law's NLP uses it too); the kinematic NLP keeps the automatic choice (with
# AMD it needs more iterations)
DRIVE_OPTIONS = {"ipopt.mumps_pivot_order": 0}
SAMPLES_PER_SUBSEGMENT = 5
SAMPLES_CONSTANT = 20
DRAW_SAMPLES_DRIVE = 80  # with a drive the draw is sampled finer: the forming force changes fast there
FORMING_SAMPLES = DRAW_SAMPLES_DRIVE + 1  # forming force [N] at the draw's samples, theta2 ... theta3


@dataclass(frozen=True)
class ConstraintBlock:
    """Name and row range of a group of NLP constraints (for reading multipliers and violations)."""

    name: str
    start: int
    stop: int

    @property
    def case_field(self) -> str:
        """The case field this block enforces (what a user can change), :data:`BLOCK_FIELDS`."""
        return BLOCK_FIELDS[self.name]


# the case field behind each constraint block: a failure message names what the user can change
BLOCK_FIELDS = {
    "peak speeds above their ends": "planner.motion_law",
    "one jerk per S-curve (Eq. 14)": "planner.motion_law",
    "cycle closes": "key_points",
    "key angles": "key_points",
    "transfer time": "process.transfer_time_s",
    "key points in order": "key_points",
    "key angles (published placement)": "planner.placement",
    "die crossing angles": "limits.die_height_mm",
    "die-height speed": "limits.die_speed_mm_s",
    "die-zone speed": "limits.die_speed_mm_s",
    "slider acceleration": "limits.slider_accel_mm_s2",
    "crank speed limit": "limits.crank_speed_rpm",
    "crank acceleration limit": "limits.crank_accel_rad_s2",
    "crank jerk limit": "limits.crank_jerk_rad_s3",
    "motor peak torque": "drive.motor.peak_torque_Nm",
    "motor RMS torque": "drive.motor.rated_torque_Nm",
    "cycle time": "planner.target_spm",
}


class Rows:
    """The constraint rows of an NLP as they are added: named blocks, expressions and bounds."""

    def __init__(self) -> None:
        self.blocks: list[ConstraintBlock] = []
        self.g: list = []
        self.lb: list[float] = []
        self.ub: list[float] = []

    def add(self, name: str, expr: ca.SX, lo, hi) -> slice:  # noqa: ANN001 - a number or an array
        """Rows ``lo <= expr <= hi`` as the block ``name``; returns their slice."""
        expr = ca.vec(expr)
        n = expr.shape[0]
        self.blocks.append(ConstraintBlock(name, len(self.lb), len(self.lb) + n))
        self.g.append(expr)
        self.lb.extend(np.broadcast_to(lo, (n,)).tolist())
        self.ub.extend(np.broadcast_to(hi, (n,)).tolist())
        return slice(len(self.lb) - n, len(self.lb))

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array(self.lb), np.array(self.ub)


def clipped_advance(tau, theta_start, omega_start, omega0, alpha0, j0, j1) -> tuple:  # noqa: ANN001 - SX or MX
    """Crank angle and speed after consecutive linear-jerk segments with start speeds ``omega0``,
    accelerations ``alpha0`` and jerks ``j0 + j1 tau`` (vectors), each run for its ``tau`` (the time
    clipped to the segment: 0 before it, its duration after it), from ``theta_start``, ``omega_start``."""
    th, om, _, _ = advance(0.0, omega0, alpha0, j0, j1, tau)
    return theta_start + ca.sum1(th), omega_start + ca.sum1(om - omega0)


def draw_states(q: dict, w2, fractions: ca.DM) -> tuple:  # noqa: ANN001 - SX or MX
    """The draw's states at ``fractions`` of it: the fixed angles theta2 ... theta3 (one turn on, as the cycle
    reaches them after time 0 at theta3), the constant speed ``w2``, no acceleration, and their times from the
    draw's start [s]. Wherever the cycle closes (as at every solution) these are its states, and every row
    built on them depends on ``w2`` alone."""
    sweep = fractions * (q["theta3"] - q["theta2"])
    n = fractions.shape[0]
    return q["theta2"] + 2 * np.pi + sweep, w2 * ca.DM.ones(n), ca.DM.zeros(n), sweep / w2


def _angle_at(t: ca.SX, starts: list, states: list, segs: list[Segment]) -> tuple[ca.SX, ca.SX]:
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
class CycleNLP:
    """The compiled NLP; see the module docstring. ``published_rows`` pin theta1 and theta4 to the
    points of the published structure; they are left unbounded for the free placement."""

    program: NLPSolver
    lbg: np.ndarray
    ubg: np.ndarray
    blocks: tuple[ConstraintBlock, ...]
    published_rows: slice
    period_rows: slice | None = None  # the drive NLP's "cycle time" row (period - target_period)
    die_zone_rows: slice | None = None  # the drive NLP's die-zone speed at every sample below the die height
    variables: tuple[tuple[str, str], ...] = VARIABLES  # name and scale kind of each decision variable
    sampled_speed_limits: bool = False  # the crank speed limits are sampled rows (the optimal law's NLP)

    def values_of(self, result: NLPResult) -> dict[str, float]:
        """The variables of a solve by name."""
        return {k: float(result.x[j]) for j, (k, _) in enumerate(self.variables)}

    def bounds(self, placement: Placement, fixed_period: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """``(lbg, ubg)`` for ``placement``; ``fixed_period``: the cycle time held at the parameter
        ``target_period`` (a target rate; drive NLP only)."""
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        pinned = 0.0 if placement == "published" else np.inf
        lbg[self.published_rows], ubg[self.published_rows] = -pinned, pinned
        if fixed_period:
            if self.period_rows is None:
                raise ValueError("only the drive NLP holds a target cycle time")
            lbg[self.period_rows], ubg[self.period_rows] = 0.0, 0.0
        return lbg, ubg

    def solve(
        self,
        start: dict[str, float],
        case_parameters: np.ndarray,
        lbx: np.ndarray,
        ubx: np.ndarray,
        placement: Placement,
        scale: np.ndarray,
        warm_start: tuple[np.ndarray, np.ndarray] | None = None,
        fixed_period: bool = False,
    ) -> NLPResult:
        """One IPOPT solve from the variable values ``start`` (physical units) for the case parameters
        (:data:`PARAMETERS` order), physical bounds ``lbx``/``ubx`` and the variables' ``scale``;
        ``warm_start``: the multipliers of a nearby solve; ``fixed_period``: see :meth:`bounds`."""
        lbg, ubg = self.bounds(placement, fixed_period)
        x0 = np.array([start[k] for k, _ in self.variables])
        return self.program.solve(x0, lbx, ubx, lbg, ubg, p=case_parameters, scale=scale, warm_start=warm_start)

    def worst_violation(self, placement: Placement, g: np.ndarray, fixed_period: bool = False) -> tuple[str, float]:
        """The constraint block with the largest violation at ``g`` (the last iterate)."""
        worst = self.worst_block(placement, g, fixed_period)
        lbg, ubg = self.bounds(placement, fixed_period)
        viol = np.maximum(lbg - g, 0) + np.maximum(g - ubg, 0)
        return worst.name, float(np.max(viol[worst.start : worst.stop], initial=0.0))

    def worst_block(self, placement: Placement, g: np.ndarray, fixed_period: bool = False) -> ConstraintBlock:
        """The block with the largest violation at ``g``."""
        lbg, ubg = self.bounds(placement, fixed_period)
        viol = np.maximum(lbg - g, 0) + np.maximum(g - ubg, 0)
        return max(self.blocks, key=lambda b: float(np.max(viol[b.start : b.stop], initial=0.0)))


def values_of(result: NLPResult) -> dict[str, float]:
    """The variables of a solve by name."""
    return {k: float(result.x[j]) for j, (k, _) in enumerate(VARIABLES)}


def _drive_constraints(add, p_case, th, om, al, d1, d2, times, period) -> tuple[ca.SX, ca.SX]:  # noqa: ANN001 - SX
    """The motor's limits at the samples (``press.dynamics``): the peak-torque envelope (peak torque up to
    the base speed, constant power above it, as one row) and the RMS torque over the cycle by the
    trapezoidal rule over the samples. The forming force enters at the draw's samples, the last
    FORMING_SAMPLES. Returns the trapezoidal ``(heat, supply energy)`` of the objectives: integral T_m^2 dt
    [N^2 m^2 s] and integral (r P + (1 - r) smoothmax(P, 0)) dt [J]."""
    q = {name: p_case[k] for name, k in DRIVE_INDEX.items()}
    start = len(PARAMETERS) + len(DRIVE_PARAMETERS)
    forming = ca.vertcat(ca.DM.zeros(th.shape[0] - FORMING_SAMPLES), p_case[start : start + FORMING_SAMPLES])
    model = DriveModel(
        q["drive_M"], q["drive_J0"], q["drive_F_cb"], q["drive_i"], q["drive_eta"], q["drive_J_m"], (), (), 0.0
    )
    tc = crank_torque(om, al, d1, d2, forming, model)
    tm = motor_torque(tc, al, model)
    # |T_m| max(1, n / n_base) <= peak is the envelope in one row per sample (kink at the base speed)
    speed = motor_speed(om, model)
    above_base = ca.fmax(1.0, speed / q["motor_base_speed"])
    add("motor peak torque", tm * above_base / q["motor_peak"], -1.0, 1.0)
    add("motor RMS torque", _trapezoid(tm**2, times) / (period * q["motor_rms"] ** 2), -np.inf, 1.0)
    # the objectives on a smooth torque: the gear's loss switches sides where T_c changes sign, and a plan
    # that saves heat or energy coasts there (T_c = 0 over stretches), so both kinks are rounded:
    # |x| -> sqrt(x^2 + eps^2)
    up, down = 1 / (model.i * model.eta), model.eta / model.i
    eps_crank = q["power_smoothing"] / (q["motor_base_speed"] * down)  # [N m] at the crank
    through = tc * (up + down) / 2 + ca.sqrt(tc**2 + eps_crank**2) * (up - down) / 2
    smooth_torque = through + model.J_m * model.i * al
    power = smooth_torque * speed
    drawn = (power + ca.sqrt(power**2 + q["power_smoothing"] ** 2)) / 2  # smooth max(P, 0)
    energy = _trapezoid(q["regen"] * power + (1 - q["regen"]) * drawn, times)
    return _trapezoid(smooth_torque**2, times), energy


def _trapezoid(values: ca.SX, times: ca.SX) -> ca.SX:
    """The trapezoidal integral of ``values`` at the sample ``times`` [s]."""
    n = values.shape[0]
    return ca.sum1((times[1:n] - times[0 : n - 1]) * (values[1:n] + values[0 : n - 1]) / 2)


def _build(law_name: str, drive: bool = False, rate: bool = False) -> CycleNLP:
    law = get_law(law_name)
    x = ca.SX.sym("x", len(VARIABLES))
    drive = drive or rate
    p_case = ca.SX.sym("p", len(PARAMETERS) + (len(DRIVE_PARAMETERS) + FORMING_SAMPLES if drive else 0))
    p_scale = ca.SX.sym("scale", len(VARIABLES))  # physical value = scale * x, chosen per case
    p = ca.vertcat(p_case, p_scale)
    v = {name: x[i] * p_scale[i] for i, (name, _) in enumerate(VARIABLES)}
    unit = {name: p_scale[i] for i, (name, _) in enumerate(VARIABLES)}
    q = {name: p_case[i] for i, name in enumerate(PARAMETERS)}

    fields = [f for f in CycleParameters.__dataclass_fields__ if f in v]
    params = CycleParameters(
        **{f: v[f] for f in fields}, draw_start=q["theta2"], draw_end=q["theta3"], motion_law=law_name
    )
    segs = cycle_segments(params)
    states = knot_states(q["theta3"], params.draw_speed, 0.0, segs)
    starts = [0.0]
    for seg in segs[:-1]:
        starts.append(starts[-1] + seg.duration)
    n_before = len(segs) - 1  # the segments from theta3 to theta2 (all but the draw)
    before = (starts[:n_before], states[:n_before], segs[:n_before])

    rows = Rows()
    add = rows.add

    w1, w2 = params.transfer_speed, params.draw_speed
    wm1, wm2 = params.feed_peak_speed, params.return_peak_speed
    # the peaks lie above the speeds they join (each half is then monotone: the crank speed is
    # smallest at w1 or w2, which the variable bounds keep above the minimum)
    add(
        "peak speeds above their ends",
        ca.vertcat(wm1 - w1, wm1 - w2, wm2 - w2, wm2 - w1) / unit["draw_speed"],
        0,
        np.inf,
    )
    if law.one_jerk_per_curve:  # Eq. 14: one jerk J for both halves of each S-curve
        d_fa, d_fd = params.feed_accel_duration, params.feed_decel_duration
        d_ra, d_rd = params.return_accel_duration, params.return_decel_duration
        t2 = unit["feed_accel_duration"] ** 2 * unit["draw_speed"]
        add(
            "one jerk per S-curve (Eq. 14)",
            ca.vertcat((wm1 - w1) * d_fd**2 - (wm1 - w2) * d_fa**2, (wm2 - w2) * d_rd**2 - (wm2 - w1) * d_ra**2) / t2,
            0.0,
            0.0,
        )
    # the cycle closes: theta at the draw start is theta2 + 2 pi
    add("cycle closes", states[n_before][0] - (q["theta2"] + 2 * np.pi), 0.0, 0.0)

    t4, t1 = v["opening_time"], v["closing_time"]
    th4, _ = _angle_at(t4, *before)
    th1, _ = _angle_at(t1, *before)
    add("key angles", ca.vertcat(th4 - q["theta4"], th1 - (q["theta1"] + 2 * np.pi)), 0.0, 0.0)
    add("transfer time", t1 - t4 - q["transfer_time"], 0.0, np.inf)
    t_end = starts[n_before]
    add(
        "key points in order",
        ca.vertcat(t4, t1 - t4, t_end - t1, t_end - v["die_down_time"], t_end - v["die_up_time"]),
        0.0,
        np.inf,
    )
    # published structure (Fig. 6): theta4 at x3 + 3 T14 (three quarters into the return deceleration),
    # theta1 at x1 + T1 (a quarter into the feed acceleration); bounds switched per solve
    rd_start = params.return_accel_duration
    fa_start = rd_start + params.return_decel_duration + params.transfer_dwell
    published_rows = add(
        "key angles (published placement)",
        ca.vertcat(
            t4 - (rd_start + 0.75 * params.return_decel_duration),
            t1 - (fa_start + 0.25 * params.feed_accel_duration),
        ),
        -np.inf,
        np.inf,
    )

    # die-height crossings outside the draw
    thd, omd = _angle_at(v["die_down_time"], *before)
    thu, omu = _angle_at(v["die_up_time"], *before)
    add(
        "die crossing angles",
        ca.vertcat(
            q["die_down_active"] * (thd - (q["die_down_angle"] + 2 * np.pi)),
            q["die_up_active"] * (thu - q["die_up_angle"]),
        ),
        0.0,
        0.0,
    )
    add(
        "die-height speed",
        ca.vertcat(q["die_down_slope"] * omd, q["die_up_slope"] * omu) / q["die_speed"],
        -np.inf,
        1.0,
    )

    # slider acceleration at sample points of every segment, one vector per segment
    th_s, om_s, al_s, t_s = [], [], [], []
    for seg, st, t0 in zip(segs, states[:-1], starts, strict=True):
        constant = seg.name in ("transfer:dwell", "draw:constant")
        count = SAMPLES_CONSTANT if constant else law.samples
        if drive and seg.name == "draw:constant":
            count = DRAW_SAMPLES_DRIVE
        fractions = np.linspace(0.0, 1.0, count + 1)
        if seg.name != "draw:constant":
            fractions = fractions[:-1]  # the end is the next segment's start
        if drive and seg.name == "draw:constant":  # sparse rows (see the module docstring)
            th, om, al, since = draw_states(q, w2, ca.DM(fractions))
            t_s.append(t0 + since)
        else:
            th, om, al, _ = advance_segment(seg, *st, ca.DM(fractions) * seg.duration)
            t_s.append(t0 + ca.DM(fractions) * seg.duration)
        th_s.append(th)
        om_s.append(om)
        al_s.append(al)
    th, om, al = ca.vertcat(*th_s), ca.vertcat(*om_s), ca.vertcat(*al_s)
    d1, d2, _ = height_derivatives(th, q["R"], q["L"])
    acc = d2 * om**2 + d1 * al
    add("slider acceleration", acc / q["accel_limit"], -1.0, 1.0)
    # motor limits: the halves are monotone in speed; their peak acceleration and jerk in closed form
    add("crank speed limit", ca.vertcat(wm1, wm2, w1, w2) / q["crank_speed_max"], -np.inf, 1.0)
    add("crank acceleration limit", ca.vertcat(*params.peak_accelerations()) / q["crank_accel_max"], -np.inf, 1.0)
    add("crank jerk limit", ca.vertcat(*params.peak_jerks()) / q["crank_jerk_max"], -np.inf, 1.0)
    objective = params.period
    period_rows = die_zone_rows = None
    if drive and not rate:
        _drive_constraints(add, p_case, th, om, al, d1, d2, ca.vertcat(*t_s), params.period)
    elif rate:
        # at a target rate a plan may peak in speed inside the die zone, between the crossings: below the die
        # height every sample keeps the die speed (max(h - h_die, v_die - |v|) >= 0, continuous; the draw's
        # constant speed is bounded already). The samples of the draw are the last FORMING_SAMPLES.
        outside = slice(0, th.shape[0] - FORMING_SAMPLES)
        h_s = height(th[outside], q["R"], q["L"])
        v_s = d1[outside] * om[outside]
        zone = ca.fmax((h_s - q["die_height"]) / q["R"], (q["die_speed"] - ca.fabs(v_s)) / q["die_speed"])
        die_zone_rows = add("die-zone speed", zone, 0.0, np.inf)
        heat, energy = _drive_constraints(add, p_case, th, om, al, d1, d2, ca.vertcat(*t_s), params.period)
        w = {name: p_case[DRIVE_INDEX[name]] for name in ("weight_period", "weight_heat", "weight_energy")}
        objective = w["weight_period"] * params.period + w["weight_heat"] * heat + w["weight_energy"] * energy
        objective -= p_case[DRIVE_INDEX["weight_dwell"]] * params.transfer_dwell
        period_rows = add("cycle time", params.period - p_case[DRIVE_INDEX["target_period"]], -np.inf, np.inf)

    nlp = {"x": x, "p": p, "f": objective, "g": ca.vertcat(*rows.g)}
    kind = "_rate" if rate else "_drive" if drive else ""
    options = {**CYCLE_OPTIONS, **(DRIVE_OPTIONS if drive else {}), **(RATE_OPTIONS if rate else {})}
    program = NLPSolver("press_cycle_" + law_name.replace("-", "_") + kind, nlp, options)
    return CycleNLP(program, *rows.bounds(), tuple(rows.blocks), published_rows, period_rows, die_zone_rows)


@cache
def cycle_nlp(law: str = DEFAULT_LAW, drive: bool = False, rate: bool = False) -> CycleNLP:
    """The compiled NLP of motion law ``law``, with the motor's limits when ``drive``; ``rate``: the drive
    NLP of a target rate (the objectives' terms, the "cycle time" row, the die-zone rows; see
    ``planning.solver.objectives``). Built on first use in a process, then reused for every case and start."""
    return _build(law, drive, rate)
