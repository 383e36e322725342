"""An upper bound on a pendulum stroke's strokes/min that no swing meeting the case's limits can exceed.

A pendulum cycle (``planning.model.pendulum``) is two robot's windows, each at least the transfer time T, and
two passes through the work: the forward swing from theta1 to theta4 and the backward swing from its theta1 to
its theta4 (each monotone, on its path coordinate u). So every cycle lasts at least ``2 T + t_f + t_b``, where
``t_k`` is the least time any motion meeting the limits takes over swing k's arc theta1 .. theta4, whatever its
speeds at the arc's ends. ``t_k`` is bounded below on a fine grid of the arc (the key angles, the die-height
crossings, the dead centres and the inflection points of h among its nodes, so that |h'| is monotone on every
interval) by the crank speed squared ``s`` any such motion can have at the nodes:

- at most every speed cap there (the top crank speed; a slide-speed cap ``(v / h')^2``: the slider speed, the
  die speed at or below the die height, the draw start speed at theta2), and on the draw the draw speed's
  bound, one value over the whole draw (the draw runs at one crank speed);
- the crank acceleration limit A_c: ``|s_(i+1) - s_i| <= 2 A_c dtheta`` (``d(omega^2)/dtheta = 2 alpha``);
- the slider acceleration limit A: ``|h'_(i+1)^2 s_(i+1) - h'_i^2 s_i| <= 2 A |h_(i+1) - h_i|`` (``d(v^2)/dtheta
  = 2 h' a``, h monotone on the interval);

propagated forward and backward over the arc until nothing changes: the largest ``s`` any motion can have at
each node. Within an interval the speed squared is at most the largest cap at its ends (|h'| monotone) and at
most either end's envelope plus the crank acceleration's reach, so the interval takes at least ``dtheta /
sqrt(that)``; with a hold each swing stands its hold time on the arc, added to ``t_k``. The bound is
``120 / (2 T + t_f + t_b)`` (two strokes a cycle). It leaves out the jerk limit, the
turns (the crank at rest there) and the windows' own motion, so it is loose: an upper bound, not an estimate.

With robots on their interference curves (``planning.solver.pendulum_robots``) there is no transfer time; the
cycle is at least the largest of: ``t_f + t_b`` (each swing passes its key angles); the robots' shortest cycle
twice (each robot goes in and out in both windows, in turns both robots', overlapping also the unloader's dwell
and clearing and the loader's dwell); both draws at their highest speed and twice the
least time the robots need between the draws (``planning.model.limits.robots.between_draws_s``: the unloader
grips after theta3 and the loader drops before theta2 in each window); and for each height ``H`` a curve names
above the draw, the least time over each swing's arc below ``H`` (the procedure above on that arc) and twice
each robot's time needing ``H`` (its two occupancies never overlap, and its tool needs ``H`` only where the
slide is at or above it). Each is a necessary condition, so the bound stays a bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planning.model.case import Case
from planning.model.limits import limits_of
from planning.model.limits.canonical import SpeedCap
from planning.model.limits.robots import between_draws_s, least_period_s, levels, robots_by_name
from planning.model.pendulum import STROKES_PER_CYCLE, SwingSetup, swing_setups
from planning.solver.upper_bound import inflections, slope_zeros
from planning.tolerances import LIMIT_REL_TOL, SAME_NODE_RAD, TIME_TOL_S, TINY
from press.robot import time_needing

CHAINED_CHECKS = 4  # the most order checks a window's robots pass in turn, each within TIME_TOL_S
ARC_INTERVALS = 20_000  # intervals over each swing's arc theta1 .. theta4
MAX_PASSES = 50  # forward and backward passes at most (the envelope settles in a few)


@dataclass(frozen=True)
class PendulumBound:
    """``spm``: no pendulum motion meeting the limits makes more; ``cycle_time_s`` [s]: no cycle is shorter;
    ``arc_times_s``: the least time over each swing's theta1 .. theta4 [s] (forward, backward)."""

    spm: float
    cycle_time_s: float
    arc_times_s: tuple[float, float]
    sets_it: str = "the robot's two windows and theta1 .. theta4"  # what gives the least cycle


def pendulum_bound(case: Case) -> PendulumBound:
    """The upper bound of a pendulum case (module docstring)."""
    setups = swing_setups(case, {})  # the case's own limits
    times = tuple(_least_arc_time(case, setup) + case.standstill_s for setup in setups)  # (a hold: on the arc)
    if case.robots is None:
        cycle = 2 * case.process.transfer_time_s + sum(times)
        return PendulumBound(STROKES_PER_CYCLE * 60.0 / cycle, cycle, times)  # type: ignore[arg-type]
    demands = [(sum(times), "theta1 .. theta4 of both swings"), *robot_demands(case, setups)]
    cycle, sets_it = max(demands)
    return PendulumBound(STROKES_PER_CYCLE * 60.0 / cycle, cycle, times, sets_it)  # type: ignore[arg-type]


def robot_demands(case: Case, setups: tuple[SwingSetup, ...]) -> list[tuple[float, str]]:
    """With robots: the least cycles [s] their demands allow, each with what it is (module docstring): the
    robots' shortest cycle in both windows (``planning.model.limits.robots.least_period_s``); the two draws and
    each window's share between the draws (``planning.model.limits.robots.between_draws_s``); for each height
    ``H`` the curves name above the draw, each swing's arc below ``H`` and each robot's time needing ``H`` in
    both windows. Each less what the verification's tolerances let a plan pass by."""
    robots = robots_by_name(case)
    # (each less what the verification's tolerances let a plan pass by: no verified plan above the bound)
    occupancy = least_period_s(case) - CHAINED_CHECKS * TIME_TOL_S
    draws = sum((s.keys[2] - s.keys[1]) / s.draw_speed_bound for s in setups) * (1 - LIMIT_REL_TOL)
    between = between_draws_s(case) - CHAINED_CHECKS * TIME_TOL_S
    out = [
        (STROKES_PER_CYCLE * occupancy, "each robot in and out in both windows"),
        (draws + STROKES_PER_CYCLE * between, "the draws and the robots between them"),
    ]
    m = case.machine
    _, th2, th3, _ = case.key_angles
    above_draw = float(max(m.height(th2), m.height(th3)))
    for level in levels(robots):
        lowest = level - LIMIT_REL_TOL * max(level, 1.0)  # the slide a clearance check passes where H is needed
        if not above_draw < lowest < m.stroke:
            continue
        down, up = (float(a) for a in m.angles_at_height(lowest))
        arcs = {"forward": (down, up), "backward": (2 * math.pi - up, 2 * math.pi - down)}
        below = sum(_least_arc_time(case, s, arcs[s.name]) + _hold_below(case, level) for s in setups)
        need = max(time_needing(r, level) for r in robots.values())
        out.append((below + STROKES_PER_CYCLE * need, f"the slide below {level:g} mm and the robots above it"))
    return out


def _hold_below(case: Case, level: float) -> float:
    """[s] the hold's standstill where it lies below ``level`` [mm] (on the arc below it), else 0."""
    return case.standstill_s if case.hold_height_mm < level else 0.0


def _nodes(case: Case, setup: SwingSetup, arc: tuple[float, float] | None = None) -> np.ndarray:
    """The arc's nodes on u (``arc``: its ends, theta1 .. theta4 when None): its ends, the key angles, die-height
    crossings, dead centres and inflections among them."""
    u1, u4 = arc if arc is not None else (setup.keys[0], setup.keys[3])
    m = case.machine
    real = [m.bdc_angle, *slope_zeros(case), *inflections(case), *m.angles_at_height(case.limits.die_height_mm)]
    on_u = [float(a) if setup.name == "forward" else 2 * math.pi - float(a) for a in real]
    inner = (a for a in [*setup.keys, *on_u] if u1 + SAME_NODE_RAD < a < u4 - SAME_NODE_RAD)
    breaks = sorted({u1, u4, *inner})
    spans = np.diff(breaks)
    counts = np.maximum(4, np.round(ARC_INTERVALS * spans / spans.sum()).astype(int))
    parts = [np.linspace(a, b, n + 1)[:-1] for a, b, n in zip(breaks[:-1], breaks[1:], counts, strict=True)]
    return np.concatenate([*parts, [u4]])


def _caps(
    case: Case, setup: SwingSetup, u: np.ndarray, h: np.ndarray, d1: np.ndarray, everywhere: bool = False
) -> np.ndarray:
    """The largest crank speed squared each speed cap allows at the nodes [rad^2/s^2]: a cap on the crank's own
    speed (the crank's top speed, the motor's through the gear: ``k`` a constant) everywhere, a cap on the
    slide's speed (``k = h'``) where it applies (``everywhere``: only the caps that apply at every angle, and the
    draw's, for an interval that leaves a cap's domain: a node on the die height's crossing bounds no interval
    above it)."""
    caps = np.full(u.size, math.inf)
    for limit in limits_of(case):
        if not isinstance(limit, SpeedCap) or limit.lower:
            continue
        factor = limit.crank_factor(case)
        inside = limit.where(case, h, bound=True)
        if inside is not None and everywhere:
            continue
        inside = np.ones(u.size, dtype=bool) if inside is None else inside
        k = np.full(u.size, float(factor)) if factor is not None else np.abs(d1)
        moving = inside & (k > 0)
        caps[moving] = np.minimum(caps[moving], (limit.top(case) / k[moving]) ** 2)
    u2, u3 = setup.keys[1], setup.keys[2]
    draw = (u >= u2 - SAME_NODE_RAD) & (u <= u3 + SAME_NODE_RAD)
    caps[draw] = min(float(np.min(caps[draw])), setup.draw_speed_bound**2)
    at2 = int(np.argmin(np.abs(u - u2)))
    if abs(d1[at2]) > 0:
        caps[at2] = min(caps[at2], (case.limits.draw_start_speed_mm_s / d1[at2]) ** 2)
    return caps


def _least_arc_time(case: Case, setup: SwingSetup, arc: tuple[float, float] | None = None) -> float:
    """The least time [s] any motion meeting the limits takes over the swing's theta1 .. theta4 (or ``arc``: its
    ends on u, around the draw)."""
    u = _nodes(case, setup, arc)
    h, d1, _, _ = setup.jets(u)
    h, d1 = np.asarray(h), np.asarray(d1)
    caps = _caps(case, setup, u, h, d1)
    s = _envelope(case, caps, np.diff(u), h, d1)
    reach = 2 * (case.limits.crank_accel_rad_s2 or math.inf) * np.diff(u)
    # within an interval: at most the largest of the caps at its ends that hold all along it (a cap with a
    # domain only where both ends lie in it: h is monotone on the interval), and either end's envelope plus reach
    free = _caps(case, setup, u, h, d1, everywhere=True)
    domained = [limit for limit in limits_of(case) if isinstance(limit, SpeedCap) and limit.where(case, h) is not None]
    both = np.ones(u.size - 1, dtype=bool)
    for limit in domained:
        within = limit.where(case, h)
        both &= within[:-1] & within[1:]
    ends = np.where(both, np.maximum(caps[:-1], caps[1:]), np.maximum(free[:-1], free[1:]))
    inside = np.minimum(ends, np.minimum(s[:-1], s[1:]) + reach)
    return float(np.sum(np.diff(u) / np.sqrt(np.maximum(inside, TINY))))


def _envelope(case: Case, caps: np.ndarray, du: np.ndarray, h: np.ndarray, d1: np.ndarray) -> np.ndarray:
    """The largest crank speed squared at the nodes under the caps and both accelerations' reach."""
    A_c = case.limits.crank_accel_rad_s2 or math.inf
    A = case.limits.slider_accel_mm_s2
    slope2 = d1**2
    rise = 2 * A * np.abs(np.diff(h))
    s = caps.copy()
    for _ in range(MAX_PASSES):
        before = s.copy()
        for i in range(s.size - 1):  # forward
            s[i + 1] = min(s[i + 1], s[i] + 2 * A_c * du[i], _slide(slope2[i], s[i], rise[i], slope2[i + 1]))
        for i in range(s.size - 2, -1, -1):  # backward
            s[i] = min(s[i], s[i + 1] + 2 * A_c * du[i], _slide(slope2[i + 1], s[i + 1], rise[i], slope2[i]))
        if np.array_equal(before, s):
            break
    return s


def _slide(slope2_from: float, s_from: float, rise: float, slope2_to: float) -> float:
    """The largest crank speed squared at a node the slide's acceleration allows from its neighbour's."""
    if slope2_to <= 0:
        return math.inf
    return (slope2_from * s_from + rise) / slope2_to
