"""The crank-slider, in line or offset (désaxé): slide height above BDC as a function of the crank angle.

Geometry (crank radius R, rod length L, offset e, in mm; the slide hangs below the crank). For the
geometric angle ``phi`` the crank pin is at ``(R sin phi, R cos phi)``; the slide moves on the vertical
line ``x = e``, its wrist pin at::

    y(phi) = R cos phi - sqrt(L^2 - (R sin phi - e)^2)

and the crank turns towards ``+phi``. TDC and BDC are where the rod is in line with the crank:
``phi_TDC = -asin(e / (L - R))``, ``phi_BDC = pi - asin(e / (L + R))``; the crank angle of the project
counts from TDC, ``theta = phi - phi_TDC``, and the height counts from BDC,
``h = y - y_BDC`` with ``y_BDC = -sqrt((L + R)^2 - e^2)``. The stroke is
``sqrt((L + R)^2 - e^2) - sqrt((L - R)^2 - e^2)``. With an offset the way down takes more crank angle
than the way up (``e > 0``: a slower working stroke and a quicker return). With ``e = 0``::

    h(theta) = R (1 + cos theta) + L - sqrt(L^2 - R^2 sin^2 theta)

and the slide turns round sharply at BDC (``d2h/dtheta2 = R + R^2/L``) and gently at TDC (``R^2/L - R``).

Derivatives (with ``u = R sin phi - e``, ``W = sqrt(L^2 - u^2)``, ``g = u u'``; a prime is d/dtheta)::

    g   = (R sin phi - e) R cos phi
    g'  = R^2 cos 2 phi + e R sin phi
    g'' = -2 R^2 sin 2 phi + e R cos phi
    h'   = -R sin phi + g / W
    h''  = -R cos phi + g' / W + g^2 / W^3
    h''' =  R sin phi + g'' / W + 3 g g' / W^3 + 3 g^3 / W^5

The paper (Wang, Wu & Ding, Eqs. 1-3) prints the usual second-order series in lambda = R/L of the
in-line crank-slider, ``S = R[(1 - cos x) + R/(4L) (1 - cos 2x)]``. Read with ``x`` measured from BDC
(``x = pi - theta``) it is the series of the exact height above, which :func:`series_height` evaluates;
it drops terms of order R lambda^3 (for 450/1200 mm at most about 3.2 mm, at 90 and 270 deg; see
``tests/test_kinematics.py``). Read as printed, with ``x`` from TDC, ``2R - S`` is the height of a slide
on the far side of the crank (an engine), which misplaces the paper's own key points (131.5 deg:
104.5 mm instead of the 200.1 mm the paper prints). The paper's key-point heights and speeds are those
of the exact press geometry.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from planning.tolerances import SAME_HEIGHT_MM
from press.backend import math_module
from press.jets import ORDER, Jet, Point
from press.mechanism import Formula, Jets, Mechanism


def offset_jets(theta: Any, geometry: Sequence[Any]) -> Jets:
    """Height above BDC and its first three derivatives (module docstring) at ``theta`` [rad from TDC] for
    ``geometry = (R, L, e, phi_TDC, y_BDC)`` [mm, mm, mm, rad, mm]; numpy or CasADi alike."""
    R, L, e, phi_tdc, y_bdc = geometry
    m = math_module(theta, *geometry)
    phi = theta + phi_tdc
    s, c = m.sin(phi), m.cos(phi)
    u = R * s - e
    W = m.sqrt(L**2 - u**2)
    g = u * (R * c)
    g1 = R**2 * m.cos(2 * phi) + e * R * s
    g2 = -2 * R**2 * m.sin(2 * phi) + e * R * c
    h = R * c - W - y_bdc
    d1 = -R * s + g / W
    d2 = -R * c + g1 / W + g**2 / W**3
    d3 = R * s + g2 / W + 3 * g * g1 / W**3 + 3 * g**3 / W**5
    return h, d1, d2, d3


def in_line_jets(theta: Any, geometry: Sequence[Any]) -> Jets:
    """The same for the in-line press, ``geometry = (R, L)`` [mm]: the offset's terms dropped
    (``g = R^2 sin theta cos theta``, ``g' = R^2 cos 2 theta``, ``g'' = -2 R^2 sin 2 theta``)."""
    R, L = geometry
    m = math_module(theta, *geometry)
    s, c = m.sin(theta), m.cos(theta)
    s2, c2 = m.sin(2 * theta), m.cos(2 * theta)
    W = m.sqrt(L**2 - R**2 * s**2)
    g = R**2 * s * c
    g1 = R**2 * c2
    g2 = -2 * R**2 * s2
    h = R * (1 + c) + L - W
    d1 = -R * s + g / W
    d2 = -R * c + g1 / W + g**2 / W**3
    d3 = R * s + g2 / W + 3 * g * g1 / W**3 + 3 * g**3 / W**5
    return h, d1, d2, d3


def in_line_series(theta: Any, geometry: Sequence[Any], order: int = ORDER) -> Jet:
    """The in-line height above BDC as a jet of ``order`` (``press.jets``) at ``theta`` [rad from TDC] for
    ``geometry = (R, L)`` [mm]: ``R (1 + cos theta) + L - sqrt(L^2 - R^2 sin^2 theta)``."""
    R, L = geometry
    t = Jet.angle(theta, order)
    return (t.cos() + 1.0) * R + L - (L**2 - (t.sin() * R).square()).sqrt()


def offset_series(theta: Any, geometry: Sequence[Any], order: int = ORDER) -> Jet:
    """The offset press's height above BDC as a jet (module docstring) for ``geometry = (R, L, e, phi_TDC,
    y_BDC)``: ``R cos phi - sqrt(L^2 - (R sin phi - e)^2) - y_BDC``, ``phi = theta + phi_TDC``."""
    R, L, e, phi_tdc, y_bdc = geometry
    phi = Jet.angle(theta + phi_tdc, order)
    return phi.cos() * R - (L**2 - (phi.sin() * R - e).square()).sqrt() - y_bdc


def in_line_evaluate(theta: Any, geometry: Sequence[Any], order: int = ORDER) -> tuple[Jet, dict]:
    """The in-line press's height (:func:`in_line_series`) and its one link, the rod: its joints (crank
    pin, wrist pin) and length [mm] (``press.mechanism.Formula``)."""
    R, L = geometry
    height = in_line_series(theta, geometry, order)
    return height, _rod_frame(theta, R, L, 0.0, 0.0, height, -(L + R))


def offset_evaluate(theta: Any, geometry: Sequence[Any], order: int = ORDER) -> tuple[Jet, dict]:
    """The same for the offset press."""
    R, L, e, phi_tdc, y_bdc = geometry
    height = offset_series(theta, geometry, order)
    return height, _rod_frame(theta, R, L, e, phi_tdc, height, y_bdc)


def _rod_frame(theta: Any, R: Any, L: Any, e: Any, phi_tdc: Any, height: Jet, y_bdc: Any) -> dict:
    phi = Jet.angle(theta + phi_tdc, height.order)
    crank_pin = Point(phi.sin() * R, phi.cos() * R)
    wrist_pin = Point(Jet(e), height + y_bdc)
    return {"rod": (crank_pin, wrist_pin, L)}


IN_LINE = Formula("crank-slider, in line", ("crank_radius", "rod_length"), in_line_evaluate, in_line_jets, ("rod",))
OFFSET = Formula(
    "crank-slider, offset",
    ("crank_radius", "rod_length", "offset", "tdc_phase", "bdc_level"),
    offset_evaluate,
    offset_jets,
    ("rod",),
)


def series_height(theta: Any, R: float, L: float) -> Any:
    """The paper's Eq. 1 (second-order series in R/L of the in-line crank-slider) as a height above BDC
    [mm] at ``theta`` [rad from TDC]: ``R (1 + cos theta) + R^2/(4 L) (1 - cos 2 theta)``."""
    m = math_module(theta)
    return R * (1 + m.cos(theta)) + R**2 / (4 * L) * (1 - m.cos(2 * theta))


def series_derivatives(theta: Any, R: float, L: float) -> tuple[Any, Any, Any]:
    """d/dtheta of :func:`series_height`, three orders (the paper's Eqs. 2, 3 divided by omega, omega^2)."""
    m = math_module(theta)
    s, c, s2, c2 = m.sin(theta), m.cos(theta), m.sin(2 * theta), m.cos(2 * theta)
    lam = R / L
    return -R * (s - lam / 2 * s2), -R * (c - lam * c2), R * (s - 2 * lam * s2)


@dataclass(frozen=True)
class CrankSlider(Mechanism):
    """A crank-slider press: ``crank_radius`` R [mm], ``rod_length`` L [mm] (longer than the crank),
    ``offset`` e [mm] of the slide's line from the crank axis (0: in line; ``|e| < L - R``)."""

    crank_radius: float
    rod_length: float
    offset: float = 0.0

    kind = "crank-slider"
    own_angle_origin = "the crank pin straight above the crank axis"
    bars = (("crank centre", "crank pin"), ("crank pin", "slide"))
    fixed = ("crank centre",)

    def joints(self, theta: Any) -> dict[str, tuple[Any, Any]]:
        """The crank centre, the crank pin ``(R sin phi, R cos phi)`` and the slide's wrist pin ``(e, y)``."""
        theta = np.asarray(theta, dtype=float)
        pin = self.crank_pin(theta)
        y_bdc = -math.sqrt((self.rod_length + self.crank_radius) ** 2 - self.offset**2)
        slide = (np.full_like(theta, self.offset), self.height(theta) + y_bdc)
        return {"crank centre": (np.zeros_like(theta), np.zeros_like(theta)), "crank pin": pin, "slide": slide}

    def crank_pin(self, theta: Any) -> tuple[Any, Any]:
        phi = np.asarray(theta, dtype=float) + self.tdc_own_angle
        return self.crank_radius * np.sin(phi), self.crank_radius * np.cos(phi)

    @property
    def tdc_own_angle(self) -> float:
        """The geometric angle of TDC [rad]: ``-asin(e / (L - R))`` (0 in line)."""
        return -math.asin(self.offset / (self.rod_length - self.crank_radius))

    def __post_init__(self) -> None:
        R, L, e = self.crank_radius, self.rod_length, self.offset
        if not (R > 0 and L > R):
            raise ValueError("need 0 < crank_radius < rod_length")
        if not abs(e) < L - R:
            raise ValueError("need |offset| < rod_length - crank_radius")

    @property
    def formula(self) -> Formula:
        """:data:`IN_LINE` without an offset, else :data:`OFFSET`."""
        return IN_LINE if self.offset == 0 else OFFSET

    @property
    def geometry(self) -> tuple[float, ...]:
        """In line ``(R, L)``; offset ``(R, L, e, phi_TDC, y_BDC)``: the dimensions [mm], the geometric angle
        of TDC [rad] and the wrist pin's position at BDC [mm] (module docstring)."""
        R, L, e = self.crank_radius, self.rod_length, self.offset
        if e == 0:
            return (R, L)
        return (R, L, e, -math.asin(e / (L - R)), -math.sqrt((L + R) ** 2 - e**2))

    @property
    def bdc_angle(self) -> float:
        """Crank angle of BDC [rad from TDC]: ``pi - asin(e/(L+R)) + asin(e/(L-R))`` (pi in line)."""
        R, L, e = self.crank_radius, self.rod_length, self.offset
        return math.pi - math.asin(e / (L + R)) + math.asin(e / (L - R))

    @property
    def stroke(self) -> float:
        """Slide stroke [mm]: ``sqrt((L+R)^2 - e^2) - sqrt((L-R)^2 - e^2)`` (2 R in line)."""
        R, L, e = self.crank_radius, self.rod_length, self.offset
        if e == 0:
            return 2.0 * R
        return math.sqrt((L + R) ** 2 - e**2) - math.sqrt((L - R) ** 2 - e**2)

    @cached_property
    def peak_curvature(self) -> float:
        """Largest ``|d2h/dtheta2|`` [mm/rad^2]: ``R + R^2/L`` at BDC in line; with an offset the generic
        search (:attr:`Mechanism.peak_curvature`)."""
        R, L = self.crank_radius, self.rod_length
        if self.offset == 0:
            return R + R**2 / L
        return Mechanism.peak_curvature.func(self)

    def angles_at_height(self, h: Any) -> tuple[Any, Any]:
        """``(descending, ascending)`` crank angles [rad] at slide height ``h`` [mm above BDC], in closed
        form: the wrist pin at ``(e, Y)``, ``Y = h + y_BDC``, is ``L`` from the crank pin, so
        ``e sin phi + Y cos phi = (R^2 + e^2 + Y^2 - L^2) / (2 R)``; with ``rho = sqrt(e^2 + Y^2)`` and
        ``beta = pi - asin(e / rho)`` that is ``cos(phi - beta) = c / rho``, ``phi = beta -+ acos(c / rho)``
        (down, up). Raises ``ValueError`` outside the stroke."""
        R, L, e = self.crank_radius, self.rod_length, self.offset
        phi_tdc, y_bdc = -math.asin(e / (L - R)), -math.sqrt((L + R) ** 2 - e**2)
        h_arr = np.asarray(h, dtype=float)
        if np.any(h_arr < -SAME_HEIGHT_MM) or np.any(h_arr > self.stroke + SAME_HEIGHT_MM):
            raise ValueError(f"height {h} mm is outside the stroke 0 ... {self.stroke:g} mm")
        if e == 0:  # in line: the law of cosines in the triangle centre-pin-slide, symmetric about BDC
            s = L + R - h_arr
            down = np.arccos(np.clip((L**2 - R**2 - s**2) / (2 * R * s), -1.0, 1.0))
            return (float(down), float(2 * np.pi - down)) if np.ndim(h) == 0 else (down, 2 * np.pi - down)
        Y = h_arr + y_bdc
        rho = np.sqrt(e**2 + Y**2)
        c = (R**2 + e**2 + Y**2 - L**2) / (2 * R)
        psi = np.arccos(np.clip(c / rho, -1.0, 1.0))
        beta = np.pi - np.arcsin(e / rho)
        down, up = beta - psi - phi_tdc, beta + psi - phi_tdc
        if np.ndim(h) == 0:
            return float(down), float(up)
        return down, up

    def rod_split(self, rod_mass_kg: float, rod_cg_from_crank_pin_mm: float) -> tuple[float, float]:
        """The connecting rod as two point masses (the drive model): ``m_B = m a_G / L`` at the wrist pin
        moves with the slide, ``m_A = m - m_B`` at the crank pin turns on radius R. Returns the mass
        moving with the slide [kg] and the inertia about the crank axis [kg m^2] (``m_A R^2``)."""
        R = self.crank_radius * 1e-3
        m_B = rod_mass_kg * rod_cg_from_crank_pin_mm / self.rod_length
        return m_B, (rod_mass_kg - m_B) * R**2
