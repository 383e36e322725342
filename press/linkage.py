"""Link-drive and knuckle-joint presses: the slide driven through a four-bar, its closed form by circle
intersections.

Frame: the crank (eccentric) turns about the origin, x to the right, y up; the crank pin is at
``a (cos phi, sin phi)`` for the oracles' crank angle ``phi`` (counter-clockwise from +x, as in
``mechpress`` and ``presslink``; the crank turns the way ``phi`` grows). A joint that closes a loop is
the intersection of two circles (``press.jets.circle_intersection``), always on the same side (the
oracles' assembly mode); the slide moves on a vertical line and hangs below the joint that drives it.
The project's crank angle ``theta`` counts from TDC, ``phi = theta + phi_TDC``; the height counts from
BDC, ``h = y_slide - y_BDC``; ``phi_TDC`` (the slide's highest point) and ``y_BDC`` are found once per
geometry by a scan and bisection on the closed form's derivative (:data:`DEAD_CENTRE_BRACKET_RAD`).

- **Link drive** (``mechpress.ld.LD``; a six-bar): crank ``a``; the ternary link on the crank pin A, its
  side ``b`` to the rocker joint B and its side ``m`` to the rod joint C, the angle ``tht`` between them
  (C turned ``tht`` counter-clockwise from B about A); the rocker ``c`` pivoting at ``(-d, -f)``; the
  rod ``g`` from C to the slide on the line ``x = h``.
- **Knuckle joint** (``presslink``'s ``ModularKnuckleJoint``, ``f = c``): crank ``a``; the rod ``b`` from
  the crank pin to the knuckle K; the upper link (rocker) ``c`` pivoting at ``(d, e)``; the main rod
  ``g`` from K to the slide on the line ``x = d + h``.

Every function works on numpy arrays and CasADi symbols alike: the NLPs hold the dimensions as
parameters. A geometry whose loops do not close at some crank angle, or whose slide does not go down
once and up once per turn, cannot be built (:class:`LinkageError` names the dimensions and the angle).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from functools import cached_property
from typing import Any, ClassVar

import numpy as np

from planning.tolerances import DEAD_CENTRE_BRACKET_RAD, MIN_LOOP_ROOM
from press.jets import ORDER, Jet, Point, circle_intersection
from press.mechanism import Formula, Jets, Mechanism

DWELL_SHARE = 5e-3  # a slide may turn back within this share of the stroke above BDC (a knuckle joint's dwell)
SIDE = -1.0  # the closing joint lies to the right of the line from the crank pin to the rocker pivot
SCAN = 7200  # crank angles of the scans (dead centres, assembly, one stroke per turn)
MEMO_SIZE = 4  # arrays of crank angles whose evaluation a linkage remembers
MEMO_MIN_SIZE = 64  # smaller arrays are evaluated again (cheaper than a look-up)


class LinkageError(ValueError):
    """A geometry that cannot be a press mechanism: ``message`` (one line), the dimensions it ``names`` (the
    mechanism's attribute names, the likeliest culprit first; none: all of them together) and the crank
    ``angle_deg`` [deg from the oracles' +x] where it fails."""

    def __init__(self, message: str, names: tuple[str, ...] = (), angle_deg: float | None = None):
        super().__init__(message)
        self.names = names
        self.angle_deg = angle_deg


Chain = Callable[[Jet, Sequence[Any]], tuple[dict[str, Point], list[tuple[Jet, tuple[str, ...]]]]]


def link_drive_chain(phi: Jet, g: Sequence[Any]) -> tuple[dict[str, Point], list[tuple[Jet, tuple[str, ...]]]]:
    """The link drive's joints at crank angle ``phi`` (a jet, from +x) for the dimensions
    ``g = (a, b, c, d, f, cos tht, sin tht, m, g, h)`` [mm]; and each loop's closing room with the dimensions
    it depends on."""
    a, b, c, d, f, ct, st, m, rod, h = g[:10]
    crank = Point(phi.cos() * a, phi.sin() * a)
    pivot = Point(-d, -f)
    rocker, room = circle_intersection(crank, b, pivot, c, SIDE)
    joint = crank + (rocker - crank).turned(ct, st).scaled(m / b)
    reach = (joint.x - h).square() * -1.0 + rod**2
    slide = Point(h, joint.y - reach.sqrt())
    points = {"pivot": pivot, "crank_pin": crank, "rocker_joint": rocker, "rod_joint": joint, "slide": slide}
    rooms = [
        (room, ("rocker", "ternary_rocker_side", "rocker_pivot_x", "rocker_pivot_y", "crank_radius")),
        (reach / rod**2, ("rod_length", "slide_offset")),
    ]
    return points, rooms


def knuckle_joint_chain(phi: Jet, g: Sequence[Any]) -> tuple[dict[str, Point], list[tuple[Jet, tuple[str, ...]]]]:
    """The knuckle joint's joints at crank angle ``phi`` for ``g = (a, b, c, d, e, g, h)`` [mm]; and each
    loop's closing room."""
    a, b, c, d, e, main, h = g[:7]
    crank = Point(phi.cos() * a, phi.sin() * a)
    pivot = Point(d, e)
    knuckle, room = circle_intersection(crank, b, pivot, c, SIDE)
    reach = (knuckle.x - (d + h)).square() * -1.0 + main**2
    slide = Point(d + h, knuckle.y - reach.sqrt())
    points = {"pivot": pivot, "crank_pin": crank, "knuckle": knuckle, "slide": slide}
    rooms = [
        (room, ("rocker", "rod_length", "rocker_pivot_x", "rocker_pivot_y", "crank_radius")),
        (reach / main**2, ("main_rod", "slide_offset")),
    ]
    return points, rooms


def _evaluate_of(chain: Chain, dimensions: int, links: dict[str, tuple[str, str, int]]) -> Callable:
    """The formula's evaluation (``press.mechanism.Formula``): the slide's height above BDC at ``theta`` from
    TDC as a jet of ``order`` and each link's two joints and length (an entry of the geometry), the
    geometry being the dimensions, then ``phi_TDC`` and ``y_BDC``."""

    def evaluate(theta: Any, geometry: Sequence[Any], order: int = ORDER) -> tuple[Jet, dict]:
        phase, bottom = geometry[dimensions], geometry[dimensions + 1]
        points, _ = chain(Jet.angle(theta + phase, order), geometry)
        frames = {name: (points[a], points[b], geometry[k]) for name, (a, b, k) in links.items()}
        return points["slide"].y - bottom, frames

    return evaluate


def _jets_of(evaluate: Callable) -> Callable[[Any, Sequence[Any]], Jets]:
    """The formula's jets: the height's first four coefficients."""

    def jets(theta: Any, geometry: Sequence[Any]) -> Jets:
        return evaluate(theta, geometry, 3)[0].c

    return jets


# each link: its first and second joint (its axis) and the index of its length in the geometry
LINK_DRIVE_LINKS = {
    "ternary": ("crank_pin", "rocker_joint", 1),
    "rocker": ("pivot", "rocker_joint", 2),
    "rod": ("rod_joint", "slide", 8),
}
KNUCKLE_JOINT_LINKS = {
    "rod": ("crank_pin", "knuckle", 1),
    "rocker": ("pivot", "knuckle", 2),
    "main_rod": ("knuckle", "slide", 5),
}
LINK_DRIVE_DIMENSIONS = (
    "crank_radius",
    "ternary_rocker_side",
    "rocker",
    "rocker_pivot_x",
    "rocker_pivot_y",
    "ternary_angle_cos",
    "ternary_angle_sin",
    "ternary_rod_side",
    "rod_length",
    "slide_offset",
)
KNUCKLE_JOINT_DIMENSIONS = (
    "crank_radius",
    "rod_length",
    "rocker",
    "rocker_pivot_x",
    "rocker_pivot_y",
    "main_rod",
    "slide_offset",
)
_LINK_DRIVE = _evaluate_of(link_drive_chain, len(LINK_DRIVE_DIMENSIONS), LINK_DRIVE_LINKS)
_KNUCKLE_JOINT = _evaluate_of(knuckle_joint_chain, len(KNUCKLE_JOINT_DIMENSIONS), KNUCKLE_JOINT_LINKS)
LINK_DRIVE = Formula(
    "link drive",
    (*LINK_DRIVE_DIMENSIONS, "tdc_phase", "bdc_level"),
    _LINK_DRIVE,
    _jets_of(_LINK_DRIVE),
    tuple(LINK_DRIVE_LINKS),
    lifted=True,
)
KNUCKLE_JOINT = Formula(
    "knuckle joint",
    (*KNUCKLE_JOINT_DIMENSIONS, "tdc_phase", "bdc_level"),
    _KNUCKLE_JOINT,
    _jets_of(_KNUCKLE_JOINT),
    tuple(KNUCKLE_JOINT_LINKS),
    lifted=True,
)


class Linkage(Mechanism):
    """A mechanism whose slide is driven through a chain of circle intersections (module docstring).
    Subclasses give ``chain``, ``formula_of`` (their :class:`~press.mechanism.Formula`), ``links`` (each
    link's joints: ``name -> (first joint, second joint, index of its length)``, the link's axis from the
    first to the second) and, when the chain reads more than the fields in order, :attr:`dimensions`."""

    chain: ClassVar[Chain]
    formula_of: ClassVar[Formula]
    links: ClassVar[dict[str, tuple[str, str, int]]]

    def __post_init__(self) -> None:
        self._dead_centres  # noqa: B018 - a geometry that cannot be a press is refused at once

    @property
    def dimensions(self) -> tuple[float, ...]:
        """The numbers the chain reads (before ``phi_TDC`` and ``y_BDC``): the dataclass fields in order,
        unless a subclass says otherwise."""
        return tuple(getattr(self, f.name) for f in fields(self))

    @property
    def formula(self) -> Formula:
        return self.formula_of

    def jets(self, theta: Any) -> Any:
        return self._evaluated(theta)[0].c

    def frames(self, theta: Any) -> dict[str, tuple[Any, Any, Any]]:
        return self._evaluated(theta)[1]

    def _evaluated(self, theta: Any) -> tuple[Jet, dict]:
        """The closed form at ``theta`` (third order), remembered for the last few arrays of angles: the
        verification, the drive's state and the reports ask for the same dense grid in turn."""
        if not isinstance(theta, np.ndarray) or theta.size < MEMO_MIN_SIZE:
            return self.formula.evaluate(theta, self.geometry)
        key = (theta.shape, hash(theta.tobytes()))
        memo = self._memo
        if key not in memo:
            if len(memo) >= MEMO_SIZE:
                memo.pop(next(iter(memo)))
            memo[key] = self.formula.evaluate(theta.copy(), self.geometry)
        return memo[key]

    @cached_property
    def _memo(self) -> dict:
        return {}

    @property
    def geometry(self) -> tuple[float, ...]:
        phase, _, bottom, _ = self._dead_centres
        return (*self.dimensions, phase, bottom)

    def points(self, theta: Any) -> dict[str, Point]:
        """Every joint (jets in the crank angle) at ``theta`` [rad from TDC]."""
        phase = self._dead_centres[0]
        theta = np.asarray(theta, dtype=float) if not hasattr(theta, "shape") else theta
        return type(self).chain(Jet.angle(theta + phase), self.dimensions)[0]

    def joints(self, theta: Any) -> dict[str, tuple[Any, Any]]:
        theta = np.asarray(theta, dtype=float)
        zero = np.zeros_like(theta)
        out = {"crank centre": (zero, zero)}
        for name, point in self.points(theta).items():
            out[name.replace("_", " ")] = (point.x.value + zero, point.y.value + zero)
        return out

    @cached_property
    def _dead_centres(self) -> tuple[float, float, float, float]:
        """``(phi_TDC, y_TDC, y_BDC, phi_BDC)``: the oracles' crank angle of the slide's highest point [rad],
        the slide's highest and lowest positions [mm] and the crank angle of the lowest [rad]. Raises
        :class:`LinkageError` where the rocker's pivot lies within the crank's reach, where a loop cannot close
        (its room below :data:`MIN_LOOP_ROOM`) and where the slide turns back anywhere but in a dwell at BDC
        (within :data:`DWELL_SHARE` of the stroke above it: a knuckle joint may wobble there)."""
        self._check_pivot()
        phi = np.linspace(0.0, 2 * math.pi, SCAN, endpoint=False)
        with np.errstate(invalid="ignore"):  # a loop that cannot close: NaN there, refused below
            points, rooms = type(self).chain(Jet.angle(phi), self.dimensions)
        for room, names in rooms:
            k = int(np.argmin(room.value))
            if not room.value[k] > MIN_LOOP_ROOM:
                raise LinkageError(
                    f"the links cannot close at crank angle {math.degrees(phi[k]):.1f} deg (counted from +x, "
                    "counter-clockwise)",
                    names,
                    math.degrees(phi[k]),
                )
        y = points["slide"].y
        top, bottom = int(np.argmax(y.value)), int(np.argmin(y.value))
        stroke = float(y.value[top] - y.value[bottom])
        slope = y.c[1]
        turning = np.flatnonzero(np.sign(slope) != np.sign(np.roll(slope, -1)))
        for k in turning:
            rise = float(max(y.value[k], y.value[(k + 1) % SCAN]) - y.value[bottom])
            if min(abs(k - top), SCAN - abs(k - top)) > 1 and rise > DWELL_SHARE * stroke:
                raise LinkageError(
                    f"the slide turns back at crank angle {math.degrees(phi[k]):.1f} deg (counted from +x), "
                    f"{rise:.1f} mm above its lowest point: a press's slide goes down once and up once per turn",
                    (),  # the dimensions together
                    math.degrees(phi[k]),
                )
        phase = self._stationary(phi[top], falling_after=True)
        lowest = self._stationary(phi[bottom], falling_after=False)
        y_top = float(self._slide_y(phase).value)
        y_bottom = float(self._slide_y(lowest).value)
        return phase % (2 * math.pi), y_top, y_bottom, lowest % (2 * math.pi)

    def _check_pivot(self) -> None:
        """The rocker's pivot must lie outside the circle of the crank pin (else the rocker's joint meets
        the crank's path: the loop cannot close for a whole turn)."""
        with np.errstate(invalid="ignore"):  # only the pivot is read
            pivot = type(self).chain(Jet.angle(0.0), self.dimensions)[0]["pivot"]
        if math.hypot(float(pivot.x.value), float(pivot.y.value)) <= self.crank_radius:
            raise LinkageError(
                "the rocker's pivot lies inside the crank circle (its distance from the crank centre is at most "
                "the crank radius)",
                ("rocker_pivot_x", "rocker_pivot_y", "crank_radius"),
            )

    own_angle_origin = "+x, counter-clockwise"

    @property
    def tdc_own_angle(self) -> float:
        """The oracles' crank angle of TDC [rad from +x]."""
        return self._dead_centres[0]

    @property
    def bdc_angle(self) -> float:
        """Crank angle of BDC [rad from TDC]: the slide's lowest point (the zero of the height's derivative
        next to the scan's lowest point, by bisection)."""
        phase, lowest = self._dead_centres[0], self._dead_centres[3]
        return (lowest - phase) % (2 * math.pi)

    def _slide_y(self, phi: float) -> Jet:
        return type(self).chain(Jet.angle(np.asarray(phi)), self.dimensions)[0]["slide"].y

    def _stationary(self, phi0: float, falling_after: bool) -> float:
        """The zero of dy/dphi next to the scan's extreme ``phi0`` (bisection)."""
        step = 2 * math.pi / SCAN
        lo, hi = phi0 - step, phi0 + step
        while hi - lo > DEAD_CENTRE_BRACKET_RAD:
            mid = 0.5 * (lo + hi)
            slope = float(self._slide_y(mid).c[1])
            if (slope > 0) == falling_after:  # still rising towards TDC (or falling towards BDC)
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    @property
    def stroke(self) -> float:
        _, top, bottom, _ = self._dead_centres
        return top - bottom


@dataclass(frozen=True)
class LinkDrive(Linkage):
    """The six-bar link drive of ``mechpress.ld.LD`` (module docstring); lengths [mm], ``ternary_angle``
    [rad]."""

    crank_radius: float
    ternary_rocker_side: float
    rocker: float
    rocker_pivot_x: float
    rocker_pivot_y: float
    ternary_angle: float
    ternary_rod_side: float
    rod_length: float
    slide_offset: float = 0.0

    kind = "link-drive"
    bars = (
        ("crank centre", "crank pin"),
        ("crank pin", "rocker joint", "rod joint"),  # the ternary link, a triangle
        ("pivot", "rocker joint"),
        ("rod joint", "slide"),
    )
    fixed = ("crank centre", "pivot")
    chain = staticmethod(link_drive_chain)
    formula_of = LINK_DRIVE
    links = LINK_DRIVE_LINKS

    @property
    def dimensions(self) -> tuple[float, ...]:
        """The fields in order, the ternary angle as its cosine and sine."""
        return (
            self.crank_radius,
            self.ternary_rocker_side,
            self.rocker,
            self.rocker_pivot_x,
            self.rocker_pivot_y,
            math.cos(self.ternary_angle),
            math.sin(self.ternary_angle),
            self.ternary_rod_side,
            self.rod_length,
            self.slide_offset,
        )


@dataclass(frozen=True)
class KnuckleJoint(Linkage):
    """The knuckle joint (toggle) of ``presslink``'s ``ModularKnuckleJoint`` with ``f = c`` (module
    docstring); lengths [mm]."""

    crank_radius: float
    rod_length: float
    rocker: float
    rocker_pivot_x: float
    rocker_pivot_y: float
    main_rod: float
    slide_offset: float = 0.0

    kind = "knuckle-joint"
    bars = (("crank centre", "crank pin"), ("crank pin", "knuckle"), ("pivot", "knuckle"), ("knuckle", "slide"))
    fixed = ("crank centre", "pivot")
    chain = staticmethod(knuckle_joint_chain)
    formula_of = KNUCKLE_JOINT
    links = KNUCKLE_JOINT_LINKS
