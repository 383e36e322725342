"""The press's own capacity: its tonnage curve and its crank (gear) torque capacity.

A mechanical press is rated by the force its frame and drive allow: the **rated force** ``F_r`` at the **rated
distance** ``d_r`` above BDC. The drive turns the crank; by virtual work (quasi-static, frictionless) the
torque on the crank that holds a force ``F`` on the slide at crank angle theta is::

    T = F |dh/dtheta|                                                                          (1)

(``h`` the slide's height above BDC [m], so ``dh/dtheta`` [m/rad] is the crank's lever on the slide). The
rating fixes the crank's torque capacity ``T_r = F_r |h'(theta_r)|`` with ``h(theta_r) = d_r`` on the down
stroke; above the rated distance the lever grows and the force the press allows falls: the **tonnage curve**::

    F_allowed(h) = min(F_r, T_r / |h'(theta(h))|)                                               (2)

(below ``d_r`` the frame's ``F_r``; at BDC the lever vanishes and the frame limits). A press builder may give
the curve as a table of force against height instead (interpolated linearly in height; beyond its ends its
end values). ``tests/test_capacity.py`` holds (2) against the crank-slider's closed form of ``h'``.

Signs: forces on the slide in kN, the force the process takes (the forming force) positive; heights in mm
above BDC; torques in kN m, their magnitude.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from planning.tolerances import TINY
from press.mechanism import Mechanism


def rated_torque_kNm(machine: Mechanism, rated_force_kN: float, rated_distance_mm: float) -> float:
    """``T_r = F_r |h'(theta_r)|`` [kN m], ``theta_r`` the crank angle of the rated distance on the down stroke."""
    down = float(machine.angles_at_height(rated_distance_mm)[0])
    lever_m = abs(float(machine.derivatives(down)[0])) * 1e-3
    return rated_force_kN * lever_m


DOWNSTROKE_SAMPLES = 4001  # crank angles from TDC to BDC on which the tonnage curve is laid out


def tonnage_curve(
    machine: Mechanism,
    rated_force_kN: float | None = None,
    rated_distance_mm: float | None = None,
    table_kN: Sequence[Sequence[float]] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The force the press allows [kN] against the slide's height [mm above BDC], ``(heights, forces)`` in
    increasing height: (2) from the rating on the down stroke (TDC to BDC on :data:`DOWNSTROKE_SAMPLES` crank
    angles), or the builder's ``table_kN`` (``[[height mm, force kN], ...]``). Interpolate it linearly."""
    if table_kN is not None:
        heights, forces = (np.array(column, dtype=float) for column in zip(*sorted(table_kN), strict=True))
        return heights, forces
    torque = rated_torque_kNm(machine, rated_force_kN, rated_distance_mm)
    theta = np.linspace(0.0, machine.bdc_angle, DOWNSTROKE_SAMPLES)
    h, d1 = machine.height(theta), machine.derivatives(theta)[0]
    lever_m = np.abs(d1) * 1e-3
    with np.errstate(divide="ignore"):
        allowed = np.minimum(rated_force_kN, np.where(lever_m > 0, torque / np.maximum(lever_m, TINY), np.inf))
    order = np.argsort(h)
    return h[order], allowed[order]
