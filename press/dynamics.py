"""Drive dynamics of a press: crank torque, motor torque and power, forming work.

Conventions (as the mechanisms, ``press.mechanism``): crank angle ``theta`` [rad] from TDC; slide height
``h`` above BDC; ``h' = dh/dtheta``, ``h'' = d2h/dtheta2``. Inside this module lengths are in metres,
forces in N, torques in N m, inertias in kg m^2, speeds in rad/s. Forces on the slide are positive
upward; crank torque is positive when it drives the crank forward; motor power is positive when the
motor draws from the supply.

Model (derived from the power balance; see the README):

- Masses: what moves with the slide (the slide, the upper die, the wrist-pin share of the rod) is one
  mass ``M``; what turns with the crank (the crankshaft and gears, the crank-pin share of the rod) one
  inertia ``J0`` about the crank axis. The mechanism says how its links split
  (``press.crank_slider.CrankSlider.rod_split``). The crank-pin share is taken as balanced (its gravity is
  neglected).
- Forces on the slide: ``F_env = F_form + F_cb - M g``. ``F_form`` is the forming force of the case's
  table (height above BDC -> force, linear between points, zero outside), acting only while the slide
  descends between theta2 and BDC; ``F_cb`` the counterbalance (constant, upward).
- Kinetic energy ``K = 1/2 (J0 + M h'^2) omega^2``. The power the crank delivers, ``T_c omega``, equals
  ``dK/dt`` minus the power of the forces on the slide, ``F_env h' omega``:

      T_c = J0 alpha + M h' (h' alpha + h'' omega^2) - F_env h'

- Motor (all motors together), gear ratio i, efficiency eta, motor-side inertia J_m:
  ``omega_m = i omega``; ``T_m = T_c / (i eta) + J_m i alpha`` when ``T_c >= 0`` (power flows to the
  crank), ``T_m = T_c eta / i + J_m i alpha`` when ``T_c < 0`` (the crank drives the motor back).
  Shaft power ``P = T_m omega_m``.

Every function works on numpy arrays and on CasADi symbols (``press.backend``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from press.backend import math_module

if TYPE_CHECKING:
    from press.crank_slider import CrankSlider
    from press.mechanism import Mechanism

GRAVITY = 9.80665  # [m/s^2] standard gravity


@dataclass(frozen=True)
class DriveModel:
    """The drive in inside units: slide-side mass ``M`` [kg], crank-side inertia ``J0`` [kg m^2],
    counterbalance ``F_cb`` [N], gear ratio ``i``, efficiency ``eta``, motor-side inertia ``J_m``
    [kg m^2], and the forming-force table ``force_heights`` [mm above BDC, increasing] ->
    ``force_values`` [N]; ``draw_start`` theta2 [rad] and ``bdc`` [rad] (forming acts from theta2 to BDC)."""

    M: float
    J0: float
    F_cb: float
    i: float
    eta: float
    J_m: float
    force_heights: tuple[float, ...]
    force_values: tuple[float, ...]
    draw_start: float
    bdc: float

    @classmethod
    def from_parts(
        cls,
        mechanism: CrankSlider,
        slide_mass_kg: float,
        rod_mass_kg: float,
        rod_cg_from_crank_pin_mm: float,
        crank_inertia_kg_m2: float,
        counterbalance_kN: float,
        gear_ratio: float,
        gear_efficiency: float,
        motor_inertia_kg_m2: float,
        forming_force_kN: list[tuple[float, float]] | None,
        draw_start: float,
    ) -> DriveModel:
        """The model from the case's engineering units; the mechanism splits the rod (module docstring)."""
        with_slide, at_crank = mechanism.rod_split(rod_mass_kg, rod_cg_from_crank_pin_mm)
        table = sorted(forming_force_kN or [])
        return cls(
            M=slide_mass_kg + with_slide,
            J0=crank_inertia_kg_m2 + at_crank,
            F_cb=counterbalance_kN * 1e3,
            i=gear_ratio,
            eta=gear_efficiency,
            J_m=motor_inertia_kg_m2,
            force_heights=tuple(float(h) for h, _ in table),
            force_values=tuple(float(f) * 1e3 for _, f in table),
            draw_start=float(draw_start),
            bdc=float(mechanism.bdc_angle),
        )


def forming_force(theta: Any, height_mm: Any, drive: DriveModel) -> Any:
    """Forming force [N] on the slide (upward) at crank angle ``theta`` [rad] (any turn) where the slide
    is at ``height_mm`` [mm]: the table's value while the slide descends between theta2 and BDC, else 0."""
    m = math_module(theta, height_mm)
    if not drive.force_heights:
        return 0 * theta
    turn = theta - 2 * np.pi * m.floor(theta / (2 * np.pi))  # in [0, 2 pi)
    active = (turn >= drive.draw_start) * (turn <= drive.bdc)
    hs, fs = drive.force_heights, drive.force_values
    if m is np:
        value = np.interp(height_mm, hs, fs, left=0.0, right=0.0)
        inside = (np.asarray(height_mm) >= hs[0]) & (np.asarray(height_mm) <= hs[-1])
        return np.where(active & inside, value, 0.0)
    value = m.pw_lin(height_mm, m.DM(hs), m.DM(fs))
    inside = (height_mm >= hs[0]) * (height_mm <= hs[-1])
    return m.if_else(active * inside, value, 0)


def crank_torque(omega: Any, alpha: Any, d1_mm: Any, d2_mm: Any, forming_N: Any, drive: DriveModel) -> Any:
    """Crank torque [N m] from the power balance: ``J0 alpha + M h' (h' alpha + h'' omega^2) - F_env h'``.

    ``omega`` [rad/s], ``alpha`` [rad/s^2], ``d1_mm = dh/dtheta`` [mm/rad], ``d2_mm = d2h/dtheta2``
    [mm/rad^2], ``forming_N`` the forming force [N] at that point (:func:`forming_force`)."""
    d1, d2 = d1_mm * 1e-3, d2_mm * 1e-3
    f_env = forming_N + drive.F_cb - drive.M * GRAVITY
    return drive.J0 * alpha + drive.M * d1 * (d1 * alpha + d2 * omega**2) - f_env * d1


def motor_torque(crank_torque_Nm: Any, alpha: Any, drive: DriveModel) -> Any:
    """Motor torque [N m] (all motors): the crank torque through the gear (losses against the power
    flow) plus the motor-side inertia: ``T_c/(i eta)`` when ``T_c >= 0``, ``T_c eta/i`` when ``T_c < 0``,
    plus ``J_m i alpha``."""
    m = math_module(crank_torque_Nm, alpha)
    t = crank_torque_Nm
    driving, braking = t / (drive.i * drive.eta), t * drive.eta / drive.i
    through = np.where(t >= 0, driving, braking) if m is np else m.if_else(t >= 0, driving, braking)
    return through + drive.J_m * drive.i * alpha


def motor_speed(omega: Any, drive: DriveModel) -> Any:
    """Motor speed [rad/s] from the crank speed [rad/s]."""
    return drive.i * omega


def envelope_torque(motor_speed_rad_s: Any, peak_torque_Nm: float, base_speed_rad_s: float) -> Any:
    """The motor's peak-torque envelope [N m]: ``peak`` up to the base speed, ``peak base / n`` above it
    (constant power)."""
    m = math_module(motor_speed_rad_s)
    n = motor_speed_rad_s
    if m is np:
        n = np.asarray(n, dtype=float)
        return peak_torque_Nm * np.minimum(1.0, base_speed_rad_s / np.maximum(np.abs(n), 1e-300))
    return peak_torque_Nm * m.fmin(1.0, base_speed_rad_s / m.fmax(m.fabs(n), 1e-300))


def forming_work(h_start_mm: float, h_end_mm: float, drive: DriveModel) -> float:
    """Work [J] of the forming force while the slide descends from ``h_start_mm`` to ``h_end_mm``
    [mm above BDC]: the integral of the piecewise-linear table over the height (exact)."""
    hs = np.asarray(drive.force_heights, dtype=float)
    fs = np.asarray(drive.force_values, dtype=float)
    if hs.size == 0 or h_start_mm <= h_end_mm:
        return 0.0
    lo, hi = max(h_end_mm, hs[0]), min(h_start_mm, hs[-1])
    if hi <= lo:
        return 0.0
    nodes = np.unique(np.concatenate([[lo, hi], hs[(hs > lo) & (hs < hi)]]))
    values = np.interp(nodes, hs, fs)
    return float(np.sum(np.diff(nodes) * (values[1:] + values[:-1]) / 2)) * 1e-3  # N * mm -> J


def drive_state(theta: Any, omega: Any, alpha: Any, mechanism: Mechanism, drive: DriveModel) -> dict[str, Any]:
    """Everything the drive does at crank states (numpy arrays): ``forming_N``, ``crank_torque_Nm``,
    ``motor_speed_rad_s``, ``motor_torque_Nm``, ``motor_power_W``; ``theta`` [rad], ``omega`` [rad/s],
    ``alpha`` [rad/s^2]."""
    h, d1, d2, _ = mechanism.jets(theta)
    f = forming_force(theta, h, drive)
    tc = crank_torque(omega, alpha, d1, d2, f, drive)
    tm = motor_torque(tc, alpha, drive)
    wm = motor_speed(omega, drive)
    return {
        "forming_N": f,
        "crank_torque_Nm": tc,
        "motor_speed_rad_s": wm,
        "motor_torque_Nm": tm,
        "motor_power_W": tm * wm,
    }
