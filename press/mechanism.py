"""What a press mechanism answers: where the slide is over one crank turn, and nothing else.

Conventions (the whole project): crank angle ``theta`` [rad] from top dead centre (TDC = 0),
increasing in the direction of rotation; slide height ``h`` [mm] measured upward from bottom dead
centre (BDC); slide velocity ``dh/dt`` [mm/s], positive upward.

A mechanism is a frozen dataclass of its dimensions [mm]. Its closed form is a :class:`Formula`: a
function of the crank angle and a ``geometry`` vector, so that one formula serves numpy arrays (the
verification, the reports) and CasADi symbols (the NLPs, built once per formula with the geometry as
parameters). A mechanism may choose among formulas by its dimensions (the in-line crank-slider is the
offset one with the offset's terms dropped: fewer operations in every NLP of an in-line press).
Everything else a planner asks of the geometry is derived here once, from that closed form: the slide's
motion from the crank's (chain rule), BDC, the stroke, the crank angles at which the slide passes a
height (going down and going up), the characteristic length and curvature the NLPs scale with. A
mechanism with closed forms for these may override them; the generic ones assume only that the slide
goes down monotonically from TDC to BDC and up again.

Nothing outside ``press/`` knows a link length.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any, ClassVar

import numpy as np

TWO_PI = 2.0 * math.pi
CURVATURE_GRID = 7200  # angles [one turn] on which the generic peak curvature is sought
DEAD_CENTRE_TOL = 1e-13  # [rad] the generic BDC search stops at this bracket width
HEIGHT_TOL = 1e-9  # [mm] a height this far outside the stroke still counts as its end


Jets = tuple[Any, Any, Any, Any]  # h [mm], dh/dtheta [mm/rad], d2h/dtheta2 [mm/rad^2], d3h/dtheta3 [mm/rad^3]


@dataclass(frozen=True)
class Formula:
    """A mechanism's closed form: ``jets(theta, geometry)`` gives the slide height above BDC and its first
    three derivatives at crank angles ``theta`` [rad from TDC] (numpy arrays or CasADi symbols) for the
    numbers ``geometry`` (numbers or symbols) named ``geometry_names``. Hashable: an NLP is built once per
    formula."""

    name: str
    geometry_names: tuple[str, ...]
    jets: Callable[[Any, Sequence[Any]], Jets]


class Mechanism(ABC):
    """A press mechanism: the slide height as a function of the crank angle, from TDC.

    Subclasses are frozen dataclasses of their dimensions; they set ``kind`` (the case's name for it) and
    give their :attr:`formula` and its :attr:`geometry`.
    """

    kind: ClassVar[str]

    # ---- the closed form ----
    @property
    @abstractmethod
    def formula(self) -> Formula:
        """The closed form of this mechanism (it may depend on the dimensions)."""

    @property
    @abstractmethod
    def geometry(self) -> tuple[float, ...]:
        """The numbers the formula reads (lengths [mm], angles [rad]), in its ``geometry_names`` order."""

    def jets(self, theta: Any) -> Jets:
        """``(h [mm], dh/dtheta [mm/rad], d2h/dtheta2 [mm/rad^2], d3h/dtheta3 [mm/rad^3])`` at crank angles
        ``theta`` [rad from TDC]."""
        return self.formula.jets(theta, self.geometry)

    # ---- derived from it ----
    def height(self, theta: Any) -> Any:
        """Slide height above BDC [mm] at crank angle ``theta`` [rad]."""
        return self.jets(theta)[0]

    def derivatives(self, theta: Any) -> tuple[Any, Any, Any]:
        """``(dh/dtheta [mm/rad], d2h/dtheta2 [mm/rad^2], d3h/dtheta3 [mm/rad^3])``."""
        return self.jets(theta)[1:]

    def slider(self, theta: Any, omega: Any, alpha: Any = 0.0, jerk: Any = 0.0) -> tuple[Any, Any, Any, Any]:
        """Slide ``(h [mm], v [mm/s], a [mm/s^2], j [mm/s^3])`` from crank ``theta`` [rad], ``omega``
        [rad/s], ``alpha`` [rad/s^2], ``jerk`` [rad/s^3], upward positive (chain rule)."""
        h, d1, d2, d3 = self.jets(theta)
        return slider_motion(h, d1, d2, d3, omega, alpha, jerk)

    @cached_property
    def bdc_angle(self) -> float:
        """Crank angle of BDC [rad from TDC]: the lowest slide position (generic: the zero of dh/dtheta
        between the lowest point of a grid's neighbours, by bisection)."""
        grid = np.linspace(0.0, TWO_PI, CURVATURE_GRID + 1)
        k = int(np.argmin(self.height(grid)))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, CURVATURE_GRID)]
        while hi - lo > DEAD_CENTRE_TOL:
            mid = 0.5 * (lo + hi)
            if float(self.derivatives(mid)[0]) < 0:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    @cached_property
    def stroke(self) -> float:
        """Slide stroke [mm]: its height at TDC (heights count from BDC)."""
        return float(self.height(0.0))

    @property
    def length_scale(self) -> float:
        """Half the stroke [mm]: the length the NLPs measure the mechanism in (the crank radius of a
        crank-slider)."""
        return 0.5 * self.stroke

    @cached_property
    def peak_curvature(self) -> float:
        """Largest ``|d2h/dtheta2|`` over the turn [mm/rad^2] (at a constant crank speed ``w`` the slide's
        acceleration peaks at ``w^2`` times it), on a grid of :data:`CURVATURE_GRID` angles and both
        dead centres."""
        grid = np.concatenate([np.linspace(0.0, TWO_PI, CURVATURE_GRID, endpoint=False), [self.bdc_angle]])
        return float(np.max(np.abs(self.derivatives(grid)[1])))

    def angles_at_height(self, h: Any) -> tuple[Any, Any]:
        """Crank angles [rad] where the slide is at height ``h`` [mm above BDC]: ``(descending, ascending)``,
        the first in ``[0, BDC]``, the second in ``[BDC, 2 pi]`` (generic: bisection on each monotone
        branch, to round-off). Raises ``ValueError`` outside the stroke."""
        target = self._within_stroke(h)
        bdc = self.bdc_angle
        down = self._bisect(target, 0.0, bdc, falling=True)
        up = self._bisect(target, bdc, TWO_PI, falling=False)
        return _shaped(down, h), _shaped(up, h)

    # ---- helpers ----
    def _within_stroke(self, h: Any) -> np.ndarray:
        target = np.asarray(h, dtype=float)
        if np.any(target < -HEIGHT_TOL) or np.any(target > self.stroke + HEIGHT_TOL):
            raise ValueError(f"height {h} mm is outside the stroke 0 ... {self.stroke:g} mm")
        return np.clip(target, 0.0, self.stroke)

    def _bisect(self, target: np.ndarray, lo: float, hi: float, falling: bool) -> np.ndarray:
        a = np.full(target.shape, lo)
        b = np.full(target.shape, hi)
        for _ in range(80):  # 2 pi / 2^80: far below round-off
            mid = 0.5 * (a + b)
            above = self.height(mid) > target
            go_right = above if falling else ~above
            a, b = np.where(go_right, mid, a), np.where(go_right, b, mid)
        return 0.5 * (a + b)


def _shaped(values: np.ndarray, like: Any) -> Any:
    """``values`` as a float when ``like`` is a scalar."""
    return float(values) if np.ndim(like) == 0 else values


def slider_motion(h: Any, d1: Any, d2: Any, d3: Any, omega: Any, alpha: Any, jerk: Any) -> tuple[Any, Any, Any, Any]:
    """The slide's ``(h, v, a, j)`` [mm, mm/s, mm/s^2, mm/s^3] from the height's derivatives with respect to
    the crank angle and the crank's ``omega`` [rad/s], ``alpha`` [rad/s^2], ``jerk`` [rad/s^3]:
    ``v = h' w``, ``a = h'' w^2 + h' alpha``, ``j = h''' w^3 + 3 h'' w alpha + h' jerk``."""
    v = d1 * omega
    a = d2 * omega**2 + d1 * alpha
    j = d3 * omega**3 + 3 * d2 * omega * alpha + d1 * jerk
    return h, v, a, j
