"""A press-tending robot (an unloader or a loader) on its path: its fastest move and its interference curve.

The first layer of the robots' model (issue 39): pure functions and small dataclasses, no case and no solver.

Conventions
-----------
- **Position** ``x`` [mm] along the robot's path, measured from the die centre (``x = 0``, where the tool grips or
  drops the part) to the robot's waiting point outside the press (``x = L``, the path length).
- **Time** [s]; a robot's cycle: from its waiting point it moves in (``x`` from ``L`` to 0), dwells at the die
  centre (grip or release), moves out (``x`` from 0 to ``L``) and waits; once per stroke of the press, periodic
  with the press's cycle time.
- **A move** is rest to rest and the fastest the limits allow: ``|v| <= v_max``, ``|a| <= a_max`` and, when
  given, ``|j| <= j_max``. Its speed never changes sign, so the position is monotone.

  Without a jerk limit it is the trapezoid (the triangle when the top speed is not reached): with
  ``L >= v_max^2 / a_max``, ``T = L / v_max + v_max / a_max``; else ``T = 2 sqrt(L / a_max)``.

  With a jerk limit it is the double-S (seven-segment) profile of Biagiotti & Melchiorri, *Trajectory Planning
  for Automatic Machines and Robots* (2008), section 3.4, for ``v0 = v1 = 0``: ``T_j`` the time of a jerk
  phase, ``T_a`` of the acceleration, ``T_v`` at top speed, ``T = 2 T_a + T_v``:
  ``T_j = a_max / j_max`` and ``T_a = T_j + v_max / a_max`` where ``v_max j_max >= a_max^2``, else
  ``T_j = sqrt(v_max / j_max)``, ``T_a = 2 T_j``; ``T_v = L / v_max - T_a``; when ``T_v < 0`` the top speed is
  not reached: ``T_v = 0`` and, where ``L >= 2 a_max^3 / j_max^2``, ``T_j = a_max / j_max``,
  ``T_a = T_j / 2 + sqrt((T_j / 2)^2 + L / a_max)``; else ``T_j = (L / (2 j_max))^(1/3)``, ``T_a = 2 T_j``.

  A profile is a list of pieces of constant jerk ``(duration, a_start, j)``: on a piece
  ``a = a_start + j t``, speed and position follow by exact integration, continuous across pieces (the
  trapezoid's acceleration steps from one piece to the next; the double-S's is continuous).
- **The interference curve**: the slide height [mm above BDC] the robot's tool needs when it is at ``x``, a
  table interpolated linearly, zero beyond its last point (the tool is clear of the die). The clearance at a
  time is the slide's height then minus what each tool needs then.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planning.tolerances import SAME_POSITION_MM, TIME_TOL_S


@dataclass(frozen=True)
class MoveLimits:
    """A robot's limits along its path: speed [mm/s], acceleration [mm/s^2], jerk [mm/s^3] (None: no limit)."""

    speed_mm_s: float
    accel_mm_s2: float
    jerk_mm_s3: float | None = None


@dataclass(frozen=True)
class Move:
    """A rest-to-rest move over ``length_mm`` as pieces ``(duration [s], a_start [mm/s^2], jerk [mm/s^3])``."""

    length_mm: float
    pieces: tuple[tuple[float, float, float], ...]

    @property
    def duration_s(self) -> float:
        return sum(p[0] for p in self.pieces)

    def state(self, tau_s: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(s, v, a)`` at times ``tau_s`` [s] from the move's start: the distance travelled [mm] (0 before
        the move, ``length_mm`` after it), the speed [mm/s] and the acceleration [mm/s^2]."""
        tau = np.clip(np.asarray(tau_s, dtype=float), 0.0, self.duration_s)
        done = tau >= self.duration_s  # at the end exactly (the pieces' sum carries round-off)
        s, v, a = np.zeros_like(tau), np.zeros_like(tau), np.zeros_like(tau)
        start, s0, v0 = 0.0, 0.0, 0.0
        for k, (length, a0, jerk) in enumerate(self.pieces):
            last = k == len(self.pieces) - 1
            inside = (tau >= start) & ((tau < start + length) | last)
            t = tau[inside] - start
            a[inside] = a0 + jerk * t
            v[inside] = v0 + a0 * t + jerk * t**2 / 2
            s[inside] = s0 + v0 * t + a0 * t**2 / 2 + jerk * t**3 / 6
            s0, v0 = (
                s0 + v0 * length + a0 * length**2 / 2 + jerk * length**3 / 6,
                v0 + a0 * length + jerk * length**2 / 2,
            )
            start += length
        return np.where(done, self.length_mm, s), np.where(done, 0.0, v), np.where(done, 0.0, a)


def fastest_move(length_mm: float, limits: MoveLimits) -> Move:
    """The fastest rest-to-rest move over ``length_mm`` [mm] within ``limits`` (the module's equations)."""
    if length_mm <= 0:
        return Move(0.0, ((0.0, 0.0, 0.0),))
    v, a = limits.speed_mm_s, limits.accel_mm_s2
    if limits.jerk_mm_s3 is None:
        if length_mm >= v * v / a:  # the trapezoid: the top speed reached
            ramp = v / a
            return Move(length_mm, ((ramp, a, 0.0), (length_mm / v - ramp, 0.0, 0.0), (ramp, -a, 0.0)))
        ramp = math.sqrt(length_mm / a)  # the triangle
        return Move(length_mm, ((ramp, a, 0.0), (ramp, -a, 0.0)))
    j = limits.jerk_mm_s3
    t_j, t_a = (a / j, a / j + v / a) if v * j >= a * a else (math.sqrt(v / j), 2 * math.sqrt(v / j))
    t_v = length_mm / v - t_a
    if t_v < 0:  # the top speed not reached
        t_v = 0.0
        if length_mm >= 2 * a**3 / j**2:
            t_j = a / j
            t_a = t_j / 2 + math.sqrt((t_j / 2) ** 2 + length_mm / a)
        else:
            t_j = (length_mm / (2 * j)) ** (1 / 3)
            t_a = 2 * t_j
    a_top = j * t_j  # the acceleration reached (a_max, or less on a short move)
    flat = t_a - 2 * t_j
    pieces = (
        (t_j, 0.0, j),
        (flat, a_top, 0.0),
        (t_j, a_top, -j),
        (t_v, 0.0, 0.0),
        (t_j, 0.0, -j),
        (flat, -a_top, 0.0),
        (t_j, -a_top, j),
    )
    return Move(length_mm, tuple(p for p in pieces if p[0] > 0))


@dataclass(frozen=True)
class InterferenceCurve:
    """The slide height [mm above BDC] a tool needs at each position [mm from the die centre], linear between
    the points, zero beyond the last (the tool clear of the die)."""

    positions_mm: tuple[float, ...]
    needed_height_mm: tuple[float, ...]

    def need(self, x_mm: np.ndarray | float) -> np.ndarray:
        """The height needed at positions ``x_mm`` [mm]."""
        x = np.asarray(x_mm, dtype=float)
        heights = np.interp(x, self.positions_mm, self.needed_height_mm)
        return np.where(x > self.positions_mm[-1] + SAME_POSITION_MM, 0.0, heights)


@dataclass(frozen=True)
class Robot:
    """A robot on its path: ``path_mm`` from the die centre to its waiting point, its move limits, its dwell at the
    die centre [s] and its interference curve."""

    name: str
    path_mm: float
    limits: MoveLimits
    dwell_s: float
    curve: InterferenceCurve

    @property
    def move(self) -> Move:
        return fastest_move(self.path_mm, self.limits)

    @property
    def occupancy_s(self) -> float:
        """From leaving its waiting point to being back there [s]: in, dwell, out."""
        return 2 * self.move.duration_s + self.dwell_s

    def position(self, t_s: np.ndarray, start_s: float, period_s: float) -> np.ndarray:
        """The position [mm] at cycle times ``t_s`` [s] of a robot that leaves its waiting point at ``start_s``
        [s] each cycle of ``period_s`` [s] (in, dwell, out, then waiting)."""
        if self.occupancy_s > period_s + TIME_TOL_S:  # (equal up to round-off: the plan's period at it)
            took = f"in, dwell and out take {self.occupancy_s:g} s"
            raise ValueError(f"{self.name}: {took}, longer than the cycle {period_s:g} s")
        return self.position_since_start(np.mod(np.asarray(t_s, dtype=float) - start_s, period_s))

    def position_of_starts(self, t_s: np.ndarray, starts_s: tuple[float, ...], period_s: float) -> np.ndarray:
        """The position [mm] at cycle times ``t_s`` [s] of a robot that leaves its waiting point at each of
        ``starts_s`` [s] each cycle of ``period_s`` [s] (occupancies that do not overlap; at its waiting point
        between them): a pendulum cycle's two strokes."""
        t = np.asarray(t_s, dtype=float)
        x = np.full(t.shape, self.path_mm)
        for start in starts_s:
            tau = np.mod(t - start, period_s)
            inside = tau < self.occupancy_s
            x[inside] = self.position_since_start(tau[inside])
        return x

    def position_since_start(self, tau_s: np.ndarray) -> np.ndarray:
        """The position [mm] at times ``tau_s`` [s] from leaving its waiting point (at it again after its
        occupancy)."""
        move = self.move
        tau = np.asarray(tau_s, dtype=float)
        inward = self.path_mm - move.state(tau)[0]
        outward = move.state(tau - move.duration_s - self.dwell_s)[0]
        out_starts = move.duration_s + self.dwell_s
        x = np.where(tau < out_starts, inward, outward)
        return np.where(tau >= self.occupancy_s, self.path_mm, x)

    def needed_height(self, t_s: np.ndarray, start_s: float, period_s: float) -> np.ndarray:
        """The slide height [mm] the tool needs at cycle times ``t_s`` [s] (:meth:`position`'s schedule)."""
        return self.curve.need(self.position(t_s, start_s, period_s))


def crossings(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """``(times, needs)``: the times [s from the robot's start] at which its tool passes its interference
    curve's points, in and out (sorted), and the height [mm] the tool needs at each point itself (the value
    on the curve's side, where a step follows the last point): the curve's kinks and its step, where a sampled
    clearance must look exactly."""
    move, out = robot.move, []
    for x in robot.curve.positions_mm:
        if not 0.0 < x < robot.path_mm:
            continue
        need = float(np.interp(x, robot.curve.positions_mm, robot.curve.needed_height_mm))
        for travelled, since in ((robot.path_mm - x, 0.0), (x, move.duration_s + robot.dwell_s)):
            lo, hi = 0.0, move.duration_s
            for _ in range(BISECTIONS):  # the distance travelled is monotone in time
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if float(move.state(mid)[0][()]) < travelled else (lo, mid)
            out.append((since + hi, need))
    out.sort()
    return np.array([t for t, _ in out], dtype=float), np.array([n for _, n in out], dtype=float)


def clear_position_mm(curve: InterferenceCurve) -> float:
    """The position [mm] from which on the tool needs nothing: clear of the die (the point after the last that
    needs height, or the last point, beyond which the curve is zero)."""
    heights = np.asarray(curve.needed_height_mm)
    needing = np.flatnonzero(heights > 0)
    if needing.size == 0:
        return 0.0
    k = int(needing[-1])
    return float(curve.positions_mm[min(k + 1, len(heights) - 1)])


def time_to_clear_s(robot: Robot) -> float:
    """The time [s] from the start of the robot's move out until its tool is clear of the die
    (:func:`clear_position_mm`; the whole move where the tool is clear only at its waiting point)."""
    move, target = robot.move, min(clear_position_mm(robot.curve), robot.path_mm)
    lo, hi = 0.0, move.duration_s
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if float(move.state(mid)[0][()]) < target else (lo, mid)
    return hi


BISECTIONS = 60  # halvings of a move's duration: below round-off of any move under a day


def sample_points(robot: Robot, count: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` times [s from the robot's start] over its occupancy and the height [mm] the tool needs at
    each: the curve's crossings (:func:`crossings`, each with its point's own need) and evenly spaced times
    between, sorted (a fixed number, so that an NLP's rows keep their shape)."""
    times, needs = crossings(robot)
    even = np.linspace(0.0, robot.occupancy_s, max(count - times.size, 2))
    all_times = np.concatenate([even, times])
    all_needs = np.concatenate([robot.curve.need(robot.position_since_start(even)), needs])
    order = np.argsort(all_times, kind="stable")[:count]
    return all_times[order], all_needs[order]


def time_needing(
    robot: Robot, level_mm: float, within_s: tuple[float, float] | None = None, grid: int = 20_001
) -> float:
    """A lower bound on the time [s] in one occupancy (or its part ``within_s``: from, to [s from the start])
    during which the tool needs at least ``level_mm``: ``grid`` even times, a step counted where the need
    reaches the level at both its ends (never more than the true time; the upper bounds' robot rows rest on
    it)."""
    lo, hi = within_s if within_s is not None else (0.0, robot.occupancy_s)
    tau = np.linspace(lo, hi, grid)
    need = robot.curve.need(robot.position_since_start(tau))
    both = (need[:-1] >= level_mm) & (need[1:] >= level_mm)
    return float(np.sum(np.diff(tau)[both]))
