"""The CasADi nonlinear program of one improved-S-curve press cycle (all CasADi lives here).

Built once per process and reused: every number of a case, and the scale of every decision variable,
enters as a parameter and the placement
structure is a pair of constraint rows whose bounds are set per solve, so a sweep, a multi-start or
the other placement only calls the compiled solver again. Decision variables are scaled to O(1).

Time 0 of the NLP is the end of the draw (theta3); the stages follow as in ``planning.cycle``. The
crank angle at any time t before the draw is evaluated in closed form as
``theta(t) = theta3 + sum_k D_k(clip(t - s_k, 0, T_k))``, with ``D_k`` the angle swept ``tau`` into
segment k. The clip makes theta(t) continuously differentiable in t and in every segment variable
(the kink of one term is cancelled by the next), so a key point may move across knots inside one
smooth NLP: that is the ``free`` placement. The ``published`` placement fixes the key points where
the relations under the paper's Fig. 6 put them: t1 = x1 + T1 (one sub-segment into the feed
acceleration), t4 = x3 + 3 T14 (three sub-segments into the return deceleration).

Constraints: speed continuity of both S-curves (Eq. 19), the cycle closes at 2 pi, the key angles
theta1 and theta4 are met, time(theta4 -> theta1) >= transfer time, |slider acceleration| <= limit at
sample points of every segment (the orchestrator lowers that sampled limit until the dense
verification holds between samples), slider speed at the die-height crossings outside the draw, draw
speed within its bounds, crank speed >= the minimum crank speed (the S-curve halves are monotone for
J >= 0), and the drive's limits: peak speeds, peak accelerations 3/2 J T, jerks J.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache
from typing import Literal

import casadi as ca
import numpy as np

from planning.cycle import CycleParameters, cycle_segments
from planning.laws import improved_scurve as sc
from planning.profile import advance, knot_states
from press.kinematics import height_derivatives

Placement = Literal["free", "published"]

# Decision variables: name, default scale (physical = scale * scaled; the scales are NLP parameters
# set per case from the magnitude of its first initial guess, this default where that is zero)
VARIABLES: tuple[tuple[str, float], ...] = (
    ("transfer_speed", 1.0),  # w1 [rad/s]
    ("draw_speed", 1.0),  # w2 [rad/s]
    ("feed_jerk", 30.0),  # J_f [rad/s^3]
    ("feed_accel_time", 0.1),  # [s]
    ("feed_decel_time", 0.1),
    ("return_jerk", 30.0),
    ("return_accel_time", 0.1),
    ("return_decel_time", 0.1),
    ("transfer_dwell", 1.0),  # [s]
    ("closing_time", 1.0),  # t1 from the end of the draw [s]
    ("opening_time", 1.0),  # t4
    ("die_down_time", 1.0),  # time of the descending die-height crossing
    ("die_up_time", 1.0),  # time of the ascending die-height crossing
)
VARIABLE_INDEX = {name: i for i, (name, _) in enumerate(VARIABLES)}
SCALES = np.array([s for _, s in VARIABLES])

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
)
PARAMETER_INDEX = {name: i for i, name in enumerate(PARAMETERS)}

IPOPT_OPTIONS = {
    "ipopt.print_level": 0,
    "print_time": False,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-10,
    "ipopt.constr_viol_tol": 1e-10,
    "ipopt.max_iter": 400,  # a start that has not converged by then is dropped (others remain)
}
WARM_OPTIONS = {
    "ipopt.warm_start_init_point": "yes",
    "ipopt.mu_init": 1e-6,
    "ipopt.warm_start_bound_push": 1e-9,
    "ipopt.warm_start_mult_bound_push": 1e-9,
    "ipopt.warm_start_slack_bound_push": 1e-9,
}
SAMPLES_PER_SUBSEGMENT = 5
SAMPLES_CONSTANT = 20


@dataclass(frozen=True)
class ConstraintBlock:
    """Name and row range of a group of NLP constraints (for reading multipliers and violations)."""

    name: str
    start: int
    stop: int


def _angle_at(t: ca.SX, starts: ca.SX, segs: dict[str, ca.SX]) -> tuple[ca.SX, ca.SX]:
    """Closed-form crank angle and speed at time ``t`` [s] over the segments (clip formulation)."""
    tau = ca.fmin(ca.fmax(t - starts, 0), segs["T"])
    th, om, _, _ = advance(0.0, segs["omega"], segs["alpha"], segs["j0"], segs["j1"], tau)
    return segs["theta0"] + ca.sum1(th), segs["omega0"] + ca.sum1(om - segs["omega"])


@dataclass
class CycleNLP:
    """The compiled NLP; see the module docstring. ``free_rows`` hold theta1 and theta4 anywhere
    (clip formulation), ``published_rows`` pin them to the knots of the published structure; the
    rows of the other placement are left unbounded."""

    solver: ca.Function
    lbg: np.ndarray
    ubg: np.ndarray
    blocks: tuple[ConstraintBlock, ...]
    free_rows: slice
    published_rows: slice
    problem: dict = field(repr=False, default_factory=dict)
    options: dict = field(repr=False, default_factory=dict)
    _warm: ca.Function | None = field(repr=False, default=None)

    def warm_solver(self) -> ca.Function:
        """The same NLP with IPOPT set up for a warm start from a nearby solution and its multipliers
        (built on first use): re-solves after a small change of a parameter take a few iterations."""
        if self._warm is None:
            opts = dict(self.options)
            opts.update(WARM_OPTIONS)
            self._warm = ca.nlpsol("press_cycle_warm", "ipopt", self.problem, opts)
        return self._warm

    def bounds(self, placement: Placement) -> tuple[np.ndarray, np.ndarray]:
        """``(lbg, ubg)`` for ``placement``."""
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        off = self.free_rows if placement == "published" else self.published_rows
        on = self.published_rows if placement == "published" else self.free_rows
        lbg[off], ubg[off] = -np.inf, np.inf
        lbg[on], ubg[on] = 0.0, 0.0
        return lbg, ubg


def _build() -> CycleNLP:
    x = ca.SX.sym("x", len(VARIABLES))
    p_case = ca.SX.sym("p", len(PARAMETERS))
    p_scale = ca.SX.sym("scale", len(VARIABLES))  # physical value = scale * x, chosen per case
    p = ca.vertcat(p_case, p_scale)
    v = {name: x[i] * p_scale[i] for i, (name, _) in enumerate(VARIABLES)}
    q = {name: p_case[i] for i, name in enumerate(PARAMETERS)}

    params = CycleParameters(
        transfer_speed=v["transfer_speed"],
        draw_speed=v["draw_speed"],
        feed_jerk=v["feed_jerk"],
        feed_accel_time=v["feed_accel_time"],
        feed_decel_time=v["feed_decel_time"],
        return_jerk=v["return_jerk"],
        return_accel_time=v["return_accel_time"],
        return_decel_time=v["return_decel_time"],
        transfer_dwell=v["transfer_dwell"],
        draw_start=q["theta2"],
        draw_end=q["theta3"],
    )
    segs = cycle_segments(params)
    states = knot_states(q["theta3"], params.draw_speed, 0.0, segs)
    durations = [s.duration for s in segs]
    starts = [0.0]
    for T in durations[:-1]:
        starts.append(starts[-1] + T)
    n_before = len(segs) - 1  # the 17 segments from theta3 to theta2 (all but the draw)
    before = {
        "T": ca.vertcat(*durations[:n_before]),
        "omega": ca.vertcat(*[st[1] for st in states[:n_before]]),
        "alpha": ca.vertcat(*[st[2] for st in states[:n_before]]),
        "j0": ca.vertcat(*[s.j0 for s in segs[:n_before]]),
        "j1": ca.vertcat(*[s.j1 for s in segs[:n_before]]),
        "theta0": states[0][0],
        "omega0": states[0][1],
    }
    start_vec = ca.vertcat(*starts[:n_before])

    blocks: list[ConstraintBlock] = []
    g: list = []
    lb: list = []
    ub: list = []

    def add(name: str, expr: ca.SX, lo, hi) -> slice:
        expr = ca.vec(expr)
        n = expr.shape[0]
        blocks.append(ConstraintBlock(name, len(lb), len(lb) + n))
        g.append(expr)
        lb.extend(np.broadcast_to(lo, (n,)).tolist())
        ub.extend(np.broadcast_to(hi, (n,)).tolist())
        return slice(len(lb) - n, len(lb))

    w1, w2 = params.transfer_speed, params.draw_speed
    # Eq. 19 for each S-curve: the speeds meet
    add(
        "feed speed continuity",
        w1
        + sc.speed_change(params.feed_jerk, params.feed_accel_time)
        - sc.speed_change(params.feed_jerk, params.feed_decel_time)
        - w2,
        0.0,
        0.0,
    )
    add(
        "return speed continuity",
        w2
        + sc.speed_change(params.return_jerk, params.return_accel_time)
        - sc.speed_change(params.return_jerk, params.return_decel_time)
        - w1,
        0.0,
        0.0,
    )
    # the cycle closes: theta at the draw start is theta2 + 2 pi
    add("cycle closes", states[n_before][0] - (q["theta2"] + 2 * np.pi), 0.0, 0.0)

    n = sc.SUBSEGMENTS
    t4, t1 = v["opening_time"], v["closing_time"]
    th4, _ = _angle_at(t4, start_vec, before)
    th1, _ = _angle_at(t1, start_vec, before)
    free_rows = add(
        "key angles (free placement)",
        ca.vertcat(th4 - q["theta4"], th1 - (q["theta1"] + 2 * np.pi)),
        0.0,
        0.0,
    )
    add("transfer time", t1 - t4 - q["transfer_time"], 0.0, np.inf)
    t_end = starts[n_before]
    add(
        "key points in order",
        ca.vertcat(t4, t1 - t4, t_end - t1, t_end - v["die_down_time"], t_end - v["die_up_time"]),
        0.0,
        np.inf,
    )
    # published structure (Fig. 6): theta4 at x3 + 3 T14, theta1 at x1 + T1, i.e. at two knots, so the
    # key angles are smooth knot states; bounds switched per solve
    k4, k1 = n + 3, 2 * n + 2  # knots: end of the 3rd return-decel / 1st feed-accel sub-segment
    published_rows = add(
        "key angles (published placement)",
        ca.vertcat(
            t4 - starts[k4],
            t1 - starts[k1],
            states[k4][0] - q["theta4"],
            states[k1][0] - (q["theta1"] + 2 * np.pi),
        ),
        -np.inf,
        np.inf,
    )

    # die-height crossings outside the draw
    thd, omd = _angle_at(v["die_down_time"], start_vec, before)
    thu, omu = _angle_at(v["die_up_time"], start_vec, before)
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

    # slider acceleration at sample points of every segment, evaluated as one vector
    cols: dict[str, list] = {k: [] for k in ("theta", "omega", "alpha", "j0", "j1", "tau")}
    for seg, st in zip(segs, states[:-1], strict=True):
        constant = seg.name in ("transfer:dwell", "draw:constant")
        fractions = np.linspace(0.0, 1.0, (SAMPLES_CONSTANT if constant else SAMPLES_PER_SUBSEGMENT) + 1)
        if seg.name != "draw:constant":
            fractions = fractions[:-1]  # the end is the next segment's start
        for f in fractions:
            for key, val in zip(("theta", "omega", "alpha", "j0", "j1"), (*st, seg.j0, seg.j1), strict=True):
                cols[key].append(val)
            cols["tau"].append(f * seg.duration)
    th, om, al, _ = advance(*(ca.vertcat(*cols[k]) for k in ("theta", "omega", "alpha", "j0", "j1", "tau")))
    d1, d2, _ = height_derivatives(th, q["R"], q["L"])
    acc = d2 * om**2 + d1 * al
    add("slider acceleration", acc / q["accel_limit"], -1.0, 1.0)
    # motor limits: the S-curve halves are monotone in speed, their accelerations peak at 3/2 J T (Eqs. 17,
    # 21) and their jerk never exceeds J (Eq. 10)
    peaks = ca.vertcat(params.feed_peak_speed, params.return_peak_speed, w1, w2)
    add("crank speed limit", peaks / q["crank_speed_max"], -np.inf, 1.0)
    halves = ca.vertcat(
        sc.peak_accel(params.feed_jerk, params.feed_accel_time),
        sc.peak_accel(params.feed_jerk, params.feed_decel_time),
        sc.peak_accel(params.return_jerk, params.return_accel_time),
        sc.peak_accel(params.return_jerk, params.return_decel_time),
    )
    add("crank acceleration limit", halves / q["crank_accel_max"], -np.inf, 1.0)
    add("crank jerk limit", ca.vertcat(params.feed_jerk, params.return_jerk) / q["crank_jerk_max"], -np.inf, 1.0)

    nlp = {"x": x, "p": p, "f": params.period, "g": ca.vertcat(*g)}
    solver = ca.nlpsol("press_cycle", "ipopt", nlp, IPOPT_OPTIONS)
    return CycleNLP(solver, np.array(lb), np.array(ub), tuple(blocks), free_rows, published_rows, nlp, IPOPT_OPTIONS)


@cache
def cycle_nlp() -> CycleNLP:
    """The compiled NLP (built on first use in a process, then reused for every case and start)."""
    return _build()
