"""Cams for a press controller: the plan as a controller holds it, and the motion a drive makes of it.

A controller moves the crank (its servo motor) as the *slave* of a virtual *master* axis turning at a
constant speed: the master angle ``m`` [deg] runs from 0 to 360 over one stroke, ``m = 360 t / P`` at the
period ``P`` [s] (``t`` from TDC: master 0 is crank 0, TDC), and the crank turns 360 deg per master turn. A
cam holds the slave's angle ``Y`` [deg] at points ``X`` of the master and interpolates between them as its
controller does (:class:`Interpolation`):

- ``poly5`` (XYVA points: ``X``, ``Y``, ``V = dY/dX`` [deg/deg], ``A = d2Y/dX2`` [deg/deg^2]): on each
  interval ``[X_k, X_k+1]`` of width ``w`` the quintic with ``Y``, ``V``, ``A`` at both ends (CODESYS
  ``SMC_CAMXYVA``, TwinCAT ``MOTIONFUNCTYPE_POLYNOM5_MM``): ``Y(X_k + x) = sum_i b_i x^i`` with
  ``b0 = Y_k``, ``b1 = V_k``, ``b2 = A_k / 2`` and, with ``d = Y_k+1 - (b0 + b1 w + b2 w^2)``,
  ``e = V_k+1 - (b1 + A_k w)``, ``f = A_k+1 - A_k``::

      b3 = (20 d - 8 e w + f w^2) / (2 w^3)
      b4 = (-30 d + 14 e w - 2 f w^2) / (2 w^4)
      b5 = (12 d - 6 e w + f w^2) / (2 w^5)

  Any slave motion of degree five or less in the master between two points is reproduced exactly.
- ``spline`` (XY points): the cubic spline through the points with continuous slope and curvature,
  periodic (the cam repeats every stroke): fitted to ``Y - X``, which the crank's turn with the master makes
  periodic in value and slope.
- ``linear`` (XY points): straight lines; the slave's speed steps at every point.

In time, at the master speed ``c = 360 / P`` [deg/s] (``P`` the period the cam runs at), the crank angle
on an interval is ``theta(tau) = pi/180 sum_i b_i (c tau)^i``: a polynomial of degree five in time, in the
form of :class:`~planning.model.profile.Profile` (the start state, the jerk ``j0 + j1 tau``, the fifth
power as the shape :class:`FifthPower`), so that the dense verification reads a cam as it reads a plan.
A linear table as a drive follows it (:func:`realised_profile`): the controller hands the drive a new
position every cycle ``dt`` [s], and each speed step ``dv`` of the table reaches the drive spread over the
cycles around its point: the crank speed ramps over ``[t_k - dt, t_k + dt]`` (the moving average of the
speed over one cycle, twice), its acceleration a triangle of height ``dv / dt``, its jerk ``+-dv / dt^2``;
away from the ramps the angle is the table's.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from planning.model.profile import Profile, Segment

DEG = math.pi / 180.0  # [rad] per degree
TURN_DEG = 360.0  # the master's and the crank's turn per stroke


class Interpolation(str, enum.Enum):
    """How a controller interpolates between a cam's points."""

    POLY5 = "poly5"  # XYVA points, a quintic between two
    SPLINE = "spline"  # XY points, the periodic cubic spline through them
    LINEAR = "linear"  # XY points, straight lines

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class FifthPower:
    """The shape term ``theta += dv D u^5`` (``u = tau / D``) of a cam's interval: with it the segment's crank
    angle is any polynomial of degree five in time (``planning.model.profile``'s shape convention:
    ``s = 5 u^4``, ``S = u^5``, ``s' = 20 u^3``, ``s'' = 60 u^2``; zero at ``u = 0`` with its slope)."""

    name: str = "fifth power"
    continuity: str = "acceleration"

    def terms(self, u: Any) -> tuple[Any, Any, Any, Any]:
        return 5 * u**4, u**5, 20 * u**3, 60 * u**2

    def peak_jerk(self) -> float:
        return 60.0

    def segment_peak_jerk(self, seg: Segment) -> float:
        """The exact largest ``|jerk|`` [rad/s^3] over ``seg``: ``j0 + j1 tau + 60 dv / D^2 (u0 + tau / D)^2``
        is a quadratic in ``tau``, largest in magnitude at an end or at its vertex."""
        D, T = float(seg.span), float(seg.duration)
        j0, j1, q = float(seg.j0), float(seg.j1), 60.0 * float(seg.dv) / D**2
        taus = [0.0, T]
        slope_at_zero, curvature = j1 + 2 * q * seg.u0 / D, 2 * q / D**2
        if curvature != 0.0 and 0.0 < -slope_at_zero / curvature < T:
            taus.append(-slope_at_zero / curvature)
        return max(abs(j0 + j1 * t + q * (seg.u0 + t / D) ** 2) for t in taus)


FIFTH_POWER = FifthPower()


@dataclass(frozen=True)
class Cam:
    """A cam as a controller holds it: ``master_deg`` (X, increasing from 0 to 360, both ends), ``slave_deg``
    (Y, the crank's angle: 0 at TDC, 360 a stroke on) and, for ``poly5``, ``slope`` (V) and ``curvature``
    (A) at the same points; ``interpolation`` between them (module docstring). ``slave_turn_deg``: how far the
    slave is on after one master turn (360: a rotary stroke; 0: a pendulum cycle, the crank back where it
    started)."""

    interpolation: Interpolation
    master_deg: np.ndarray
    slave_deg: np.ndarray
    slope: np.ndarray | None = None
    curvature: np.ndarray | None = None
    slave_turn_deg: float = TURN_DEG

    def __post_init__(self) -> None:
        x = self.master_deg
        if x.size < 2 or x[0] != 0.0 or x[-1] != TURN_DEG or np.any(np.diff(x) <= 0):
            raise ValueError("a cam's master runs from 0 to 360 deg, increasing")
        if (self.interpolation is Interpolation.POLY5) != (self.slope is not None and self.curvature is not None):
            raise ValueError("XYVA points (slope and curvature) exactly for poly5")
        if self.interpolation is Interpolation.SPLINE and x.size < 4:
            raise ValueError("a periodic spline needs at least 3 points")

    @property
    def points(self) -> int:
        """The cam's points over one turn (the end at 360 deg is the start again)."""
        return int(self.master_deg.size - 1)

    @cached_property
    def coefficients(self) -> np.ndarray:
        """``b_0 .. b_5`` of each interval (rows) in the master from its start [deg/deg^i]."""
        x, y = self.master_deg, self.slave_deg
        w = np.diff(x)
        b = np.zeros((w.size, 6))
        b[:, 0] = y[:-1]
        if self.interpolation is Interpolation.LINEAR:
            b[:, 1] = np.diff(y) / w
        elif self.interpolation is Interpolation.SPLINE:
            b[:, 1:4] = _periodic_spline(x, y)
        else:
            b[:, 1:] = quintic_coefficients(w, y, self.slope, self.curvature)
        return b

    def at(self, master_deg: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(Y [deg], dY/dX, d2Y/dX2, d3Y/dX3)`` at master angles (any real: a turn on adds 360 deg to
        ``Y`` the slave's turn, :attr:`slave_turn_deg`); at a point the interval that starts there."""
        m = np.asarray(master_deg, dtype=float)
        turns = np.floor(m / TURN_DEG)
        local = m - turns * TURN_DEG
        k = np.clip(np.searchsorted(self.master_deg, local, side="right") - 1, 0, self.points - 1)
        x = local - self.master_deg[k]
        b = self.coefficients[k]
        y = b[:, 0] + x * (b[:, 1] + x * (b[:, 2] + x * (b[:, 3] + x * (b[:, 4] + x * b[:, 5]))))
        v = b[:, 1] + x * (2 * b[:, 2] + x * (3 * b[:, 3] + x * (4 * b[:, 4] + x * 5 * b[:, 5])))
        a = 2 * b[:, 2] + x * (6 * b[:, 3] + x * (12 * b[:, 4] + x * 20 * b[:, 5]))
        j = 6 * b[:, 3] + x * (24 * b[:, 4] + x * 60 * b[:, 5])
        return y + turns * self.slave_turn_deg, v, a, j

    def at_end(self) -> tuple[float, float, float, float]:
        """``(Y, dY/dX, d2Y/dX2, d3Y/dX3)`` at 360 deg from the last interval's polynomial (its left end)."""
        b, w = self.coefficients[-1], self.master_deg[-1] - self.master_deg[-2]
        y = sum(b[i] * w**i for i in range(6))
        v = sum(i * b[i] * w ** (i - 1) for i in range(1, 6))
        a = sum(i * (i - 1) * b[i] * w ** (i - 2) for i in range(2, 6))
        j = sum(i * (i - 1) * (i - 2) * b[i] * w ** (i - 3) for i in range(3, 6))
        return float(y), float(v), float(a), float(j)

    def end_steps(self) -> tuple[float, float, float]:
        """The steps across the cam's end (360 deg back to 0, the slave's turn on): in ``Y`` [deg], ``dY/dX`` and
        ``d2Y/dX2`` (zero for a cam that repeats smoothly; a linear table's slope steps there as at every
        point)."""
        y_end, v_end, a_end, _ = self.at_end()
        first = self.coefficients[0]
        return float(first[0] + self.slave_turn_deg - y_end), float(first[1] - v_end), float(2 * first[2] - a_end)


def quintic_coefficients(w: np.ndarray, y: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``b_1 .. b_5`` of each interval's quintic with ``y``, ``v``, ``a`` at both ends (module docstring)."""
    d = y[1:] - (y[:-1] + v[:-1] * w + a[:-1] / 2 * w**2)
    e = v[1:] - (v[:-1] + a[:-1] * w)
    f = a[1:] - a[:-1]
    b3 = (20 * d - 8 * e * w + f * w**2) / (2 * w**3)
    b4 = (-30 * d + 14 * e * w - 2 * f * w**2) / (2 * w**4)
    b5 = (12 * d - 6 * e * w + f * w**2) / (2 * w**5)
    return np.column_stack([v[:-1], a[:-1] / 2, b3, b4, b5])


def _periodic_spline(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``b_1 .. b_3`` of the periodic cubic spline through ``(x, y)`` with ``y - x`` periodic: the second
    derivatives ``M_k`` solve ``w_k-1 M_k-1 + 2 (w_k-1 + w_k) M_k + w_k M_k+1 = 6 (s_k - s_k-1)`` round
    the turn (``s_k`` the chords' slopes), a cyclic tridiagonal system."""
    w = np.diff(x)
    s = np.diff(y) / w
    w_before, s_before = np.roll(w, 1), np.roll(s, 1)
    m = _cyclic_tridiagonal(w_before, 2 * (w_before + w), w, 6 * (s - s_before))
    m_next = np.roll(m, -1)
    return np.column_stack([s - w * (2 * m + m_next) / 6, m / 2, (m_next - m) / (6 * w)])


def _cyclic_tridiagonal(lower: np.ndarray, diagonal: np.ndarray, upper: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve ``lower_k x_k-1 + diagonal_k x_k + upper_k x_k+1 = rhs_k`` with indices round a cycle
    (Sherman-Morrison on the Thomas algorithm; the system is diagonally dominant)."""
    n = diagonal.size
    gamma = -diagonal[0]
    main = diagonal.astype(float).copy()
    main[0] -= gamma
    main[-1] -= lower[0] * upper[-1] / gamma
    x = _thomas(lower, main, upper, rhs.astype(float))
    u = np.zeros(n)
    u[0], u[-1] = gamma, upper[-1]
    z = _thomas(lower, main, upper, u)
    factor = (x[0] + lower[0] * x[-1] / gamma) / (1.0 + z[0] + lower[0] * z[-1] / gamma)
    return x - factor * z


def _thomas(lower: np.ndarray, main: np.ndarray, upper: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """The tridiagonal system's solution (``lower[0]`` and ``upper[-1]`` unused)."""
    n = main.size
    c, d = np.zeros(n), np.zeros(n)
    c[0], d[0] = upper[0] / main[0], rhs[0] / main[0]
    for k in range(1, n):
        denominator = main[k] - lower[k] * c[k - 1]
        c[k] = upper[k] / denominator if k < n - 1 else 0.0
        d[k] = (rhs[k] - lower[k] * d[k - 1]) / denominator
    x = np.zeros(n)
    x[-1] = d[-1]
    for k in range(n - 2, -1, -1):
        x[k] = d[k] - c[k] * x[k + 1]
    return x


def realised_profile(cam: Cam, period_s: float, cycle_s: float) -> Profile:
    """The crank's motion [rad, s] when the master turns once in ``period_s`` [s]: the cam's intervals in
    time (a smooth cam), or a linear table as a drive follows it with the controller's cycle ``cycle_s``
    [s] (module docstring)."""
    if cam.interpolation is Interpolation.LINEAR:
        return _linear_as_driven(cam, period_s, cycle_s)
    c = TURN_DEG / period_s
    b = cam.coefficients
    powers = c ** np.arange(6)
    a = DEG * b * powers  # theta(tau) = sum_i a_i tau^i on each interval
    durations = np.diff(cam.master_deg) / c
    segments = tuple(
        Segment(
            f"cam:{k}",
            float(d),
            float(6 * a[k, 3]),
            float(24 * a[k, 4]),
            FIFTH_POWER if a[k, 5] != 0.0 else None,
            float(a[k, 5] * d**4),
            float(d),
        )
        for k, d in enumerate(durations)
    )
    return Profile(segments, float(a[0, 0]), float(a[0, 1]), float(2 * a[0, 2]))


def _linear_as_driven(cam: Cam, period_s: float, cycle_s: float) -> Profile:
    """A linear table's motion as the drive makes it (module docstring): piecewise-constant jerk."""
    c = TURN_DEG / period_s
    x, y = cam.master_deg, cam.slave_deg
    speeds = DEG * np.diff(y) / np.diff(x) * c  # [rad/s] on each interval
    steps = speeds - np.roll(speeds, 1)  # at each point 0 .. n-1 (point 0 is the end too)
    times = x[:-1] / c
    dt = cycle_s
    images = np.concatenate([times - period_s, times, times + period_s])
    image_steps = np.tile(steps, 3)
    near = (images > -2 * dt) & (images < period_s + 2 * dt)
    images, image_steps = images[near], image_steps[near]
    edges = np.concatenate([images - dt, images, images + dt])
    rates = np.concatenate([image_steps, -2 * image_steps, image_steps]) / dt**2
    order = np.argsort(edges, kind="stable")
    edges, rates = edges[order], rates[order]
    before = edges <= 0.0
    jerk0 = float(np.sum(rates[before]))
    inside = (edges > 0.0) & (edges < period_s)
    knots = np.concatenate([[0.0], edges[inside], [period_s]])
    jerks = jerk0 + np.concatenate([[0.0], np.cumsum(rates[inside])])
    middles = (knots[:-1] + knots[1:]) / 2
    nearest = np.sort(images)
    at = np.clip(np.searchsorted(nearest, middles), 1, nearest.size - 1)
    gap = np.minimum(np.abs(middles - nearest[at - 1]), np.abs(middles - nearest[at]))
    jerks = np.where(gap < dt, jerks, 0.0)  # no ramp here: the table's straight line, its sum's round-off left out
    keep = np.diff(knots) > 0.0
    segments = tuple(
        Segment("cam:linear", float(d), float(j), 0.0) for d, j in zip(np.diff(knots)[keep], jerks[keep], strict=True)
    )
    s = -images  # each ramp's local time at t = 0
    ramp = np.abs(s) < dt
    theta0 = DEG * y[0] + float(np.sum(image_steps[ramp] * _ramp_angle(s[ramp], dt)))
    smooth = np.where(s <= -dt, 0.0, np.where(s >= dt, 1.0, _ramp_speed(s, dt)))
    omega0 = speeds[0] + float(np.sum(image_steps * (smooth - (s >= 0.0))))
    alpha0 = float(np.sum(image_steps[ramp] * (dt - np.abs(s[ramp])) / dt**2))
    return Profile(segments, theta0, omega0, alpha0)


def _ramp_speed(s: np.ndarray, dt: float) -> np.ndarray:
    """The share of a speed step reached ``s`` [s] from its point (a smooth step over ``[-dt, dt]``)."""
    return np.where(s <= 0.0, (s + dt) ** 2 / (2 * dt**2), 1.0 - (dt - s) ** 2 / (2 * dt**2))


def _ramp_angle(s: np.ndarray, dt: float) -> np.ndarray:
    """The angle [s per rad/s of step] the smooth step adds to the table's sharp one ``s`` [s] from its point:
    ``(s + dt)^3 / (6 dt^2)`` before, ``(dt - s)^3 / (6 dt^2)`` after (zero outside ``[-dt, dt]``)."""
    return np.where(s <= 0.0, (s + dt) ** 3, (dt - s) ** 3) / (6 * dt**2)
