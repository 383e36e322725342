"""Crank-slider kinematics: slider height above BDC as a function of the crank angle.

Conventions (the whole project): crank angle ``theta`` [rad] from top dead centre (TDC = 0),
increasing in the direction of rotation; slider height ``h`` [mm] measured upward from bottom
dead centre (BDC). Slider velocity is ``dh/dt`` [mm/s], positive upward.

Exact geometry of a press (crank radius R, rod length L, in-line slide hanging below the crank;
at TDC the crank pin points up, away from the slide)::

    h(theta) = R (1 + cos theta) + L - sqrt(L^2 - R^2 sin^2 theta)

The slide turns round sharply at BDC (d2h/dtheta2 = R + R^2/L) and gently at TDC (R^2/L - R).

The paper (Wang, Wu & Ding, Eqs. 1-3) prints the usual second-order series in lambda = R/L,
``S = R[(1 - cos x) + R/(4L) (1 - cos 2x)]``. Read with ``x`` measured from BDC (``x = pi - theta``)
it is the series of the exact height above, ``h = R (1 + cos theta) + R^2/(4L) (1 - cos 2 theta)``,
which is what ``model="series"`` evaluates; it drops terms of order R lambda^3 (for 450/1200 mm at
most about 3.2 mm, at 90 and 270 deg; see ``tests/test_kinematics.py``). Read as printed, with ``x`` from
TDC, ``2R - S`` is the height of a slide on the far side of the crank (an engine), which misplaces
the paper's own key points (131.5 deg: 104.5 mm instead of the 200.1 mm the paper prints). The
paper's key-point heights and speeds are those of the exact press geometry.

Every function accepts numpy arrays or CasADi symbols (SX/MX/DM) for the angle and speeds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from press.backend import math_module

Model = Literal["exact", "series"]


def height(theta: Any, R: float, L: float, model: Model = "exact") -> Any:
    """Slider height above BDC [mm] at crank angle ``theta`` [rad]; ``R``, ``L`` [mm]."""
    m = math_module(theta)
    if model == "series":
        return R * (1 + m.cos(theta)) + R**2 / (4 * L) * (1 - m.cos(2 * theta))  # Eq. 1, x = pi - theta
    s = m.sin(theta)
    return R * (1 + m.cos(theta)) + L - m.sqrt(L**2 - R**2 * s**2)


def height_derivatives(theta: Any, R: float, L: float, model: Model = "exact") -> tuple[Any, Any, Any]:
    """First three derivatives of the height with respect to the crank angle.

    Returns ``(dh/dtheta [mm/rad], d2h/dtheta2 [mm/rad^2], d3h/dtheta3 [mm/rad^3])``.
    """
    m = math_module(theta)
    s, c = m.sin(theta), m.cos(theta)
    s2, c2 = m.sin(2 * theta), m.cos(2 * theta)
    if model == "series":
        lam = R / L  # derivatives of Eq. 1 with x = pi - theta (Eqs. 2, 3 divided by omega, omega^2)
        return (
            -R * (s - lam / 2 * s2),
            -R * (c - lam * c2),
            R * (s - 2 * lam * s2),
        )
    W = m.sqrt(L**2 - R**2 * s**2)
    g = R**2 * s * c  # = R^2/2 sin 2theta; W' = -g/W
    g1 = R**2 * c2
    g2 = -2 * R**2 * s2
    d1 = -R * s + g / W
    d2 = -R * c + g1 / W + g**2 / W**3
    d3 = R * s + g2 / W + 3 * g * g1 / W**3 + 3 * g**3 / W**5
    return d1, d2, d3


def slider_motion(
    theta: Any, omega: Any, alpha: Any, jerk: Any, R: float, L: float, model: Model = "exact"
) -> tuple[Any, Any, Any, Any]:
    """Slider height, velocity, acceleration and jerk from the crank state.

    Parameters: ``theta`` crank angle [rad], ``omega`` crank speed [rad/s], ``alpha`` crank
    acceleration [rad/s^2], ``jerk`` crank jerk [rad/s^3], ``R``, ``L`` [mm].
    Returns ``(h [mm], v [mm/s], a [mm/s^2], j [mm/s^3])``, upward positive (chain rule).
    """
    d1, d2, d3 = height_derivatives(theta, R, L, model)
    h = height(theta, R, L, model)
    v = d1 * omega
    a = d2 * omega**2 + d1 * alpha
    j = d3 * omega**3 + 3 * d2 * omega * alpha + d1 * jerk
    return h, v, a, j


def angles_at_height(h: Any, R: float, L: float) -> tuple[Any, Any]:
    """Crank angles [rad] where the slider is at height ``h`` [mm] above BDC (exact geometry).

    Returns ``(descending, ascending)``: the angle in [0, pi] on the way down and the angle in
    [pi, 2 pi] on the way up. The slide pin lies ``s = L + R - h`` below the crank centre; the law of
    cosines in the triangle centre-pin-slide gives ``cos theta = (L^2 - R^2 - s^2) / (2 R s)``.
    Raises ``ValueError`` outside the stroke.
    """
    h_arr = np.asarray(h, dtype=float)
    if np.any(h_arr < -1e-9) or np.any(h_arr > 2 * R + 1e-9):
        raise ValueError(f"height {h} mm is outside the stroke 0 ... {2 * R} mm")
    s = L + R - h_arr
    cos_t = np.clip((L**2 - R**2 - s**2) / (2 * R * s), -1.0, 1.0)
    down = np.arccos(cos_t)
    return down, 2 * np.pi - down


@dataclass(frozen=True)
class CrankSlider:
    """An in-line crank-slider press.

    Attributes: ``crank_radius`` [mm], ``rod_length`` [mm] (longer than the crank),
    ``model``: ``"exact"`` geometry (default) or the paper's ``"series"`` (Eqs. 1-3).
    """

    crank_radius: float
    rod_length: float
    model: Model = "exact"

    def __post_init__(self) -> None:
        if not (self.crank_radius > 0 and self.rod_length > self.crank_radius):
            raise ValueError("need 0 < crank_radius < rod_length")

    @property
    def stroke(self) -> float:
        """Slider stroke [mm] = 2 R."""
        return 2.0 * self.crank_radius

    def height(self, theta: Any) -> Any:
        """Slider height above BDC [mm] at crank angle ``theta`` [rad]."""
        return height(theta, self.crank_radius, self.rod_length, self.model)

    def derivatives(self, theta: Any) -> tuple[Any, Any, Any]:
        """``(dh/dtheta [mm/rad], d2h/dtheta2 [mm/rad^2], d3h/dtheta3 [mm/rad^3])``."""
        return height_derivatives(theta, self.crank_radius, self.rod_length, self.model)

    def slider(self, theta: Any, omega: Any, alpha: Any = 0.0, jerk: Any = 0.0) -> tuple[Any, Any, Any, Any]:
        """Slider ``(h [mm], v [mm/s], a [mm/s^2], j [mm/s^3])`` from crank ``theta`` [rad],
        ``omega`` [rad/s], ``alpha`` [rad/s^2], ``jerk`` [rad/s^3]."""
        return slider_motion(theta, omega, alpha, jerk, self.crank_radius, self.rod_length, self.model)

    def angles_at_height(self, h: Any) -> tuple[Any, Any]:
        """``(descending, ascending)`` crank angles [rad] at slider height ``h`` [mm] (exact geometry)."""
        return angles_at_height(h, self.crank_radius, self.rod_length)
