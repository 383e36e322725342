"""What the drive does over one planned cycle: torques, RMS, power and energy, from the closed-form profile.

The integrals over the cycle use Gauss-Legendre quadrature (:data:`GAUSS_NODES` nodes) on pieces of at
most :data:`MAX_PIECE_S`, and at least :data:`MIN_PIECES` per span, between breakpoints: every knot of
the profile, theta2 and BDC (where the forming force starts and ends; the mechanism says where BDC is)
and every height of the forming-force table on the way down (its kinks). The integrands are smooth on
each piece, so the crank work ``integral T_c omega dt`` is exact to about 1e-12 relative and can be
checked against the forming work, which is integrated exactly from the table
(``press.dynamics.forming_work``): over a cycle the kinetic energy returns to its start, and gravity and
the counterbalance are conservative, so the two are equal (the energy balance). The drawn and returned
energies ``E+ = integral max(P, 0) dt`` and ``E- = integral min(P, 0) dt`` have kinks where the power
changes sign; there the quadrature is accurate to the piece length squared.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from planning.model.case import RPM, Case
from planning.model.profile import Profile, dense_times
from planning.tolerances import SAME_TIME_S
from press.dynamics import drive_state, envelope_torque, forming_work

GAUSS_NODES = 4
MAX_PIECE_S = 5e-3  # [s] (4-point Gauss-Legendre is exact for polynomials of degree 7 on each piece)
MAX_PIECES = 400_000  # a longer cycle gets longer pieces
MIN_PIECES = 8  # per span between breakpoints: a short segment of a trigonometric law (a cycloidal half of
# a few ms is one period of its cosine) is resolved as finely as a long one


@dataclass(frozen=True)
class DriveFigures:
    """One cycle of the drive: peaks, RMS and energies in engineering units."""

    peak_motor_torque_Nm: float  # largest |T_m|
    peak_motor_torque_angle_deg: float
    rms_motor_torque_Nm: float
    peak_crank_torque_Nm: float
    peak_motor_power_kW: float  # largest |P|
    peak_motor_speed_rpm: float
    energy_drawn_kJ: float  # E+
    energy_returned_kJ: float  # E- (negative or zero)
    energy_net_kJ: float
    supply_energy_kJ: float  # drawn from the supply per stroke, E+ - r |E-| (r: drive.regen_efficiency)
    forming_work_kJ: float
    crank_work_kJ: float  # integral of T_c omega over the cycle: equals the forming work
    crank_work_abs_kJ: float  # integral of |T_c omega|: the scale of the energy balance
    peak_torque_use_pct: float  # largest |T_m| / envelope at that speed
    rms_torque_use_pct: float  # RMS / rated
    power: PowerFigures | None = field(default=None, compare=False)  # the chain to the grid (drive.electrical)

    def as_dict(self) -> dict[str, float]:
        """The figures as ``result.json``'s ``drive`` block writes them (the power chain apart)."""
        return {k: v for k, v in self.__dict__.items() if k != "power"}


@dataclass(frozen=True)
class PowerFigures:
    """One cycle of the power chain from the motors to the grid (``press.power``; computed by
    ``planning.solver.peak_shaving``): energies per stroke [kJ], powers [kW], the storage's state [kJ]. Over the
    cycle ``grid_energy = forming work + gear + copper + converter + storage + resistor losses +
    storage_change`` (the storage's schedule is periodic: its change is zero to the programme's tolerance)."""

    copper_loss_kJ: float
    converter_loss_kJ: float
    gear_loss_kJ: float
    storage_loss_kJ: float
    resistor_loss_kJ: float
    storage_change_kJ: float  # stored energy at the cycle's end minus at its start
    bus_energy_kJ: float
    bus_supply_energy_kJ: float  # what the grid gives without storage: integral r P_bus + (1 - r) max(P_bus, 0) dt
    grid_energy_kJ: float
    grid_energy_kWh_per_1000_strokes: float
    mean_bus_power_kW: float
    mean_grid_power_kW: float
    bus_peak_kW: float  # the grid's peak without storage
    grid_peak_kW: float  # with the case's storage and its schedule (dense)
    grid_peak_angle_deg: float
    grid_peak_sampled_kW: float  # the peak-shaving programme's, on its samples
    storage_usable_kJ: float
    storage_swing_kJ: float
    storage_start_kJ: float
    storage_min_kJ: float
    storage_max_kJ: float
    storage_peak_power_kW: float
    grid_limit_kW: float | None
    bus_cap_for_limit_kW: float | None  # above the grid limit with storage: the bus cap the storage could
    # shave to the limit on this plan's shape (planning.solver.peak_shaving.bus_cap_for_limit; None otherwise)
    storage_for_limit_kJ: float | None  # with storage and a grid limit: the least usable energy with which it
    # holds the limit on this plan (None: no size does, or no storage or limit;
    # planning.solver.peak_shaving.storage_needed)
    storage_to_flatten_kJ: float | None  # with storage: the least usable energy of one like it that brings the
    # grid's peak within 5 % of the mean bus power (planning.solver.peak_shaving.storage_to_flatten; None: none does)
    schedule: Any = field(default=None, compare=False, repr=False)  # planning.solver.peak_shaving.Schedule

    def as_dict(self) -> dict[str, Any]:
        """The figures as ``result.json``'s ``power`` block writes them (the schedule apart)."""
        return {k: v for k, v in self.__dict__.items() if k != "schedule"}


def breakpoints(profile: Profile, case: Case) -> np.ndarray:
    """Times [s] where the drive's integrands may kink: knots, theta2, BDC, table heights going down."""
    times = list(profile.knot_times)
    th0 = profile.theta0
    machine = case.machine
    bdc = machine.bdc_angle
    angles = [case.key_angles[1], bdc]
    table = case.process.forming_force_kN or []
    for h, _ in table:
        if 0 < h < machine.stroke:
            down = float(machine.angles_at_height(h)[0])
            if case.key_angles[1] < down < bdc:
                angles.append(down)
    for a in angles:
        a = th0 + ((a - th0) % (2 * math.pi))
        if a <= th0 + 2 * math.pi:
            times.append(profile.time_at_angle(a))
    return np.unique(np.clip(np.asarray(times, dtype=float), profile.t0, profile.t0 + profile.duration))


def quadrature(
    profile: Profile, case: Case, extra_edges: np.ndarray | None = None, edges: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Nodes [s] and weights [s] of the cycle's quadrature (see the module docstring); ``extra_edges`` [s]:
    more breakpoints (the storage schedule's, where its power jumps); ``edges`` [s]: the breakpoints themselves
    (a pendulum stroke's, whose crank turns back: ``planning.solver.pendulum_check``), else a rotary cycle's."""
    edges = breakpoints(profile, case) if edges is None else np.unique(np.asarray(edges, dtype=float))
    if extra_edges is not None:
        edges = np.unique(np.concatenate([edges, np.clip(extra_edges, profile.t0, profile.t0 + profile.duration)]))
        edges = edges[np.concatenate([[True], np.diff(edges) > SAME_TIME_S])]
    span = np.diff(edges)
    step = max(MAX_PIECE_S, profile.duration / MAX_PIECES)
    counts = np.maximum(MIN_PIECES, np.ceil(span / step).astype(int))
    starts = np.repeat(edges[:-1], counts) + np.concatenate(
        [np.arange(c) * (s / c) for c, s in zip(counts, span, strict=True)]
    )
    lengths = np.repeat(span / counts, counts)
    x, w = np.polynomial.legendre.leggauss(GAUSS_NODES)
    nodes = (starts[:, None] + lengths[:, None] * (x[None, :] + 1) / 2).ravel()
    weights = (lengths[:, None] * w[None, :] / 2).ravel()
    return nodes, weights


def cycle_integrals(profile: Profile, case: Case, swings: Any = None) -> dict[str, float]:
    """The quadrature's integrals over the cycle: ``rms_motor_torque_Nm``, ``energy_drawn_kJ``,
    ``energy_returned_kJ``, ``crank_work_kJ``, ``crank_work_abs_kJ``, ``forming_work_kJ``, and the
    quadrature's drive state (``state``, ``omega``) for the peaks. ``swings``: a pendulum stroke's
    ``(breakpoints [s], forming(theta, omega) [N])``: its quadrature's edges and the forming force on either swing,
    two strokes a cycle (the forming work twice)."""
    edges, forming = (None, None) if swings is None else swings
    t, w = quadrature(profile, case, edges=edges)
    th, om, al, _ = profile.at_time(t)
    s = drive_state(th, om, al, case.machine, case.drive_model, None if forming is None else forming(th, om))
    tm, p = s["motor_torque_Nm"], s["motor_power_W"]
    h2 = float(case.machine.height(case.key_angles[1]))
    work = s["crank_torque_Nm"] * om
    drawn = float(np.sum(w * np.maximum(p, 0.0))) / 1e3
    returned = float(np.sum(w * np.minimum(p, 0.0))) / 1e3
    return {
        "rms_motor_torque_Nm": math.sqrt(float(np.sum(w * tm**2)) / profile.duration),
        "energy_drawn_kJ": drawn,
        "energy_returned_kJ": returned,
        "supply_energy_kJ": drawn + case.drive.regen_efficiency * returned,
        "crank_work_kJ": float(np.sum(w * work)) / 1e3,
        "crank_work_abs_kJ": float(np.sum(w * np.abs(work))) / 1e3,
        "forming_work_kJ": (1 if swings is None else 2) * forming_work(h2, 0.0, case.drive_model) / 1e3,
        "state": s,
    }


def dense_drive_state(profile: Profile, case: Case) -> tuple[np.ndarray, dict]:  # a rotary plan's
    """The crank angle [rad] and the drive's state (``press.dynamics.drive_state``) on the verification's
    dense grid (uniform, knots included)."""
    t = dense_times(profile.duration, profile.knot_times - profile.t0)
    th, om, al, _ = profile.at_time(profile.t0 + t)
    return th, drive_state(th, om, al, case.machine, case.drive_model)


def drive_figures(
    profile: Profile, case: Case, integrals: dict | None = None, dense: tuple[np.ndarray, dict] | None = None
) -> DriveFigures:
    """The drive's figures over the cycle of ``profile`` (a plan's, from TDC); needs ``case.drive``.
    Integrals by the quadrature (:func:`cycle_integrals`); peaks on the dense grid (:func:`dense_drive_state`)
    and the quadrature's nodes together. ``integrals`` and ``dense``: those two already computed (the
    verification computes both), else computed here."""
    motor = case.drive.motor
    c = integrals if integrals is not None else cycle_integrals(profile, case)
    s = c["state"]
    tm, p = s["motor_torque_Nm"], s["motor_power_W"]
    theta, d = dense if dense is not None else dense_drive_state(profile, case)
    abs_torque = np.abs(d["motor_torque_Nm"])
    k = int(np.argmax(abs_torque))
    rms = c["rms_motor_torque_Nm"]
    return DriveFigures(
        peak_motor_torque_Nm=float(abs_torque[k]),
        peak_motor_torque_angle_deg=float(math.degrees(theta[k]) % 360.0),
        rms_motor_torque_Nm=rms,
        peak_crank_torque_Nm=float(max(np.max(np.abs(s["crank_torque_Nm"])), np.max(np.abs(d["crank_torque_Nm"])))),
        peak_motor_power_kW=float(max(np.max(np.abs(p)), np.max(np.abs(d["motor_power_W"])))) / 1e3,
        peak_motor_speed_rpm=float(np.max(np.abs(s["motor_speed_rad_s"]))) / RPM,  # either way (a pendulum's)
        energy_drawn_kJ=c["energy_drawn_kJ"],
        energy_returned_kJ=c["energy_returned_kJ"],
        energy_net_kJ=c["energy_drawn_kJ"] + c["energy_returned_kJ"],
        supply_energy_kJ=c["supply_energy_kJ"],
        forming_work_kJ=c["forming_work_kJ"],
        crank_work_kJ=c["crank_work_kJ"],
        crank_work_abs_kJ=c["crank_work_abs_kJ"],
        peak_torque_use_pct=100.0
        * max(float(np.max(np.abs(tm) / _envelope(s["motor_speed_rad_s"], case))), _envelope_use(d, case)),
        rms_torque_use_pct=100.0 * rms / motor.rated_torque_Nm,
    )


def _envelope(motor_speed_rad_s: np.ndarray, case: Case) -> np.ndarray:
    m = case.drive.motor
    return envelope_torque(motor_speed_rad_s, m.peak_torque_Nm, m.base_speed_rpm * RPM)


def _envelope_use(state: dict, case: Case) -> float:
    return float(np.max(np.abs(state["motor_torque_Nm"]) / _envelope(state["motor_speed_rad_s"], case)))
