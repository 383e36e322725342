"""Limits stated once, in canonical form: linear in the crank's acceleration and speed squared.

Most limits of a press cycle are, at each crank angle theta, linear in ``alpha`` (the crank's acceleration)
and ``s = omega^2`` (its speed squared), toppra's canonical form (``toppra/constraint/linear_constraint.py``)::

    lo <= a(theta) alpha + b(theta) omega^2 + c(theta) <= hi                                    (1)

A limit states ``a, b, c`` and ``lo, hi`` once; the parts every algorithm asks for derive from them here:
the NLPs' rows (at their samples, or on the crank's closed-form extremes where the coefficients are
constant), the dense check, the time-optimal bound's rows at both ends of every interval, the highest
constant draw speed (``alpha = 0``), and, for the certified upper bound, rows and envelopes that every motion
within the limit meets. For those, with ``alpha = (1/2) ds/dtheta``, (1) is a first-order linear
inequality in ``s(theta)``; an integrating factor ``mu`` with ``mu' = 2 b mu / a`` turns it into::

    d(mu s)/dtheta = (2 mu / a) (a alpha + b s)      so      mu s |_i^(i+1) = integral (2 mu / a) (form) dtheta

and, where ``2 mu / a`` keeps its sign over an interval, with ``I' = 2 mu / a``:
``|mu_(i+1) s_(i+1) - mu_i s_i| <= hi |I_(i+1) - I_i|`` (``lo = -hi``, ``c = 0``), and over a piece
``[p, q]`` of interval i ``s <= (mu_i s_i + hi |I(q) - I_i|) / min mu`` (from its start) and
``s <= (mu_(i+1) s_(i+1) + hi |I_(i+1) - I(p)|) / min mu`` (from its end). A limit gives ``mu`` and ``I`` in
closed form: the slide's acceleration ``a = h'``, ``b = h''`` has ``mu = h'^2``, ``I = 2 h`` (the slide's own
kinematics, ``d(v^2)/dtheta = 2 h' a_slide``); the crank's ``a = 1, b = 0`` has ``mu = 1``, ``I = 2 theta``. At
a node where ``a = 0`` (a dead centre of the slide) (1) is a bound on ``s`` alone.

A **speed cap** is (1) with ``a = 0``, ``c = 0``: ``|k(theta) omega| <= v`` (``b = k^2``, ``hi = v^2``), with ``k``
the crank's own speed (``k = 1``, or the gear ratio for the motor) or the slide's (``k = h'``) where the limit
applies (the die speed only at or below the die height). Its check, its bounds on the speed squared at the
bound's nodes, its caps over the upper bound's pieces and its draw-speed bound derive from ``k`` and ``v``.

Every expression works on numpy arrays and CasADi symbols alike (``press.backend``).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from planning.model.limits.base import (
    BoundMesh,
    Check,
    Dense,
    Draw,
    Envelope,
    Limit,
    RelaxedMesh,
    Row,
    Transcription,
)
from planning.tolerances import DEAD_CENTRE_SLOPE, LIMIT_REL_TOL


def _form(a: Any, b: Any, alpha: Any, speed2: Any) -> Any:
    """``b speed2 + a alpha`` (``c = 0``), without the terms whose coefficient is the number 0 or 1 times."""
    terms = []
    if not (np.isscalar(b) and b == 0):
        terms.append(speed2 if (np.isscalar(b) and b == 1) else b * speed2)
    if not (np.isscalar(a) and a == 0):
        terms.append(alpha if (np.isscalar(a) and a == 1) else a * alpha)
    out = terms[0]
    for term in terms[1:]:
        out = out + term
    return out


class AccelLimit(Limit):
    """A limit ``|a alpha + b omega^2| <= hi`` over the whole cycle (``c = 0``, ``lo = -hi``), stated by
    :meth:`coefficients` and :meth:`cap` (module docstring); ``parameter``: the NLP parameter that holds
    ``hi`` (backed off by ``backoff``); ``crank_only``: ``a`` and ``b`` are constants (the rows then hold
    the transcription's closed-form extremes of the crank's acceleration, else its samples)."""

    parameter: ClassVar[str]
    row_name: ClassVar[str]  # the name of its block of NLP rows
    crank_only: ClassVar[bool] = False
    shared: ClassVar[bool] = False  # its samples' rows read the transcription's ``accel_shares``

    def coefficients(self, theta: Any, d1: Any, d2: Any) -> tuple[Any, Any]:
        """``(a, b)`` at crank angles ``theta`` with the height's derivatives ``d1`` [mm/rad], ``d2`` [mm/rad^2]."""
        raise NotImplementedError

    def cap(self, case: Any) -> float:
        """``hi``, in the limit's unit."""
        raise NotImplementedError

    def integrating_factor(self, mesh: RelaxedMesh) -> tuple[Any, Any, Any, Any, Any]:
        """``(mu at the nodes, its least over each piece, I at the nodes, I at each piece's start, at its
        end)`` (module docstring)."""
        raise NotImplementedError

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {self.parameter: self.cap(case) * (1 - self.backoff)}

    def rows(self, nlp: Transcription) -> list[Row]:
        if self.crank_only:
            peaks = nlp.accelerations
            lo = -1.0 if peaks.signed else -np.inf
            return [Row(self.row_name, peaks.values / nlp.param(self.parameter), lo, 1.0)]
        a, b = self.coefficients(nlp.theta, nlp.slope, nlp.curvature)
        value = nlp.outside_draw(_form(a, b, nlp.alpha, nlp.omega**2)) / nlp.param(self.parameter)
        if self.shared and nlp.accel_shares is not None:  # each segment's share of the limit
            value = value / nlp.accel_shares
        return [Row(self.row_name, value, -1.0, 1.0, sampled=True)]

    def dense_values(self, dense: Dense) -> np.ndarray:
        """``|a alpha + b omega^2|`` at every sample of ``dense``, in the limit's unit."""
        a, b = self.coefficients(dense.theta, dense.slope, dense.curvature)
        return np.abs(_form(a, b, dense.alpha, dense.omega**2)) * np.ones_like(dense.t)

    def check(self, dense: Dense) -> list[Check]:
        limit = self.cap(dense.case)
        value = self.dense_values(dense)
        check = Check.of(self.id, self.name, float(np.max(value)), limit, self.unit, "max", LIMIT_REL_TOL * limit)
        return [check.located(dense.t, dense.theta, value, limit)]

    def draw_speed_bound(self, draw: Draw) -> float | None:
        """At a constant speed ``alpha = 0``: ``|b| omega^2 <= hi`` (None where ``b`` vanishes: no bound)."""
        _, b = self.coefficients(draw.theta, draw.d1, draw.d2)
        most = float(np.max(np.abs(b)))
        return math.sqrt(self.cap(draw.case) / most) if most > 0 else None

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        bound = self.draw_speed_bound(draw)
        if bound is None:
            return []
        limit = self.cap(draw.case)
        value = limit * (speed / bound) ** 2
        return [Check.of(self.id, self.draw_name, value, limit, self.unit, "max", 0.0)]

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        """(1) at both ends of every interval of constant acceleration (once where the coefficients are
        constants and ``b = 0``: the two ends are one row)."""
        hi = self.cap(mesh.case)
        n = mesh.dtheta.size
        a0, b0 = self.coefficients(mesh.theta[:-1], mesh.d1[:-1], mesh.d2[:-1])
        a1, b1 = self.coefficients(mesh.theta[1:], mesh.d1[1:], mesh.d2[1:])
        start = (_form(a0, b0, mesh.alpha, mesh.s), -hi * np.ones(n), hi * np.ones(n))
        if self.crank_only and np.isscalar(b0) and b0 == 0:
            return [start]
        return [start, (_form(a1, b1, mesh.alpha, mesh.s_next), -hi * np.ones(n), hi * np.ones(n))]

    def relaxed_rows(self, mesh: RelaxedMesh) -> list[tuple[Any, Any, Any]]:
        """``|mu_(i+1) s_(i+1) - mu_i s_i| <= hi |I_(i+1) - I_i|`` on every interval; at a node where ``a = 0``,
        ``|b s| <= hi`` (module docstring)."""
        hi = self.cap(mesh.case)
        mu, _, integral, _, _ = self.integrating_factor(mesh)
        w, w_next = mu[:-1] * mesh.s, mu[1:] * mesh.s_next
        room = hi * np.abs(np.diff(integral))
        rows = [(w_next - w, -room, room)]
        a, b = self.coefficients(mesh.theta[:-1], mesh.d1[:-1], mesh.d2[:-1])
        a = np.broadcast_to(a, mesh.theta[:-1].shape)
        dead = np.flatnonzero(np.abs(a) <= DEAD_CENTRE_SLOPE * np.max(np.abs(a)))
        if dead.size:
            b = np.broadcast_to(b, mesh.theta[:-1].shape)
            rows.append((b[dead] * mesh.s[dead.tolist()], -hi * np.ones(dead.size), hi * np.ones(dead.size)))
        return rows

    def relaxed_envelopes(self, mesh: RelaxedMesh) -> list[Envelope]:
        """Over a piece [p, q] of interval i: ``s <= (mu_i s_i + hi |I(q) - I_i|) / min mu`` and ``s <=
        (mu_(i+1) s_(i+1) + hi |I_(i+1) - I(p)|) / min mu`` (pieces where mu vanishes: none)."""
        hi = self.cap(mesh.case)
        mu, mu_min, integral, at_a, at_b = self.integrating_factor(mesh)
        mu_min = np.broadcast_to(mu_min, mesh.cell.shape)
        moving = mu_min > 0
        m = np.where(moving, mu_min, 1.0)
        start, end = mesh.cell, mesh.cell + 1
        mu = np.broadcast_to(mu, mesh.theta.shape)
        from_start = (mu[start] * mesh.s_a + hi * np.abs(at_b - integral[start])) / m
        from_end = (mu[end] * mesh.s_b + hi * np.abs(integral[end] - at_a)) / m
        return [Envelope(from_start, moving, "start"), Envelope(from_end, moving, "end")]

    @property
    def draw_name(self) -> str:
        """The name of ``pressplan check``'s static check in the draw."""
        return f"{self.name.split(' <=')[0]} during the draw <= {self.field}"


class SpeedCap(Limit):
    """A limit ``|k omega| <= v`` (a speed cap: (1) with ``a = c = 0``), or ``k omega >= v`` (``lower``), where
    it applies; ``k``: the crank's own speed times a constant (:meth:`crank_factor`, not None) or the
    slide's, ``k = h'`` (``crank_factor`` None). ``unit_divisor``: the check's value is ``|k omega|`` divided
    by it (rpm: ``RPM``); :meth:`limit` is ``v`` so divided, as the case gives it."""

    lower: ClassVar[bool] = False
    unit_divisor: ClassVar[float] = 1.0

    def limit(self, case: Any) -> float:
        """The case's value of the limit, in its unit."""
        raise NotImplementedError

    def top(self, case: Any) -> float:
        """``v`` [rad/s times k's unit]: the case's value times :attr:`unit_divisor`."""
        return self.limit(case) * self.unit_divisor

    def crank_factor(self, case: Any) -> float | None:
        """The constant ``k`` of a cap on the crank's own speed; None for the slide's (``k = h'``)."""
        return None

    def where(self, case: Any, h: np.ndarray, bound: bool = False) -> np.ndarray | None:
        """The samples (heights ``h`` [mm]) where the limit applies; None: everywhere. ``bound``: at the bound's
        nodes (a crossing of the domain's edge counts)."""
        return None

    def _k(self, case: Any, d1: np.ndarray) -> Any:
        factor = self.crank_factor(case)
        return d1 if factor is None else factor

    def check(self, dense: Dense) -> list[Check]:
        case = dense.case
        limit = self.limit(case)
        k = self._k(case, dense.slope)
        values = k * dense.omega if self.lower or (np.isscalar(k) and k > 0) else np.abs(k * dense.omega)
        values = values * np.ones_like(dense.t) if np.isscalar(values) else values
        inside = self.where(case, dense.h)
        t, theta = dense.t, dense.theta
        if inside is not None:
            values, t, theta = values[inside], t[inside], theta[inside]
        extreme = (np.min(values) if self.lower else np.max(values)) if values.size else 0.0
        kind, value = "min" if self.lower else "max", float(extreme) / self.unit_divisor
        check = Check.of(self.id, self.name, value, limit, self.unit, kind, LIMIT_REL_TOL * limit)
        return [check.located(t, theta, values / self.unit_divisor, limit)]

    def bound_speeds(self, mesh: BoundMesh) -> tuple[np.ndarray | None, np.ndarray | None]:
        """``(v / |k|)^2`` at the nodes where the limit applies and ``k`` is not zero."""
        v = self.top(mesh.case)
        factor = self.crank_factor(mesh.case)
        n = mesh.dtheta.size
        if factor is not None and self.where(mesh.case, mesh.h[:-1], bound=True) is None:
            value = np.full(n, (v / factor) ** 2)
            return (value, None) if self.lower else (None, value)
        k = np.abs(np.broadcast_to(self._k(mesh.case, mesh.d1[:-1]), (n,)))
        inside = self.where(mesh.case, mesh.h[:-1], bound=True)
        moving = (inside if inside is not None else np.ones(n, dtype=bool)) & (k > 0)
        upper = np.full(n, np.inf)
        upper[moving] = (v / k[moving]) ** 2
        return None, upper

    def relaxed_caps(self, mesh: RelaxedMesh) -> np.ndarray | None:
        """``v^2 / min k^2`` over each piece wholly where the limit applies (a lower cap: none)."""
        if self.lower:
            return None
        v = self.top(mesh.case)
        factor = self.crank_factor(mesh.case)
        if factor is not None:
            return np.full(mesh.cell.size, (v / factor) ** 2)
        inside = self.where(mesh.case, np.maximum(mesh.h_a, mesh.h_b))
        moving = (inside if inside is not None else np.ones(mesh.cell.size, dtype=bool)) & (mesh.slope2_min > 0)
        caps = np.full(mesh.cell.size, np.inf)
        caps[moving] = v**2 / mesh.slope2_min[moving]
        return caps

    def draw_speed_bound(self, draw: Draw) -> float | None:
        """The highest constant draw speed: ``v / max |k|`` over the draw (a lower cap: none)."""
        if self.lower:
            return None
        factor = self.crank_factor(draw.case)
        if factor is not None:
            return self.top(draw.case) / factor
        inside = self.where(draw.case, draw.h)
        slopes = np.abs(draw.d1 if inside is None else draw.d1[inside])
        slope = float(np.max(slopes)) if slopes.size else 0.0
        return self.top(draw.case) / slope if slope > 0 else np.inf
