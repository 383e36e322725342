"""Normalised speed-transition shapes: the non-polynomial-jerk laws in closed form.

A shape is a function ``s(u)`` on ``u in [0, 1]`` with ``s(0) = 0``, ``s(1) = 1`` and zero slope at both
ends, ``s'(0) = s'(1) = 0``. A half of duration ``D`` [s] that changes the crank speed by ``dv`` [rad/s]
follows it as::

    omega(tau) = omega_0 + dv s(u)            u = tau / D
    theta(tau) = theta_0 + omega_0 tau + dv D S(u)        S(u) = integral_0^u s
    alpha(tau) = dv / D s'(u)                 jerk(tau) = dv / D^2 s''(u)

Every shape here is point-symmetric about ``u = 1/2`` (``s(1 - u) = 1 - s(u)``), so ``S(1) = 1/2`` and a
half sweeps ``D (omega_0 + dv / 2)``. ``terms(u)`` returns ``(s, S, s', s'')`` and works on floats,
numpy arrays and CasADi symbols (the parameter of a shape may be a CasADi symbol too).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from press.backend import math_module


@dataclass(frozen=True)
class Quintic:
    """Fifth-order polynomial transition (Liu & Wu, LED die bonder): ``s = 10 u^3 - 15 u^4 + 6 u^5``.

    Zero speed change, acceleration and jerk at both ends, so the jerk is continuous across the
    constant-speed segments and the peak. Peaks: ``s' = 15/8`` at ``u = 1/2``; ``|s''| = 10 / sqrt(3)`` at
    ``u = 1/2 -+ sqrt(3)/6``.
    """

    name: str = "quintic"
    continuity: str = "jerk"

    def terms(self, u: Any) -> tuple[Any, Any, Any, Any]:
        s = u**3 * (10 - 15 * u + 6 * u**2)
        S = u**4 * (2.5 - 3 * u + u**2)
        s1 = 30 * u**2 * (1 - u) ** 2
        s2 = 60 * u * (1 - u) * (1 - 2 * u)
        return s, S, s1, s2

    def peak_rate(self) -> float:
        return 15.0 / 8.0

    def peak_jerk(self) -> float:
        return 10.0 / math.sqrt(3.0)


@dataclass(frozen=True)
class Cycloidal:
    """Cycloidal transition (cam design): acceleration ``s' = 1 - cos(2 pi u)``, a full cosine bump.

    ``s = u - sin(2 pi u) / (2 pi)``; jerk ``s'' = 2 pi sin(2 pi u)`` is zero at both ends, so the jerk is
    continuous. Peaks: ``s' = 2`` at ``u = 1/2``; ``|s''| = 2 pi`` at ``u = 1/4, 3/4``.
    """

    name: str = "cycloidal"
    continuity: str = "jerk"

    def terms(self, u: Any) -> tuple[Any, Any, Any, Any]:
        m = math_module(u)
        w = 2 * math.pi
        s = u - m.sin(w * u) / w
        S = u**2 / 2 - (1 - m.cos(w * u)) / w**2
        return s, S, 1 - m.cos(w * u), w * m.sin(w * u)

    def peak_rate(self) -> float:
        return 2.0

    def peak_jerk(self) -> float:
        return 2 * math.pi


@dataclass(frozen=True)
class Logistic:
    """The logistic S-curve of Li & Chen (bond-wire winder), Eq. 4,
    ``f = f_s + (f_e - f_s) / (1 + exp(-a (x - d) / d))`` on ``x in [0, 2 d]``, with ``a`` the source's
    "flexible" parameter (4-6 there).

    As printed the curve neither starts at ``f_s`` nor ends at ``f_e``, and its slope at the ends is
    ``2 a g(0) (1 - g(0))`` (``g`` the logistic), so joining it to constant speeds would step the speed
    and the acceleration. Here (derived, not in the source) the end slope is taken out and the rest
    rescaled: with ``g(u) = 1 / (1 + exp(-a (2u - 1)))`` and ``c = g'(0)``::

        s(u) = (g(u) - g(0) - c u) / N,    N = g(1) - g(0) - c

    which meets both speeds with zero acceleration at the ends: the acceleration is continuous and
    the jerk steps at the ends by ``g''(0) / N`` (relative to the peak jerk about ``4 e^-a``, 5% at a = 4).
    """

    flexible: Any = 5.0
    name: str = "logistic"
    continuity: str = "acceleration"

    def _g(self, z: Any) -> Any:
        return 1 / (1 + math_module(z).exp(-z))

    def _norm(self) -> tuple[Any, Any, Any]:
        a = self.flexible
        g0 = self._g(-a)
        c = 2 * a * g0 * (1 - g0)
        return g0, c, 1 - 2 * g0 - c

    def terms(self, u: Any) -> tuple[Any, Any, Any, Any]:
        a = self.flexible
        m = math_module(u, a)
        g0, c, N = self._norm()
        z = a * (2 * u - 1)
        g = self._g(z)
        g1 = 2 * a * g * (1 - g)
        g2 = 2 * a * g1 * (1 - 2 * g)
        G = (m.log(1 + m.exp(z)) - m.log(1 + m.exp(-a))) / (2 * a)  # integral_0^u g
        return (g - g0 - c * u) / N, (G - g0 * u - c * u**2 / 2) / N, (g1 - c) / N, g2 / N

    def peak_rate(self) -> Any:
        _, c, N = self._norm()
        return (self.flexible / 2 - c) / N

    def peak_jerk(self) -> Any:
        """Largest ``|s''|``: ``4 a^2 max sigma (1 - sigma) (1 - 2 sigma)`` = ``4 a^2 sqrt(3) / 18`` / N,
        reached inside the half when ``a >= 1.317`` (the bounds of the law keep it there)."""
        _, _, N = self._norm()
        return 4 * self.flexible**2 * math.sqrt(3.0) / 18.0 / N


LOGISTIC_MIN_FLEXIBLE = 1.317  # below it the peak jerk of the logistic lies at the ends of a half
