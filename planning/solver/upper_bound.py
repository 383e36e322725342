"""The certified upper bound: strokes/min that no crank motion meeting the case's limits can exceed.

The grid bound (``planning.solver.bound``) restricts the motion (constant crank acceleration on each
interval, the slider's limit at the interval's ends): it approaches the true optimum from below and is
not an upper bound. Here the same question is relaxed instead: every motion that meets the limits also
meets the relaxed problem, so the relaxed optimum is an upper bound on its strokes/min. With a hold at the
bottom the least crank speed is left out and the hold's time added (a plan with the hold, its standstill cut
out, meets the relaxed problem; ``planning.solver.bound``).

Variables: ``s_i`` [rad^2/s^2] the crank speed squared at the nodes (any motion's own values there) and
``tau_p`` [s] the time spent on each piece of each interval (pieces cut each interval; any motion's own
times satisfy every row below, so it is a feasible point). Rows, each true for every motion that meets
the limits (the limits state their own, ``Limit.relaxed_rows`` / ``relaxed_caps`` /
``relaxed_envelopes``):

- at the nodes, every limit's bound on the speed (a condition at an angle holds at the node's angle);
- the slide's kinematics, exact for any motion: with ``v = h' omega``, ``d(v^2)/dtheta = 2 h' a``, so
  where h is monotone (the dead centres are nodes) ``|h'_(i+1)^2 s_(i+1) - h'_i^2 s_i| <= 2 A |h_(i+1) -
  h_i|`` (A the slider-acceleration limit), and ``|h'' s| <= A`` at a dead centre;
- the draw at one speed: ``s`` equal on the draw's nodes, within the draw-speed range;
- the mean crank acceleration of an interval (``(s_(i+1) - s_i) / (2 dtheta)``) within the crank's
  acceleration limit; the means of intervals i and i + m - 1 differ by at most J times the m intervals'
  time, m = 2 and 4 (crank jerk J; ``CrankJerkLimit.relaxed_rows``);
- the robot's window: the times of its intervals add up to at least the transfer time;
- each piece's time from the mean of the crank speed squared over it (Jensen: ``1/sqrt`` is convex, so
  ``tau_p = integral dtheta / sqrt(s) >= (b - a) / sqrt(mean s)``), the mean bounded above by the mean of
  an envelope E of ``s`` over the piece's :data:`SUBPIECES` sub-pieces, each sub-piece at its envelope's
  largest value there: a speed limit's largest value (crank, motor, slider, die speed), ``(h'_i^2 s_i + 2 A
  |h(b) - h_i|) / min h'^2`` and its mirror from the interval's end (the slide cannot gain speed faster
  than A allows), ``s_i + 2 A_c (b - theta_i)`` and its mirror (the crank acceleration limit A_c), and
  ``s_i`` on the draw; and, at each of :data:`SPLITS`, an envelope growing from the start over the first
  part of the piece with one from the end over the rest (a motion that speeds up, then slows down). Every
  one of these is a valid row; the tightest binds. On a piece where h' vanishes (the first sliver next to
  a dead centre, :data:`DEAD_CENTRE_SLIVER` of its interval) no envelope holds and its time is bounded by
  0 only. Every interval has h and h'^2 monotone (every zero of h' -- TDC, BDC and a linkage's other
  dips -- and every inflection point of h is a node), so the least h'^2 of a sub-piece is at one of its
  ends. On an arc where a limit is active the envelope follows the motion to O(sub-piece) and Jensen's
  inequality costs O(piece^2): without a jerk limit the bound converges from above as the grid refines
  (the jerk rows keep a slack of m / (m - 1) on a jerk ramp at any mesh).

``1 / sqrt`` of an affine function is convex, so the relaxed problem is convex and IPOPT's optimum is its
global one; the upper bound is ``60 / (sum tau)`` at that optimum, up to IPOPT's tolerance (1e-10; only
its status Solve_Succeeded is taken). A
limit with no relaxed form (the motor's peak torque, the RMS torque) is left out (named in the answer):
the number stays an upper bound, looser. The relaxation tightens as the grid refines (:func:`upper_bound`'s
``points`` and ``pieces``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from planning.model.case import RPM, Case
from planning.model.limits import limits_of
from planning.model.limits.base import BoundMesh, Envelope, RelaxedMesh
from planning.solver.bound import BOUND_OPTIONS, angle_mesh, draw_nodes, node_speed_bounds
from planning.solver.ipopt import NLPSolver
from planning.solver.outcomes import NoPlanFound
from planning.solver.precheck import precheck
from planning.tolerances import DEAD_CENTRE_SLOPE, SAME_ANGLE_RAD, SAME_NODE_RAD

UPPER_POINTS = 1440  # intervals of the grid by default
UPPER_PIECES = 1  # pieces per interval (a time variable each)
SUBPIECES = 256  # sub-pieces per piece: a piece's mean envelope is the mean of their largest values
SPLITS = (0.5,)  # shares of a piece after which a start-side envelope gives way to an end-side one
SOLVED = "Solve_Succeeded"  # the only IPOPT status whose optimum is taken as the bound
DEAD_CENTRE_SLIVER = 1.0 / 1024  # share of an interval next to a dead centre whose time is bounded by 0 only
INFLECTION_GRID = 7200  # angles on which the sign changes of h' and h'' are looked for


@dataclass(frozen=True)
class UpperBound:
    """The certified upper bound: ``spm`` (no motion meeting the limits makes more), ``cycle_time_s`` [s]
    (no motion's cycle is shorter), ``points`` (intervals) and ``pieces`` (per interval) of the mesh,
    ``left_out`` (limits of the case without a relaxed form: not in the bound, which stays an upper bound),
    ``wall_time_s`` [s]."""

    spm: float
    cycle_time_s: float
    points: int
    pieces: int
    left_out: tuple[str, ...]
    wall_time_s: float

    def as_dict(self) -> dict:
        return {
            "spm": self.spm,
            "cycle_time_s": self.cycle_time_s,
            "points": self.points,
            "pieces": self.pieces,
            "left_out": list(self.left_out),
            "wall_time_s": self.wall_time_s,
            "method": "convex relaxation over crank angle (every motion meeting the limits meets it)",
        }


def slope_zeros(case: Case) -> list[float]:
    """Crank angles [rad] where h' changes sign other than TDC and BDC (a linkage's second dip near BDC, where
    h is not monotone), by bisection on a grid of :data:`INFLECTION_GRID` angles; each becomes a node with a
    dead-centre sliver, so that h is monotone on every interval."""
    return [a for a in _sign_changes(case, 1) if _apart(a, (0.0, 2 * math.pi, case.machine.bdc_angle))]


def _apart(angle: float, others: tuple[float, ...]) -> bool:
    return all(abs(angle - o) > SAME_NODE_RAD for o in others)


def inflections(case: Case) -> list[float]:
    """Crank angles [rad] where h'' changes sign (h'^2 has its interior extremes only there and at the zeros
    of h'), by bisection on a grid of :data:`INFLECTION_GRID` angles."""
    return _sign_changes(case, 2)


def _sign_changes(case: Case, order: int) -> list[float]:
    """Crank angles [rad] where the ``order``-th derivative of h changes sign."""
    mesh = np.linspace(0.0, 2 * math.pi, INFLECTION_GRID + 1)
    d2 = case.machine.jets(mesh)[order]
    k = np.flatnonzero(np.sign(d2[:-1]) * np.sign(d2[1:]) < 0)
    lo, hi = mesh[k], mesh[k + 1]
    sign_lo = np.sign(d2[k])
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        same = np.sign(case.machine.jets(mid)[order]) == sign_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    return (0.5 * (lo + hi)).tolist()


def _pieces(theta: np.ndarray, d1: np.ndarray, pieces: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each interval cut into ``pieces`` equal pieces, a sliver split off next to a dead centre: (interval
    of each piece, its start, its end [rad], whether it touches a dead centre)."""
    scale = np.max(np.abs(d1))
    cells, starts, ends, dead = [], [], [], []
    for i in range(theta.size - 1):
        a, b = theta[i], theta[i + 1]
        cuts = list(np.linspace(a, b, pieces + 1))
        dead_start = abs(d1[i]) <= DEAD_CENTRE_SLOPE * scale
        dead_end = abs(d1[i + 1]) <= DEAD_CENTRE_SLOPE * scale
        if dead_start:
            cuts.insert(1, a + DEAD_CENTRE_SLIVER * (b - a))
        if dead_end:
            cuts.insert(len(cuts) - 1, b - DEAD_CENTRE_SLIVER * (b - a))
        for k in range(len(cuts) - 1):
            cells.append(i)
            starts.append(cuts[k])
            ends.append(cuts[k + 1])
            dead.append((dead_start and k == 0) or (dead_end and k == len(cuts) - 2))
    return np.array(cells), np.array(starts), np.array(ends), np.array(dead)


@dataclass(frozen=True)
class Relaxation:
    """The relaxed problem of a case on one mesh: ``nlp`` (CasADi: ``x`` scaled variables, ``f``, ``g``),
    ``scale`` (physical = scale * x: the crank speed squared at the nodes [rad^2/s^2], then each piece's time
    [s]), bounds ``lbx``, ``ubx`` (physical), ``lbg``, ``ubg``, start ``x0`` (physical); the mesh: ``theta``
    (nodes [rad], from theta1 over one turn), ``cell`` (each piece's interval), ``a``, ``b`` (its ends
    [rad]); ``left_out`` (limits without a relaxed form)."""

    nlp: dict
    scale: np.ndarray
    lbx: np.ndarray
    ubx: np.ndarray
    lbg: np.ndarray
    ubg: np.ndarray
    x0: np.ndarray
    theta: np.ndarray
    cell: np.ndarray
    a: np.ndarray
    b: np.ndarray
    left_out: tuple[str, ...]

    def point_of(self, speed_at, time_at) -> np.ndarray:  # noqa: ANN001 - callables of angles
        """A motion's own point of the relaxed problem (physical): its crank speed squared at the nodes and
        its time on each piece, from ``speed_at(angles)`` [rad/s] and ``time_at(angle)`` [s] (the time the
        motion passes a crank angle, counted from theta1; the angles are taken over one turn from theta1)."""
        start = self.theta[0]
        at_a = np.array([time_at(float(x)) for x in self.a])
        at_b = np.array([time_at(float(x)) if x < start + 2 * math.pi - SAME_ANGLE_RAD else math.nan for x in self.b])
        period = time_at(start + 2 * math.pi)
        at_b = np.where(np.isnan(at_b), period, at_b)
        return np.concatenate([np.asarray(speed_at(self.theta[:-1])) ** 2, at_b - at_a])

    def rows_at(self, x: np.ndarray) -> np.ndarray:
        """The rows ``g`` at the physical point ``x``."""
        g = ca.Function("g", [self.nlp["x"]], [self.nlp["g"]])
        return np.asarray(g(x / self.scale)).ravel()


def upper_bound(case: Case, points: int = UPPER_POINTS, pieces: int = UPPER_PIECES) -> UpperBound:
    """The certified upper bound of ``case`` (module docstring) on a grid of about ``points`` intervals,
    each in ``pieces`` pieces; raises a :class:`~planning.solver.outcomes.PlanningError` if there is none."""
    t_start = time.perf_counter()
    r = relaxation(case, points, pieces)
    solver = NLPSolver("upper_bound", r.nlp, BOUND_OPTIONS, fixed_scale=r.scale)
    res = solver.solve(r.x0, r.lbx, r.ubx, r.lbg, r.ubg, clip_to_bounds=False)
    if res.return_status != SOLVED:  # not IPOPT's "acceptable" level: its rows may be violated by far more
        raise NoPlanFound(f"the upper bound did not converge ({res.return_status})")
    period = float(np.sum(res.x[r.theta.size - 1 :])) + case.standstill_s  # a hold's standstill comes on top
    return UpperBound(
        spm=60.0 / period,
        cycle_time_s=period,
        points=r.theta.size - 1,
        pieces=pieces,
        left_out=r.left_out,
        wall_time_s=time.perf_counter() - t_start,
    )


def relaxation(case: Case, points: int = UPPER_POINTS, pieces: int = UPPER_PIECES) -> Relaxation:
    """The relaxed problem of ``case`` (module docstring) on a grid of about ``points`` intervals, each in
    ``pieces`` pieces; raises a :class:`~planning.solver.outcomes.PlanningError` when the case has no
    motion at all (the prechecks)."""
    w2_lo, w2_hi = precheck(case)
    m = case.machine
    th = angle_mesh(case, points, (0.0, m.bdc_angle, *slope_zeros(case), *inflections(case)))
    dth = np.diff(th)
    h, d1, d2, _ = m.jets(th)
    _, th2, th3, th4 = case.key_angles
    limits = limits_of(case)
    draw = draw_nodes(case, th)
    window = th[:-1] >= th4 - SAME_ANGLE_RAD
    lbx_s, ubx_s = node_speed_bounds(BoundMesh(case, th, h, d1, d2, dth, window), limits, draw, w2_lo, w2_hi)

    cell, a, b, dead = _pieces(th, d1, pieces)
    h_a, d1_a = m.jets(a)[:2]
    h_b, d1_b = m.jets(b)[:2]
    slope2_min = np.where(dead, 0.0, np.minimum(d1_a**2, d1_b**2))
    mesh = RelaxedMesh(case, th, h, d1, d2, dth, window, cell=cell, a=a, b=b, h_a=h_a, h_b=h_b, slope2_min=slope2_min)
    s_unit, tau_unit, x_s, x_tau, tau_piece = _symbols(mesh, lbx_s, ubx_s)

    g, lbg, ubg, left_out = _limit_rows(mesh, limits, draw)
    relaxed = [limit for limit in limits if limit.field not in left_out]
    inside = draw[th[draw + 1] <= th3 + SAME_ANGLE_RAD]  # the draw's intervals (the node at theta3 starts the return)
    tau_floor = _piece_time_rows(mesh, relaxed, inside, dead, tau_piece, (g, lbg, ubg))
    width = b - a
    nlp = {"x": ca.vertcat(x_s, x_tau), "f": ca.sum1(tau_piece), "g": ca.vertcat(*g)}
    return Relaxation(
        nlp=nlp,
        scale=np.concatenate([s_unit, tau_unit]),
        lbx=np.concatenate([lbx_s, tau_floor]),
        ubx=np.concatenate([ubx_s, np.full(cell.size, np.inf)]),
        lbg=np.concatenate(lbg),
        ubg=np.concatenate(ubg),
        x0=np.concatenate([s_unit, np.maximum(width / np.sqrt(s_unit[cell]), tau_floor)]),
        theta=th,
        cell=cell,
        a=a,
        b=b,
        left_out=tuple(dict.fromkeys(left_out)),
    )


def _symbols(mesh: RelaxedMesh, lbx_s: np.ndarray, ubx_s: np.ndarray) -> tuple:
    """The relaxation's variables on ``grid`` (set on it): the speed squared at the nodes and each piece's
    time, scaled (``s_unit``, ``tau_unit``: the grid bound's scales); returns ``(s_unit, tau_unit, x_s,
    x_tau, tau_piece)``."""
    case, th, cell = mesh.case, mesh.theta, mesh.cell
    n = th.size - 1
    w_acc2 = case.limits.slider_accel_mm_s2 / case.machine.peak_curvature  # scales, as the grid bound's
    s_unit = np.clip(np.full(n, w_acc2), lbx_s, ubx_s)
    tau_unit = (mesh.b - mesh.a) / np.sqrt(s_unit[cell])
    x_s = ca.SX.sym("s", n)  # scalar operations only: SX evaluates them fastest
    x_tau = ca.SX.sym("tau", cell.size)
    s = ca.DM(s_unit) * x_s
    tau_piece = ca.DM(tau_unit) * x_tau
    mesh.s = s
    mesh.s_next = ca.vertcat(s[1:], s[0])
    mesh.alpha = (mesh.s_next - mesh.s) / (2 * mesh.dtheta)  # each interval's mean acceleration over angle
    # each interval's time: the sum of its pieces' (a sparse 0/1 matrix)
    to_cell = ca.DM(ca.Sparsity.triplet(n, cell.size, cell.tolist(), list(range(cell.size))), 1.0)
    mesh.tau = ca.mtimes(to_cell, tau_piece)
    mesh.tau_next = ca.vertcat(mesh.tau[1:], mesh.tau[0])
    return s_unit, tau_unit, x_s, x_tau, tau_piece


def _limit_rows(mesh: RelaxedMesh, limits: tuple, draw: np.ndarray) -> tuple[list, list, list, list[str]]:
    """Each limit's relaxed rows (the fields of those without any: left out), then the draw at one speed:
    ``(g, lbg, ubg, left_out)``."""
    g, lbg, ubg = [], [], []
    left_out = []
    for limit in limits:
        rows = limit.relaxed_rows(mesh)
        if rows is None:
            left_out.append(limit.field)
            continue
        for expr, lo, hi in rows:
            g.append(expr)
            lbg.append(np.broadcast_to(lo, (expr.shape[0],)))
            ubg.append(np.broadcast_to(hi, (expr.shape[0],)))
    if draw.size > 1:  # the draw at one speed
        s = mesh.s
        g.append(s[draw[1:].tolist()] - s[draw[:-1].tolist()])
        lbg.append(np.zeros(draw.size - 1))
        ubg.append(np.zeros(draw.size - 1))
    return g, lbg, ubg, left_out


def _piece_time_rows(
    mesh: RelaxedMesh, relaxed: list, inside: np.ndarray, dead: np.ndarray, tau_piece: ca.SX, rows: tuple
) -> np.ndarray:
    """Each piece's time from the mean of the envelopes over its sub-pieces (module docstring): rows appended
    to ``rows`` (``g, lbg, ubg``) where the mean depends on the nodes, the time's floor where it is constant
    (returned)."""
    g, lbg, ubg = rows
    cell = mesh.cell
    sub = _sub_mesh(mesh, SUBPIECES)

    def envelopes_of(g_: RelaxedMesh) -> list[Envelope]:  # the limits', then the draw's at one speed
        return [e for limit in relaxed for e in limit.relaxed_envelopes(g_)] + [
            Envelope(g_.s_a, np.isin(g_.cell, inside), "exact")
        ]

    combined = _affine(envelopes_of, sub) + _caps(relaxed, sub)
    width = mesh.b - mesh.a
    tau_floor = np.zeros(cell.size)
    s_start, s_end = mesh.s[cell.tolist()], mesh.s_next[cell.tolist()]
    for k_a, k_b, k_c in _mean_forms(combined, SUBPIECES):
        ok = np.isfinite(k_c) & ~dead
        constant = ok & (k_a == 0.0) & (k_b == 0.0)
        tau_floor[constant] = np.maximum(tau_floor[constant], width[constant] / np.sqrt(k_c[constant]))
        k = np.flatnonzero(ok & ~constant)
        if k.size:
            mean = ca.DM(k_a[k]) * s_start[k.tolist()] + ca.DM(k_b[k]) * s_end[k.tolist()] + ca.DM(k_c[k])
            g.append(tau_piece[k.tolist()] - ca.DM(width[k]) / ca.sqrt(mean))
            lbg.append(np.zeros(k.size))
            ubg.append(np.full(k.size, np.inf))
    return tau_floor


@dataclass(frozen=True)
class _Affine:
    """An envelope on the sub-pieces as numbers: ``start * s_i + end * s_(i+1) + constant`` [rad^2/s^2] with
    ``s_i``, ``s_(i+1)`` the nodes of the sub-piece's interval (infinite where it does not hold), ``side``."""

    start: np.ndarray
    end: np.ndarray
    constant: np.ndarray
    side: str


def _affine(envelopes_of, sub: RelaxedMesh) -> list[_Affine]:  # noqa: ANN001 - grid -> list of Envelope
    """The envelopes ``envelopes_of(sub)`` as numbers: evaluated at the unit node values (each is affine in
    them), infinite where it does not hold."""
    at = []
    for s_a, s_b in ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)):
        sub.s_a, sub.s_b = np.full(sub.cell.size, s_a), np.full(sub.cell.size, s_b)
        at.append([np.where(e.where, np.broadcast_to(e.value, sub.cell.shape), np.inf) for e in envelopes_of(sub)])
    out = []
    for c, at_start, at_end, env in zip(*at, envelopes_of(sub), strict=True):
        finite = np.isfinite(c)
        base = np.where(finite, c, 0.0)
        out.append(_Affine(np.where(finite, at_start - base, 0.0), np.where(finite, at_end - base, 0.0), c, env.side))
    return out


def _caps(limits: list, sub: RelaxedMesh) -> list[_Affine]:
    """The limits' caps as one envelope of either side: on each sub-piece the least of them (none: [])."""
    caps = [np.asarray(c, dtype=float) for c in (limit.relaxed_caps(sub) for limit in limits) if c is not None]
    if not caps:
        return []
    zero = np.zeros(sub.cell.size)
    return [_Affine(zero, zero, np.min(caps, axis=0), "both")]


def _sub_mesh(mesh: RelaxedMesh, count: int) -> RelaxedMesh:
    """Each piece of ``grid`` cut into ``count`` equal sub-pieces, in order (a piece's at ``count * p`` on)."""
    frac = np.linspace(0.0, 1.0, count + 1)
    width = (mesh.b - mesh.a)[:, None]
    a = (mesh.a[:, None] + width * frac[None, :-1]).ravel()
    b = (mesh.a[:, None] + width * frac[None, 1:]).ravel()
    dead = np.repeat(mesh.slope2_min == 0.0, count)
    h_a, d1_a = mesh.case.machine.jets(a)[:2]
    h_b, d1_b = mesh.case.machine.jets(b)[:2]
    slope2_min = np.where(dead, 0.0, np.minimum(d1_a**2, d1_b**2))
    return RelaxedMesh(
        mesh.case,
        mesh.theta,
        mesh.h,
        mesh.d1,
        mesh.d2,
        mesh.dtheta,
        mesh.window,
        cell=np.repeat(mesh.cell, count),
        a=a,
        b=b,
        h_a=h_a,
        h_b=h_b,
        slope2_min=slope2_min,
    )


def _mean_forms(envelopes: list[_Affine], count: int):  # noqa: ANN202 - a generator of triples
    """Each piece's mean of an envelope over its sub-pieces, as ``(start, end, constant)`` coefficients of
    its interval's nodes (each a valid bound on the piece's mean crank speed squared): one envelope over the
    whole piece, and a start-side one over the first part with an end-side one over the rest (a motion
    accelerating at its limit, then decelerating), at each of :data:`SPLITS`."""

    def mean(env: _Affine, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        cols = slice(lo, hi)
        return tuple(
            np.sum(np.reshape(v, (-1, count))[:, cols], axis=1) / count for v in (env.start, env.end, env.constant)
        )

    for env in envelopes:
        yield mean(env, 0, count)
    firsts = [e for e in envelopes if e.side in ("start", "both")]  # the draw's ("exact") needs no split
    lasts = [e for e in envelopes if e.side in ("end", "both")]
    for split in SPLITS:
        r = round(split * count)
        for x in firsts:
            for y in lasts:
                if x is y:
                    continue
                p, q = mean(x, 0, r), mean(y, r, count)
                yield tuple(u + v for u, v in zip(p, q, strict=True))


__all__ = ["RPM", "Relaxation", "UpperBound", "relaxation", "upper_bound"]
