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
reaches BDC once going down from TDC and leaves it once going up (it may wobble in a dwell at BDC).

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

from planning.tolerances import DEAD_CENTRE_BRACKET_RAD, ROOT_STEP_RAD, SAME_HEIGHT_MM
from press.jets import ORDER

TWO_PI = 2.0 * math.pi
CURVATURE_GRID = 7200  # angles [one turn] on which the generic peak curvature is sought
ROOT_ITERATIONS = 100  # at most (bisection alone would need about 40 from a grid interval)


Jets = tuple[Any, Any, Any, Any]  # h [mm], dh/dtheta [mm/rad], d2h/dtheta2 [mm/rad^2], d3h/dtheta3 [mm/rad^3]


@dataclass(frozen=True)
class Formula:
    """A mechanism's closed form for the numbers ``geometry`` (numbers or symbols) named ``geometry_names``.

    ``evaluate(theta, geometry, order)`` gives, at crank angles ``theta`` [rad from TDC] (numpy arrays or
    CasADi symbols), the slide's height above BDC as a jet of the given order (``press.jets``: the height
    and its derivatives with respect to the crank angle) and the frames: each link's two joints (points of
    jets) and length [mm] by the link's name, the links named ``link_names`` (the drive's link masses); one
    evaluation of the closed form for both. ``jets(theta, geometry)``: the height's first four
    coefficients (a mechanism may give them in a shorter closed form). ``lifted``: the NLPs take the
    derivatives of this mechanism's quantities from its series rather than differentiating its closed form
    for every direction (``planning.solver.lifting``): worth it for a long closed form (a linkage's), not
    for a few operations (the crank-slider's: building the lifted derivatives costs more than its solves
    save). Hashable: an NLP is built once per formula.
    """

    name: str
    geometry_names: tuple[str, ...]
    evaluate: Callable[..., tuple[Any, dict[str, tuple[Any, Any, Any]]]]
    jets: Callable[[Any, Sequence[Any]], Jets]
    link_names: tuple[str, ...]
    lifted: bool = False

    def series(self, theta: Any, geometry: Sequence[Any], order: int = ORDER) -> Any:
        """The slide's height above BDC as a jet of ``order``."""
        return self.evaluate(theta, geometry, order)[0]

    def frames(self, theta: Any, geometry: Sequence[Any], order: int = ORDER) -> dict[str, tuple[Any, Any, Any]]:
        """Each link's two joints (points of jets of ``order``) and length [mm]."""
        return self.evaluate(theta, geometry, order)[1]


class Mechanism(ABC):
    """A press mechanism: the slide height as a function of the crank angle, from TDC.

    Subclasses are frozen dataclasses of their dimensions; they set ``kind`` (the case's name for it) and
    give their :attr:`formula` and its :attr:`geometry`.
    """

    kind: ClassVar[str]
    own_angle_origin: ClassVar[str] = "TDC"  # where the mechanism's own crank angle counts from (reports)
    bars: ClassVar[tuple[tuple[str, ...], ...]] = ()  # the rigid links between joints (:meth:`joints`)
    fixed: ClassVar[tuple[str, ...]] = ()  # the joints fixed to the frame

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

    def frames(self, theta: Any) -> dict[str, tuple[Any, Any, Any]]:
        """Each link's two joints (jets to the third derivative) and length [mm] at ``theta``
        (:attr:`Formula.frames`)."""
        return self.formula.frames(theta, self.geometry)

    @property
    def tdc_own_angle(self) -> float:
        """TDC's crank angle [rad] counted the mechanism's own way (:attr:`own_angle_origin`, in the
        direction of rotation): what its maker's drawings and other programs call it."""
        return 0.0

    @abstractmethod
    def joints(self, theta: Any) -> dict[str, tuple[Any, Any]]:
        """Every joint's position ``(x, y)`` [mm] at crank angles ``theta`` [rad from TDC] (numpy), the crank
        centre at the origin, y up, the slide's joint named ``slide``: what a drawing of the mechanism needs
        (with :attr:`bars` and :attr:`fixed`)."""

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
        while hi - lo > DEAD_CENTRE_BRACKET_RAD:
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
        the first time it reaches ``h`` going down from TDC and the last time it leaves it going up before
        TDC (a slide that wobbles in a dwell near BDC passes some heights more than once). Generic: the
        bracketing interval on a grid of :data:`CURVATURE_GRID` angles, then Newton's method kept inside it
        (bisection where a step would leave it), to round-off; a height asked before is remembered. Raises
        ``ValueError`` outside the stroke."""
        if np.ndim(h) == 0 and float(h) in self._angles_memo:
            return self._angles_memo[float(h)]
        target = self._within_stroke(h).ravel()
        grid, heights = self._height_grid
        level = np.maximum(target, heights.min())[:, None]  # the grid's lowest point is BDC, up to round-off
        first = np.argmax(heights[None, 1:] <= level, axis=1)  # the first interval ending at or below
        at_or_below = heights[None, :-1] <= level
        last = at_or_below.shape[1] - 1 - np.argmax(at_or_below[:, ::-1], axis=1)  # the last starting so
        down = self._root(target, grid[first], grid[first + 1])
        up = self._root(target, grid[last], grid[last + 1])
        out = _shaped(down, h), _shaped(up, h)
        if np.ndim(h) == 0:
            self._angles_memo[float(h)] = out
        return out

    def lowest_on_arc(self, start: float, end: float) -> tuple[float, float]:
        """The slide's lowest position over the crank arc from ``start`` to ``end`` [rad from TDC, ``end >=
        start``, through TDC when ``end`` passes 2 pi]: ``(height [mm], crank angle [rad, 0 ... 2 pi))``. The
        arc's ends and the angles of the height grid inside it (BDC among them); between grid angles a
        local dip of the slide can lie lower by at most ``max|h''| dtheta^2 / 8`` (never above: a height
        found here is one the slide reaches)."""
        grid, heights = self._height_grid
        turns = np.arange(math.floor(start / TWO_PI), math.floor(end / TWO_PI) + 1) * TWO_PI
        unrolled = (grid[None, :] + turns[:, None]).ravel()
        inside = (unrolled > start) & (unrolled < end)
        angles = np.concatenate([[start, end], unrolled[inside]])
        h = np.concatenate(
            [np.asarray(self.height(np.array([start, end])), dtype=float), np.tile(heights, len(turns))[inside]]
        )
        k = int(np.argmin(h))
        return float(h[k]), float(angles[k] % TWO_PI)

    @cached_property
    def _angles_memo(self) -> dict[float, tuple[float, float]]:
        return {}

    @cached_property
    def _height_grid(self) -> tuple[np.ndarray, np.ndarray]:
        """Crank angles over the turn, BDC among them, and the slide's heights there."""
        grid = np.unique(np.concatenate([np.linspace(0.0, TWO_PI, CURVATURE_GRID + 1), [self.bdc_angle]]))
        heights = np.asarray(self.height(grid), dtype=float)
        return grid, heights

    # ---- helpers ----
    def _within_stroke(self, h: Any) -> np.ndarray:
        target = np.asarray(h, dtype=float)
        if np.any(target < -SAME_HEIGHT_MM) or np.any(target > self.stroke + SAME_HEIGHT_MM):
            raise ValueError(f"height {h} mm is outside the stroke 0 ... {self.stroke:g} mm")
        return np.clip(target, 0.0, self.stroke)

    def _root(self, target: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """The crank angle in each bracket ``[lo, hi]`` where the height is ``target`` (the height crosses it
        there): Newton's method on the height's jets, a step that would leave the bracket replaced by
        bisection, the bracket narrowed at every step; until the steps fall below round-off."""
        lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
        rising = self.height(hi) > self.height(lo)
        x = 0.5 * (lo + hi)
        for _ in range(ROOT_ITERATIONS):
            h, d1, _, _ = self.jets(x)
            f = h - target
            above = f > 0
            right_side = above == rising  # the root lies left of x
            hi, lo = np.where(right_side, x, hi), np.where(right_side, lo, x)
            with np.errstate(divide="ignore", invalid="ignore"):
                newton = x - f / d1
            inside = np.isfinite(newton) & (newton > lo) & (newton < hi)
            step = np.where(inside, newton, 0.5 * (lo + hi))
            done = np.abs(step - x) <= ROOT_STEP_RAD
            x = step
            if np.all(done):
                break
        return x


def _shaped(values: np.ndarray, like: Any) -> Any:
    """``values`` as a float when ``like`` is a scalar, else in its shape."""
    return float(values[0]) if np.ndim(like) == 0 else values.reshape(np.shape(like))


def slider_motion(h: Any, d1: Any, d2: Any, d3: Any, omega: Any, alpha: Any, jerk: Any) -> tuple[Any, Any, Any, Any]:
    """The slide's ``(h, v, a, j)`` [mm, mm/s, mm/s^2, mm/s^3] from the height's derivatives with respect to
    the crank angle and the crank's ``omega`` [rad/s], ``alpha`` [rad/s^2], ``jerk`` [rad/s^3]:
    ``v = h' w``, ``a = h'' w^2 + h' alpha``, ``j = h''' w^3 + 3 h'' w alpha + h' jerk``."""
    v = d1 * omega
    a = d2 * omega**2 + d1 * alpha
    j = d3 * omega**3 + 3 * d2 * omega * alpha + d1 * jerk
    return h, v, a, j
