"""The time-optimal bound on a mesh: the shortest cycle of a crank motion with constant acceleration on
each interval of a grid over crank angle, under the case's limits. It approaches the true optimum from
below as the grid refines (a restriction of the motions, not an upper bound: ``planning.solver.upper_bound``
gives the certified one).

No motion law: the crank speed is free except for the limits (acceleration-limited; the acceleration
may jump). Direct transcription over crank angle in the phase plane: on a grid theta_0 < ... <
theta_N = theta_0 + 2 pi (the key angles are nodes) the variable is ``s_i = omega_i^2`` [rad^2/s^2].
With s linear between nodes the crank acceleration is constant on each interval,
``alpha = (s_{i+1} - s_i) / (2 dtheta)``, and the interval takes ``2 dtheta / (sqrt(s_i) + sqrt(s_{i+1}))``.

    minimise   sum tau_i
    subject to tau_i >= 2 dtheta_i / (sqrt(s_i) + sqrt(s_{i+1}))       (convex)
               |d2h/dtheta2 s + dh/dtheta alpha_i| <= A  at both ends of interval i   (linear in s)
               s = w2^2 on the draw (w2 given, or one free value within its bounds)
               s <= (v_die / |dh/dtheta|)^2 where the slider is at or below the die height
               s >= w_min^2;   sum of tau over theta4 -> theta1 >= transfer time   (linear)

Each limit of the case states its own part (``planning.model.limits``: ``bound_speeds``, ``bound_rows``);
the RMS torque takes none (it is not a limit at a crank angle). Every constraint set is convex and the
objective linear, so IPOPT's optimum is the global one: a local solution cannot be mistaken for the
bound. Where ``tau_i`` exceeds the interval's time (only
useful inside the robot window), the window's time is relaxed (``window_slack_s`` reports how much was
used); the constant acceleration per interval and the slider's limit at the interval's ends restrict the
motions, so the number is not certified to bound every motion (on the published case 13.038 at 1440
intervals, where a motion meeting every limit makes 13.0405). The drive's speed and
acceleration limits enter as bounds on s and alpha. A crank-jerk limit J enters between neighbouring
intervals as ``|alpha_{i+1} - alpha_i| <= J (tau_i + tau_{i+1}) / 2`` (``planning.model.limits.crank_jerk``).
With a hold at the bottom (``process.hold_time_s``) the crank stops at the hold's angle for the hold time:
the bound leaves the least crank speed out (the crank stops in a hold, the plan decides where its stop
begins and ends) and adds the hold's time to the fastest motion's (any plan with the hold, its standstill
cut out, is a motion the bound's problem admits). Without a crank
acceleration limit the slack can be realised: near TDC dh/dtheta -> 0, so the slider does not feel the
crank's acceleration there and the crank may slow almost to a stop at no cost in slider acceleration.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from planning.model.case import RPM, Case
from planning.model.limits import limits_of
from planning.model.limits.base import BoundMesh
from planning.solver.ipopt import NLPSolver
from planning.solver.outcomes import Infeasible, NoPlanFound
from planning.solver.precheck import precheck
from planning.tolerances import SAME_ANGLE_RAD, SAME_NODE_RAD

DEFAULT_POINTS = 1440
BOUND_OPTIONS = {"ipopt.max_iter": 3000}  # added to the wrapper's base options


@dataclass(frozen=True)
class Bound:
    """The bound: ``spm``, ``cycle_time_s`` [s], ``points`` of the mesh, ``window_slack_s`` [s] (time the
    relaxation adds in the robot window beyond the motion's own), ``draw_speed_rpm``, the speed
    profile ``angle_deg`` / ``crank_speed_rpm`` at the nodes, ``wall_time_s`` [s]."""

    spm: float
    cycle_time_s: float
    points: int
    window_slack_s: float
    draw_speed_rpm: float
    angle_deg: np.ndarray
    crank_speed_rpm: np.ndarray
    wall_time_s: float
    crank_jerk_limit_rad_s3: float | None = None

    def as_dict(self) -> dict:
        return {
            "spm": self.spm,
            "cycle_time_s": self.cycle_time_s,
            "points": self.points,
            "window_slack_s": self.window_slack_s,
            "draw_speed_rpm": self.draw_speed_rpm if math.isfinite(self.draw_speed_rpm) else None,  # a free draw
            "peak_crank_speed_rpm": float(np.max(self.crank_speed_rpm)),
            "wall_time_s": self.wall_time_s,
            "crank_jerk_limit_rad_s3": self.crank_jerk_limit_rad_s3,
            "method": "phase-plane direct transcription over crank angle, convex (the grid's global optimum: "
            "constant crank acceleration per interval, a restriction that approaches the optimum from below; "
            "the certified upper bound: --certified)",
        }


def angle_mesh(case: Case, points: int, extra: tuple[float, ...] = ()) -> np.ndarray:
    """Nodes [rad] from theta1 over one revolution, ``points`` intervals in all (more only when ``points`` is
    below :data:`MIN_INTERVALS_PER_ARC` per arc). Among them: the key angles,
    TDC, and the angles where the slide passes the die height, so that the die-height speed limit holds
    exactly where it starts and ends (between nodes it would be missed); and the ``extra`` angles [rad]."""
    th1, th2, th3, th4 = case.key_angles
    two_pi = 2 * math.pi
    breaks = {th2, th3, th4, two_pi, *(a % two_pi for a in extra)}
    die = case.limits.die_height_mm
    if 0 < die < case.machine.stroke:
        breaks |= {float(a) for a in case.machine.angles_at_height(die)}
    inside = sorted(a + two_pi if a <= th1 else a for a in breaks)
    inside = [a for a in inside if th1 + SAME_NODE_RAD < a < th1 + two_pi - SAME_NODE_RAD]
    arcs = [th1, *sorted(set(inside)), th1 + two_pi]
    spans = np.diff(arcs)
    nodes = [np.array([th1])]
    for a, b, n in zip(arcs[:-1], arcs[1:], _apportion(points, spans / two_pi), strict=True):
        nodes.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(nodes)


MIN_INTERVALS_PER_ARC = 4  # between neighbouring breaks (key angles, TDC, die-height crossings)


def _apportion(points: int, shares: np.ndarray) -> list[int]:
    """``points`` intervals shared among arcs in proportion to ``shares`` (summing to 1), each at least
    :data:`MIN_INTERVALS_PER_ARC`, by the largest remainders: exactly ``points`` in all unless the minimum
    per arc needs more."""
    ideal = points * shares
    counts = np.maximum(MIN_INTERVALS_PER_ARC, np.floor(ideal)).astype(int)
    spare = points - int(counts.sum())
    if spare > 0:
        order = np.argsort(-(ideal - np.floor(ideal)), kind="stable")
        counts[order[:spare]] += 1  # spare < len(shares): each floor lost less than one interval
    elif spare < 0:  # the minimum per arc took more: give it back from the largest arcs
        for k in np.argsort(-counts, kind="stable"):
            give = min(-spare, counts[k] - MIN_INTERVALS_PER_ARC)
            counts[k] -= give
            spare += give
            if spare == 0:
                break
    return counts.tolist()


def time_optimal_bound(case: Case, points: int = DEFAULT_POINTS) -> Bound:
    """The bound for ``case`` on a grid of about ``points`` intervals; raises a
    :class:`~planning.solver.outcomes.PlanningError` if there is none."""
    t_start = time.perf_counter()
    w2_lo, w2_hi = precheck(case)
    th = angle_mesh(case, points)
    n = len(th) - 1  # intervals; node n is node 0 one revolution on
    dth = np.diff(th)
    m = case.machine
    h, d1, d2, _ = m.jets(th)
    lim = case.limits
    th1, th2, th3, th4 = case.key_angles
    limits = limits_of(case)

    draw = draw_nodes(case, th)
    window = th[:-1] >= th4 - SAME_ANGLE_RAD  # the grid starts at theta1: the robot window is [theta4, theta1 + 2 pi)
    mesh = BoundMesh(case, th, h, d1, d2, dth, window)
    lbx_s, ubx_s = node_speed_bounds(mesh, limits, draw, w2_lo, w2_hi)
    # scales: each node's speed^2 near the speed the slider-acceleration limit allows at constant speed,
    # within the node's bounds; each interval's time accordingly. A draw at 0.001 rpm and a stroke at
    # 30 rpm then both solve with variables of order one.
    w_acc2 = lim.slider_accel_mm_s2 / m.peak_curvature
    s_unit = np.clip(np.full(n, w_acc2), lbx_s, ubx_s)
    tau_unit = dth / np.sqrt(s_unit)
    x_s = ca.MX.sym("s", n)  # scaled speed^2 at nodes 0..n-1; node n is node 0
    x_tau = ca.MX.sym("tau", n)
    mesh.s = ca.DM(s_unit) * x_s
    mesh.tau = ca.DM(tau_unit) * x_tau
    mesh.s_next = ca.vertcat(mesh.s[1:], mesh.s[0])
    mesh.tau_next = ca.vertcat(mesh.tau[1:], mesh.tau[0])
    mesh.alpha = (mesh.s_next - mesh.s) / (2 * dth)
    g = [mesh.tau - 2 * dth / (ca.sqrt(mesh.s) + ca.sqrt(mesh.s_next))]  # each interval's time (convex)
    lbg, ubg = [np.zeros(n)], [np.full(n, np.inf)]
    for limit in limits:
        for expr, lo, hi in limit.bound_rows(mesh):
            g.append(expr)
            lbg.append(np.broadcast_to(lo, (expr.shape[0],)))
            ubg.append(np.broadcast_to(hi, (expr.shape[0],)))
    if draw.size > 1:  # one speed through the draw
        g.append(mesh.s[draw[1:].tolist()] - mesh.s[draw[:-1].tolist()])
        lbg.append(np.zeros(draw.size - 1))
        ubg.append(np.zeros(draw.size - 1))
    nlp = {"x": ca.vertcat(x_s, x_tau), "f": ca.sum1(mesh.tau), "g": ca.vertcat(*g)}
    solver = NLPSolver("bound", nlp, BOUND_OPTIONS, fixed_scale=np.concatenate([s_unit, tau_unit]))
    s0 = s_unit  # the scales: speeds the slider-acceleration limit allows, within every bound
    x0 = np.concatenate([s0, 2 * dth / (2 * np.sqrt(s0))])
    lbx = np.concatenate([lbx_s, np.zeros(n)])
    ubx = np.concatenate([ubx_s, np.full(n, np.inf)])
    # the optimum as IPOPT returns it: the grid's speeds are read with max(s, 0) below
    res = solver.solve(x0, lbx, ubx, np.concatenate(lbg), np.concatenate(ubg), clip_to_bounds=False)
    if not res.success:
        raise NoPlanFound(f"the time-optimal bound did not converge ({res.return_status})")
    xs = res.x
    s_opt, tau_opt = np.maximum(xs[:n], 0.0), xs[n:]
    s_next_opt = np.roll(s_opt, -1)
    motion = 2 * dth / (np.sqrt(s_opt) + np.sqrt(s_next_opt))
    period = float(np.sum(tau_opt)) + case.standstill_s  # a hold: the fastest motion, then the standstill
    return Bound(
        spm=60.0 / period,
        cycle_time_s=period,
        points=n,
        window_slack_s=float(np.sum(tau_opt - motion)),
        draw_speed_rpm=float(np.sqrt(s_opt[draw[0]]) / RPM) if draw.size else math.nan,
        angle_deg=np.degrees(th[:-1]) % 360.0,
        crank_speed_rpm=np.sqrt(s_opt) / RPM,
        wall_time_s=time.perf_counter() - t_start,
        crank_jerk_limit_rad_s3=lim.crank_jerk_rad_s3,
    )


def draw_nodes(case: Case, theta: np.ndarray) -> np.ndarray:
    """The nodes of the grid ``theta`` [rad] in the draw at one constant speed, theta2 ... theta3; none for a
    draw at constant slide speed (its speed free, under the slide's cap: ``planning.model.limits.
    draw_slide_speed``)."""
    _, th2, th3, _ = case.key_angles
    nodes = np.flatnonzero((theta[:-1] >= th2 - SAME_ANGLE_RAD) & (theta[:-1] <= th3 + SAME_ANGLE_RAD))
    return nodes[:0] if case.free_draw else nodes


def node_speed_bounds(
    mesh: BoundMesh, limits: tuple, draw: np.ndarray, w2_lo: float, w2_hi: float
) -> tuple[np.ndarray, np.ndarray]:
    """The bounds on the speed squared at the nodes: every limit's, the draw's range on the draw's nodes.
    :class:`Infeasible` naming the limit that leaves no speed at some node."""
    n = mesh.dtheta.size
    lower, upper = np.zeros(n), np.full(n, np.inf)
    uppers = []
    for limit in limits:
        lo, up = limit.bound_speeds(mesh)
        if lo is not None:
            lower = np.maximum(lower, lo)
        if up is not None:
            upper = np.minimum(upper, up)
            uppers.append((limit, up))
    lower[draw] = np.maximum(lower[draw], w2_lo**2)
    upper[draw] = np.minimum(upper[draw], w2_hi**2)
    empty = np.flatnonzero(upper < lower)
    if empty.size:
        k = int(empty[0])
        limit = next((lim for lim, up in uppers if up[k] < lower[k]), None)
        field = limit.field if limit is not None else "limits.min_crank_speed_rpm"
        raise Infeasible(
            f"{field} leaves no crank speed above the minimum at {math.degrees(mesh.theta[k]) % 360:.1f} deg",
            limit=field,
        )
    return lower, upper
