"""Drive dynamics of a press: crank torque, motor torque and power, forming work.

Conventions (as the mechanisms, ``press.mechanism``): crank angle ``theta`` [rad] from TDC; slide height
``h`` above BDC; ``h' = dh/dtheta``, ``h'' = d2h/dtheta2``. Inside this module lengths are in metres,
forces in N, torques in N m, inertias in kg m^2, speeds in rad/s. Forces on the slide are positive
upward; crank torque is positive when it drives the crank forward; motor power is positive when the
motor draws from the supply.

Model (derived from the power balance; see the README):

- Masses: what moves with the slide (the slide, the upper die, the wrist-pin share of a crank-slider's
  rod) is one mass ``M``; what turns with the crank (the crankshaft and gears, the crank-pin share of
  the rod) one inertia ``J0`` about the crank axis (``press.crank_slider.CrankSlider.rod_split``; the
  crank-pin share is taken as balanced, its gravity neglected). A linkage's links (``LinkMass``) each
  have a mass at their centre of gravity and an inertia about it; their kinetic energy
  ``1/2 J_links(theta) omega^2`` with ``J_links = sum m (x_G'^2 + y_G'^2) + I phi'^2`` (primes: d/dtheta
  of the CG's position and of the link's angle, from the mechanism's closed form) and their weight's
  generalised force ``-sum m g y_G'`` enter Lagrange's equation below.
- Forces on the slide: ``F_env = F_form + F_cb - M g``. ``F_form`` is the forming force of the case's
  table (height above BDC -> force, linear between points, zero outside), acting only while the slide
  descends between theta2 and BDC; ``F_cb`` the counterbalance (constant, upward).
- Kinetic energy ``K = 1/2 J(theta) omega^2`` with ``J = J0 + M h'^2 + J_links``. Lagrange's equation for
  the one coordinate theta, ``T_c = J alpha + 1/2 J' omega^2 - Q``, with the generalised force
  ``Q = F_env h' - sum m g y_G'`` (virtual work):

      T_c = J0 alpha + M h' (h' alpha + h'' omega^2) - F_env h' + J_links alpha + 1/2 J_links' omega^2
            + sum m g y_G'

  (for a crank-slider, whose rod is split, the link terms are zero).

- Motor (all motors together), gear ratio i, efficiency eta, motor-side inertia J_m:
  ``omega_m = i omega``; ``T_m = T_c / (i eta) + J_m i alpha`` when power flows to the crank (``T_c`` and
  ``omega`` of one sign: ``T_c >= 0`` turning forward or standing, ``T_c < 0`` turning backward, as on a
  pendulum stroke's backward swing), ``T_m = T_c eta / i + J_m i alpha`` when the crank drives the motor back.
  Shaft power ``P = T_m omega_m``.

Every function works on numpy arrays and on CasADi symbols (``press.backend``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from planning.tolerances import HOLD_STILL_RAD_S, TINY
from press.backend import math_module
from press.jets import Jet

if TYPE_CHECKING:
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
    links: tuple[LinkMass, ...] = ()

    @classmethod
    def from_parts(
        cls,
        mechanism: Mechanism,
        slide_mass_kg: float,
        crank_inertia_kg_m2: float,
        counterbalance_kN: float,
        gear_ratio: float,
        gear_efficiency: float,
        motor_inertia_kg_m2: float,
        forming_force_kN: list[tuple[float, float]] | None,
        draw_start: float,
        lumped: tuple[float, float] = (0.0, 0.0),
        links: tuple[LinkMass, ...] = (),
    ) -> DriveModel:
        """The model from the case's engineering units; ``lumped``: a mass moving with the slide [kg] and an
        inertia turning with the crank [kg m^2] (a crank-slider's split rod); ``links``: a linkage's links
        (module docstring)."""
        with_slide, at_crank = lumped
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
            links=tuple(link for link in links if link.mass > 0 or link.inertia > 0),
        )


@dataclass(frozen=True)
class LinkMass:
    """One link of a linkage: its ``name`` (the mechanism's), ``mass`` [kg] at its centre of gravity,
    ``along`` [mm] from the link's first joint toward its second and ``across`` [mm] to the left of that
    axis, and ``inertia`` [kg m^2] about its centre of gravity."""

    name: str
    mass: float
    along: float
    across: float = 0.0
    inertia: float = 0.0


def link_jets(frames: dict[str, tuple[Any, Any, Any]], links: tuple[Any, ...]) -> tuple[Jet, Jet]:
    """``(J_links [kg m^2], sum m g y_G' [N m])`` of ``links`` (each with ``name``, ``mass``, ``along``,
    ``across``, ``inertia``; numbers or symbols) as jets in the crank angle, one order below the
    mechanism's ``frames`` (link name -> first joint, second joint, length [mm]; points of jets,
    ``press.jets``): ``J_links = sum m (x_G'^2 + y_G'^2) + I phi'^2`` with ``phi' = u_x u_y' - u_y u_x'`` for
    the link's unit vector ``u``."""
    J = G = Jet(0.0)
    for link in links:
        first, second, length = frames[link.name]
        axis = (second - first).scaled(1.0 / length)  # a unit vector along the link
        cg = first + axis.scaled(link.along) + axis.perpendicular().scaled(link.across)
        x1, y1 = cg.x.derivative() * 1e-3, cg.y.derivative() * 1e-3  # [m/rad]
        turn = axis.x * axis.y.derivative() - axis.y * axis.x.derivative()  # d(angle)/dtheta of a unit vector
        J = J + (x1.square() + y1.square()) * link.mass + turn.square() * link.inertia
        G = G + y1 * (link.mass * GRAVITY)
    return J, G


def link_terms(frames: dict[str, tuple[Any, Any, Any]], links: tuple[Any, ...]) -> tuple[Any, Any, Any]:
    """``(J_links [kg m^2], dJ_links/dtheta [kg m^2/rad], sum m g y_G' [N m])`` (:func:`link_jets`)."""
    J, G = link_jets(frames, links)
    return J.c[0], J.c[1], G.c[0]


def forming_force(theta: Any, height_mm: Any, drive: DriveModel) -> Any:
    """Forming force [N] on the slide (upward) at crank angle ``theta`` [rad] (any turn) where the slide
    is at ``height_mm`` [mm]: the table's value while the slide descends between theta2 and BDC, else 0."""
    m = math_module(theta, height_mm)
    if not drive.force_heights:
        return 0 * theta
    turn = theta - 2 * np.pi * m.floor(theta / (2 * np.pi))  # in [0, 2 pi)
    active = (turn >= drive.draw_start) * (turn <= drive.bdc)
    return table_force(height_mm, active, drive)


def table_force(height_mm: Any, active: Any, drive: DriveModel) -> Any:
    """The forming-force table's force [N] at slide heights ``height_mm`` [mm] (linear between rows, zero outside
    them) where ``active`` (booleans or 0/1 symbols: where the forming window is), else 0; numbers or symbols
    (each entry of a symbol vector looked up alone: CasADi's ``pw_lin`` takes a scalar)."""
    m = math_module(height_mm)
    hs, fs = drive.force_heights, drive.force_values
    if not hs:
        return 0 * height_mm
    if m is np:
        h = np.asarray(height_mm, dtype=float)
        value = np.interp(h, hs, fs, left=0.0, right=0.0)
        return np.where(np.asarray(active, dtype=bool) & (h >= hs[0]) & (h <= hs[-1]), value, 0.0)
    table_h, table_f = m.DM(hs), m.DM(fs)
    value = m.vertcat(*[m.pw_lin(height_mm[k], table_h, table_f) for k in range(height_mm.shape[0])])
    inside = (height_mm >= hs[0]) * (height_mm <= hs[-1])
    return m.if_else(active * inside, value, 0)


def crank_torque(
    omega: Any,
    alpha: Any,
    d1_mm: Any,
    d2_mm: Any,
    forming_N: Any,
    drive: DriveModel,
    links: tuple[Any, Any, Any] | None = None,
) -> Any:
    """Crank torque [N m] from Lagrange's equation (module docstring):
    ``J0 alpha + M h' (h' alpha + h'' omega^2) - F_env h'`` plus, with ``links`` (:func:`link_terms`),
    ``J_links alpha + 1/2 J_links' omega^2 + sum m g y_G'``.

    ``omega`` [rad/s], ``alpha`` [rad/s^2], ``d1_mm = dh/dtheta`` [mm/rad], ``d2_mm = d2h/dtheta2``
    [mm/rad^2], ``forming_N`` the forming force [N] at that point (:func:`forming_force`)."""
    d1, d2 = d1_mm * 1e-3, d2_mm * 1e-3
    f_env = forming_N + drive.F_cb - drive.M * GRAVITY
    torque = drive.J0 * alpha + drive.M * d1 * (d1 * alpha + d2 * omega**2) - f_env * d1
    if links is not None:
        J, dJ, G = links
        torque = torque + J * alpha + 0.5 * dJ * omega**2 + G
    return torque


def motor_torque(crank_torque_Nm: Any, alpha: Any, drive: DriveModel, omega: Any = None) -> Any:
    """Motor torque [N m] (all motors): the crank torque through the gear (losses against the power
    flow) plus the motor-side inertia: ``T_c/(i eta)`` where power flows to the crank, ``T_c eta/i`` where
    the crank drives the motor back, plus ``J_m i alpha``. The power flows to the crank where ``T_c >= 0``
    and the crank turns forward (``omega`` None: it does), or ``T_c < 0`` and it turns backward; a standing
    crank (``|omega| <= HOLD_STILL_RAD_S``) is held through the gear as if driven, ``T_c/(i eta)`` either way
    (no power flows: the motor holds the crank's torque against the gear's friction, the same on either
    side)."""
    m = math_module(crank_torque_Nm, alpha)
    t = crank_torque_Nm
    driving, braking = t / (drive.i * drive.eta), t * drive.eta / drive.i
    if m is np:
        if omega is None:
            to_crank = t >= 0
        else:
            w = np.asarray(omega)
            to_crank = (np.abs(w) <= HOLD_STILL_RAD_S) | ((t >= 0) == (w > 0))
        through = np.where(to_crank, driving, braking)
    else:
        through = m.if_else(t >= 0, driving, braking)  # the NLPs turn forward
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
        return peak_torque_Nm * np.minimum(1.0, base_speed_rad_s / np.maximum(np.abs(n), TINY))
    return peak_torque_Nm * m.fmin(1.0, base_speed_rad_s / m.fmax(m.fabs(n), TINY))


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


def drive_state(
    theta: Any, omega: Any, alpha: Any, mechanism: Mechanism, drive: DriveModel, forming_N: Any = None
) -> dict[str, Any]:
    """Everything the drive does at crank states (numpy arrays): ``forming_N``, ``crank_torque_Nm``,
    ``motor_speed_rad_s``, ``motor_torque_Nm``, ``motor_power_W``; ``theta`` [rad], ``omega`` [rad/s, either
    sign], ``alpha`` [rad/s^2]; ``forming_N``: the forming force [N] there when the caller knows it (a pendulum
    stroke's, acting on either swing), else :func:`forming_force`'s."""
    h, d1, d2, _ = mechanism.jets(theta)
    f = forming_force(theta, h, drive) if forming_N is None else forming_N
    links = link_terms(mechanism.frames(theta), drive.links) if drive.links else None
    tc = crank_torque(omega, alpha, d1, d2, f, drive, links)
    tm = motor_torque(tc, alpha, drive, omega)
    wm = motor_speed(omega, drive)
    return {
        "forming_N": f,
        "crank_torque_Nm": tc,
        "motor_speed_rad_s": wm,
        "motor_torque_Nm": tm,
        "motor_power_W": tm * wm,
    }
