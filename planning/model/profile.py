"""Piecewise motion profiles of the crank, evaluated in closed form.

A profile is a start state ``(theta0 [rad], omega0 [rad/s], alpha0 [rad/s^2])`` and a list of
segments, each a duration ``T`` [s] with a jerk that is linear in the local time ``tau`` [s]::

    j(tau) = j0 + j1 tau                    [rad/s^3]
    alpha(tau) = alpha0 + j0 tau + j1 tau^2 / 2
    omega(tau) = omega0 + alpha0 tau + j0 tau^2 / 2 + j1 tau^3 / 6
    theta(tau) = theta0 + omega0 tau + alpha0 tau^2 / 2 + j0 tau^3 / 6 + j1 tau^4 / 24

plus, for the laws that are not piecewise polynomial in jerk (``planning.model.laws.shapes``), a shape
term: a speed change ``dv`` [rad/s] along a normalised shape ``s(u)`` over a span ``D`` [s], of which
the segment covers ``u`` from ``u0`` to ``u0 + T / D`` (``u0 > 0`` only for a piece split off a half).
The shape term is added as its remainder beyond the start state, so the start state is always the
full state and the two parts superpose::

    omega += dv (s(u) - s(u0) - s'(u0) du),   du = tau / D,  u = u0 + du
    theta += dv D (S(u) - S(u0) - s(u0) du - s'(u0) du^2 / 2)
    alpha += dv / D (s'(u) - s'(u0)),         jerk += dv / D^2 s''(u)

Every motion law of the project is such a list, so one evaluator serves the optimizer (with CasADi
symbols), the plan and the verification (with numpy arrays). The state is continuous at every knot by
construction.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np

from planning.tolerances import ANGLE_ROUND_OFF_RAD, SAME_TIME_S

MAX_STEP_S = 1e-3  # [s] dense grid step (at most), for cycles up to MAX_SAMPLES * MAX_STEP_S = 1000 s
MAX_SAMPLES = 1_000_000  # grid points at most: a longer cycle gets a uniform step of period / MAX_SAMPLES


class Segment(NamedTuple):
    """One segment: ``name``, ``duration`` [s], jerk ``j0`` [rad/s^3] + ``j1`` [rad/s^4] * tau, and an
    optional ``shape`` term: speed change ``dv`` [rad/s] over ``span`` [s] from ``u0`` (see above)."""

    name: str
    duration: Any
    j0: Any
    j1: Any
    shape: Any = None
    dv: Any = 0.0
    span: Any = None
    u0: float = 0.0


def shape_segment(name: str, duration: Any, dv: Any, shape: Any) -> Segment:
    """A whole shaped half: speed change ``dv`` [rad/s] over ``duration`` [s] along ``shape``."""
    return Segment(name, duration, 0.0, 0.0, shape, dv, duration, 0.0)


def shape_part(seg: Segment, tau: Any) -> tuple[Any, Any, Any, Any]:
    """The shape term of ``seg`` after ``tau`` [s]: ``(dtheta, domega, dalpha, jerk)``, zero without one."""
    if seg.shape is None:
        return 0.0, 0.0, 0.0, 0.0
    D, dv = seg.span, seg.dv
    du = tau / D
    s, S, s1, s2 = seg.shape.terms(seg.u0 + du)
    if isinstance(seg.u0, float) and seg.u0 == 0.0:  # every shape starts at rest: s = S = s' = 0
        return dv * D * S, dv * s, dv / D * s1, dv / D**2 * s2
    a, A, a1, _ = seg.shape.terms(seg.u0)
    return (
        dv * D * (S - A - a * du - a1 * du**2 / 2),
        dv * (s - a - a1 * du),
        dv / D * (s1 - a1),
        dv / D**2 * s2,
    )


def advance_segment(seg: Segment, theta0: Any, omega0: Any, alpha0: Any, tau: Any) -> tuple[Any, Any, Any, Any]:
    """State ``(theta, omega, alpha, jerk)`` after ``tau`` [s] inside ``seg`` from the given start state."""
    th, om, al, je = advance(theta0, omega0, alpha0, seg.j0, seg.j1, tau)
    dth, dom, dal, dje = shape_part(seg, tau)
    return th + dth, om + dom, al + dal, je + dje


def split_segment(seg: Segment, tau: float) -> tuple[Segment, Segment]:
    """``seg`` (numeric) cut ``tau`` [s] after its start into two segments that together move the same."""
    first = seg._replace(duration=tau)
    span = seg.span if seg.span is not None else 1.0
    second = seg._replace(
        duration=float(seg.duration) - tau,
        j0=seg.j0 + seg.j1 * tau,
        u0=seg.u0 + (tau / span if seg.shape is not None else 0.0),
    )
    return first, second


def advance(theta0: Any, omega0: Any, alpha0: Any, j0: Any, j1: Any, tau: Any) -> tuple[Any, Any, Any, Any]:
    """State ``(theta [rad], omega [rad/s], alpha [rad/s^2], jerk [rad/s^3])`` after ``tau`` [s]
    inside a segment with jerk ``j0 + j1 tau`` that starts at ``(theta0, omega0, alpha0)``."""
    jerk = j0 + j1 * tau
    alpha = alpha0 + j0 * tau + j1 * tau**2 / 2
    omega = omega0 + alpha0 * tau + j0 * tau**2 / 2 + j1 * tau**3 / 6
    theta = theta0 + omega0 * tau + alpha0 * tau**2 / 2 + j0 * tau**3 / 6 + j1 * tau**4 / 24
    return theta, omega, alpha, jerk


def knot_states(theta0: Any, omega0: Any, alpha0: Any, segments: Sequence[Segment]) -> list[tuple[Any, Any, Any]]:
    """States ``(theta, omega, alpha)`` at the start of every segment and at the end of the last."""
    states = [(theta0, omega0, alpha0)]
    for seg in segments:
        th, om, al, _ = advance_segment(seg, *states[-1], seg.duration)
        states.append((th, om, al))
    return states


@dataclass(frozen=True)
class Profile:
    """A numeric piecewise profile starting at time ``t0`` [s].

    ``segments`` hold plain floats; ``theta0`` [rad], ``omega0`` [rad/s], ``alpha0`` [rad/s^2].
    """

    segments: tuple[Segment, ...]
    theta0: float
    omega0: float
    alpha0: float = 0.0
    t0: float = 0.0

    @property
    def durations(self) -> np.ndarray:
        """Segment durations [s]."""
        return np.array([float(s.duration) for s in self.segments])

    @property
    def knot_times(self) -> np.ndarray:
        """Times [s] of the segment boundaries, ``len(segments) + 1`` values."""
        return self.t0 + np.concatenate([[0.0], np.cumsum(self.durations)])

    @property
    def duration(self) -> float:
        """Total duration [s]."""
        return float(self.durations.sum())

    def knots(self) -> np.ndarray:
        """Knot states as an array of shape ``(n + 1, 3)``: theta [rad], omega [rad/s], alpha [rad/s^2]
        (computed once per profile; a copy is returned)."""
        return self._knots.copy()

    @cached_property
    def _knots(self) -> np.ndarray:
        return np.array(knot_states(self.theta0, self.omega0, self.alpha0, self.segments), dtype=float)

    def at_time(self, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(theta [rad], omega [rad/s], alpha [rad/s^2], jerk [rad/s^3])`` at times ``t`` [s].

        Vectorised; times outside the profile are extrapolated from the first or last segment.
        At a knot the later segment is used (jerk is right-continuous).
        """
        t = np.asarray(t, dtype=float)
        knots = self.knots()
        tk = self.knot_times
        idx = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, len(self.segments) - 1)
        j0 = np.array([float(s.j0) for s in self.segments])[idx]
        j1 = np.array([float(s.j1) for s in self.segments])[idx]
        th0, om0, al0 = knots[idx, 0], knots[idx, 1], knots[idx, 2]
        tau = t - tk[idx]
        out = [np.array(v, dtype=float) for v in np.broadcast_arrays(*advance(th0, om0, al0, j0, j1, tau))]
        for k, seg in enumerate(self.segments):
            if seg.shape is not None:
                mask = idx == k
                for v, d in zip(out, shape_part(seg, tau[mask]), strict=True):
                    v[mask] += d
        return tuple(out)

    def time_at_angle(self, theta: float) -> float:
        """First time [s] at which the (increasing) crank angle reaches ``theta`` [rad].

        Bracketed by the knots, then refined by Newton steps on the closed form (bisection fallback).
        """
        knots = self.knots()
        tk = self.knot_times
        if theta < knots[0, 0] or theta > knots[-1, 0]:
            raise ValueError("angle outside the profile")
        k = int(np.clip(np.searchsorted(knots[:, 0], theta, side="right") - 1, 0, len(self.segments) - 1))
        if k > 0 and knots[k - 1, 0] == knots[k, 0] and abs(knots[k, 0] - theta) <= ANGLE_ROUND_OFF_RAD:
            while k > 0 and knots[k - 1, 0] == knots[k, 0]:  # a standstill at theta: where it starts
                k -= 1
            return float(tk[k])
        lo, hi = 0.0, float(self.segments[k].duration)
        seg = self.segments[k]
        tau = 0.5 * (lo + hi)
        for _ in range(100):
            th, om, _, _ = advance_segment(seg, *knots[k], tau)
            err = th - theta
            if abs(err) < ANGLE_ROUND_OFF_RAD:
                break
            if err > 0:
                hi = tau
            else:
                lo = tau
            step = tau - err / om if om > 0 else 0.5 * (lo + hi)
            tau = step if lo < step < hi else 0.5 * (lo + hi)
        return float(tk[k] + tau)


def dense_times(period: float, knot_times: np.ndarray, max_step: float = MAX_STEP_S) -> np.ndarray:
    """A uniform grid over ``[0, period]`` [s] with step <= ``max_step`` (at most :data:`MAX_SAMPLES`
    points: a coarser uniform step for a cycle longer than 1000 s), merged with the knots: the grid of
    the dense verification and of the drive's peaks."""
    return sample_times(period, knot_times, max_step)[0]


def sample_times(period: float, knot_times: np.ndarray, max_step: float = MAX_STEP_S) -> tuple[np.ndarray, np.ndarray]:
    """:func:`dense_times` and, for each point of its uniform grid, the index of that point among them
    (a grid point within :data:`SAME_TIME_S` of a knot is that knot): ``(times [s], uniform indices)``."""
    n = min(int(math.ceil(period / max_step)), MAX_SAMPLES)
    grid = np.linspace(0.0, period, n + 1)
    knots = np.asarray(knot_times, dtype=float)
    # a grid point on a knot up to round-off is the knot: the grid does not hang on the last digits
    near = np.zeros(grid.size, dtype=bool)
    at = np.searchsorted(grid, knots)
    for j in (np.clip(at - 1, 0, n), np.clip(at, 0, n)):
        near[j[np.abs(grid[j] - knots) <= SAME_TIME_S]] = True
    near[[0, n]] = False  # the ends stay
    times = np.unique(np.concatenate([grid[~near], knots]))
    right = np.clip(np.searchsorted(times, grid), 0, times.size - 1)
    left = np.clip(right - 1, 0, times.size - 1)
    uniform = np.where(np.abs(times[left] - grid) < np.abs(times[right] - grid), left, right)
    return times, uniform


def max_abs_jerk(prof: Profile) -> float:
    """Largest |crank jerk| [rad/s^3] of a profile: at a segment's ends where the jerk is linear; for a
    shaped segment the closed-form peak of its whole half (``|dv| / D^2`` times the shape's peak), which a
    piece cut off at TDC may not reach, so the figure errs on the safe side; a cam's fifth power
    (``planning.model.cam.FifthPower``) gives its segment's exact peak."""
    out = 0.0
    for s in prof.segments:
        exact = getattr(s.shape, "segment_peak_jerk", None)  # a shape that knows its segment's peak exactly
        if exact is not None:
            out = max(out, exact(s))
            continue
        j = max(abs(float(s.j0)), abs(float(s.j0) + float(s.j1) * float(s.duration)))
        if s.shape is not None:
            j += abs(float(s.dv)) / float(s.span) ** 2 * float(s.shape.peak_jerk())
        out = max(out, j)
    return out
