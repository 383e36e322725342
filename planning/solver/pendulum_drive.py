"""The drive's rows of a pendulum NLP (``planning.solver.pendulum_nlp``): the motor's peak and RMS torque, the
crank's torque capacity and (a grid peak limit without a storage) the bus's power at the swings' samples.

Each swing runs on its path coordinate u with speeds >= 0 (``planning.model.pendulum``); on the backward swing
``theta = 2 pi - u``, so ``theta' = -u'``, ``theta'' = -u''``, ``h' = -h_b'`` and a linkage's ``J_links' `` and
weight term change sign. Lagrange's equation (``press.dynamics``) then gives the crank torque on u as ``-T_c``:
``T_u = J0 u'' + M h_b' (h_b' u'' + h'' u'^2) - F_env h_b' + J_links u'' + 1/2 J_links,u u'^2 + G_u`` with
``J_links,u = -J_links'`` and ``G_u = -sum m g y_G'`` there. Power flows to the crank where ``T_c`` and the crank
speed have one sign, that is where ``T_u >= 0``: the motor torque on u is ``press.dynamics.motor_torque`` of
``T_u`` (its magnitude the motor's, its sign flipped), the motor's speed ``i u'``, its power ``T_m omega_m``
the same on either coordinate. The forming force acts where the slide descends at or below the draw start's
height: on each swing's path from theta2 to BDC (``planning.model.pendulum.forming_on_path``).

Samples: every segment of the halves at ``law.samples`` points and the swing's end (at rest), the draw at
:data:`~planning.solver.parameters.DRAW_SAMPLES_DRIVE` + 1 fixed angles at the draw speed. The RMS integrates
``T_m^2`` by the trapezoidal rule over each swing's samples in time and adds each standstill's holding torque
squared times its time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from planning.model.case import RPM, Case
from planning.model.cycle import HOLD_SEGMENT
from planning.model.free_swing import samples_per_segment
from planning.model.limits.base import trapezoid
from planning.model.limits.grid import EXCESS_SMOOTHING, bus_power
from planning.model.pendulum import TWO_PI, forming_on_path
from planning.model.profile import advance_segment
from planning.solver.nlp import DriveSamples as NLPDriveSamples
from planning.solver.nlp import objective_terms
from planning.solver.parameters import DRAW_SAMPLES_DRIVE, objective_values
from press.dynamics import crank_torque, link_terms, motor_torque

PEAK, RMS = "drive.motor.peak_torque_Nm", "drive.motor.rated_torque_Nm"  # the case fields of the motor's rows
GRID = "drive.grid.peak_power_kW"
DRAW_TORQUE_POINTS = 2001  # angles of a swing's draw on which the precheck takes the drive's torques


@dataclass
class DriveSamples:
    """One swing's samples in time order: crank torque ``tc`` and motor torque ``tm`` on u [N m], motor speed
    [rad/s], the crank's acceleration on u ``alpha`` [rad/s^2], their ``times`` from the swing's start [s];
    ``holding``: the motor torque at rest at its end."""

    tc: Any
    tm: Any
    speed: Any
    alpha: Any
    times: Any
    holding: Any


def _links(case: Case, swing: str, u: Any) -> tuple[Any, Any, Any] | None:
    """A linkage's link terms on u: ``(J, dJ/du, G_u)`` (signs flipped on the backward swing)."""
    model = case.drive_model
    if not model.links:
        return None
    theta = u if swing == "forward" else TWO_PI - u
    J, dJ, G = link_terms(case.machine.frames(theta), model.links)
    return (J, dJ, G) if swing == "forward" else (J, -dJ, -G)


def swing_drive(case: Case, swing: Any) -> DriveSamples:
    """The drive at the samples of one swing (``swing``: the NLP's ``SwingSymbols``)."""
    model = case.drive_model
    p = swing.params
    fractions = ca.DM(np.linspace(0.0, 1.0, samples_per_segment(p.motion_law) + 1)[:-1])
    parts = []  # (u, omega, alpha, times from the swing's start, forming force) of each segment, in time order
    parts += _half_samples(*swing.feed, fractions, 0.0)
    parts.append(_draw_samples(swing))
    parts += _half_samples(*swing.ret, fractions, p.feed_time + p.draw_time)
    end = swing.return_end  # at rest at the swing's end
    parts.append((end[0], end[1], end[2], p.duration))
    u, om, al, times = (ca.vertcat(*column) for column in zip(*parts, strict=True))
    h, d1, d2, _ = swing.setup.jets(u)
    forming = forming_on_path(case, swing.setup.name, u, h)  # the draw's and, past theta3 before BDC, the return's
    tc = crank_torque(om, al, d1, d2, forming, model, _links(case, swing.setup.name, u))
    tm = motor_torque(tc, al, model)
    if p.has_hold:  # standing at the hold: held through the gear as if driven (``press.dynamics.motor_torque``)
        standing = _hold_samples(swing, fractions.shape[0])
        tm = ca.vertcat(*[_held(tc[i], model) if i in standing else tm[i] for i in range(tm.shape[0])])
    # at rest at the swing's end, held as at the hold (on u or in the crank's own angle: the same magnitude)
    return DriveSamples(tc, tm, model.i * om, al, times, _held(tc[tc.shape[0] - 1], model))


def _held(crank_torque_Nm: Any, model: Any) -> Any:
    """The motor torque [N m] that holds a standing crank's torque (``press.dynamics.motor_torque`` at rest)."""
    return crank_torque_Nm / (model.i * model.eta)


def _hold_samples(swing: Any, per_segment: int) -> set[int]:
    """The indices of a swing's samples (:func:`swing_drive`'s order) at its hold's standstill."""
    first = per_segment * len(swing.feed[2]) + DRAW_SAMPLES_DRIVE + 1  # the return's first sample
    k = next(i for i, seg in enumerate(swing.ret[2]) if seg.name == HOLD_SEGMENT)
    return set(range(first + k * per_segment, first + (k + 1) * per_segment))


def _half_samples(starts: list, states: list, segs: list, fractions: ca.DM, offset: Any) -> list[tuple]:
    """The samples of a half's segments: ``(u, omega, alpha, times)``."""
    out = []
    for seg, st, t0 in zip(segs, states, starts, strict=True):
        th, om, al, _ = advance_segment(seg, *st, fractions * seg.duration)
        out.append((th, om, al, offset + t0 + fractions * seg.duration))
    return out


def _draw_samples(swing: Any) -> tuple:
    """The draw's samples: fixed angles theta2 .. theta3 on u at the draw speed."""
    u2, u3 = swing.setup.keys[1], swing.setup.keys[2]
    u = np.linspace(u2, u3, DRAW_SAMPLES_DRIVE + 1)
    w2 = swing.params.draw_speed
    times = swing.params.feed_time + ca.DM(u - u2) / w2
    return ca.DM(u), w2 * ca.DM.ones(u.size), ca.DM.zeros(u.size), times


def trapezoid_heat(samples: DriveSamples) -> Any:
    """``integral T_m^2 dt`` over a swing by the trapezoidal rule on its samples [N^2 m^2 s]."""
    t, sq = samples.times, samples.tm**2
    n = t.shape[0]
    return ca.sum1((t[1:n] - t[0 : n - 1]) * (sq[1:n] + sq[0 : n - 1]) / 2)


def rate_terms(case: Case, drives: dict[str, DriveSamples], turns: tuple[Any, Any]) -> tuple[Any, Any]:
    """``(heat [N^2 m^2 s], supply energy [J])`` of a cycle of two swings, as the rotary rate NLP takes them
    (``planning.solver.nlp.objective_terms``: the gear's loss rounded where T_c changes sign, the supply
    ``r P + (1 - r) smoothmax(P, 0)`` of the shaft power ``P = T_m omega_m``, or with the drive's copper or
    converter losses of the bus power through them, the same on u as on theta), each
    standstill's holding torque squared times its time added to the heat (and, with the losses, its copper loss
    to the energy: at rest no power flows to the shaft)."""
    q = objective_values(case)
    d = case.drive
    q["motor_base_speed"] = d.motor.base_speed_rpm * RPM
    losses = d.has_losses  # the energy at the bus then
    heat, energy = 0.0, 0.0
    for samples in drives.values():
        torque = NLPDriveSamples(case.drive_model, samples.tc, samples.tm, samples.speed)
        h, e = objective_terms(q, torque, samples.alpha, samples.times, losses)
        heat, energy = heat + h, energy + e
    f, b = drives["forward"], drives["backward"]
    if losses:  # standing at the turns the bus still feeds the holding torque's copper loss
        copper = q["copper_coefficient"] / q["converter_efficiency"]
        energy += copper * (f.holding**2 * turns[0] + b.holding**2 * turns[1])
    return heat + f.holding**2 * turns[0] + b.holding**2 * turns[1], energy


def drive_rows(
    case: Case, add: Any, drives: dict[str, DriveSamples], turns: tuple[Any, Any], period: Any, limits: dict[str, float]
) -> None:
    """The drive's rows (``add``: ``planning.solver.nlp.Rows.add``): the motor's peak torque within its envelope at
    every sample, its RMS over the cycle (``turns``: the standstills at theta_e and theta_s, after the forward and
    the backward swing), the crank's torque capacity (where the case gives one: ``limits`` holds it)."""
    motor = case.drive.motor
    base = motor.base_speed_rpm * RPM
    for samples in drives.values():
        above_base = ca.fmax(1.0, samples.speed / base)
        add("motor peak torque", samples.tm * above_base / limits["motor_peak_torque"], -1.0, 1.0, PEAK)
        if "crank_torque" in limits:
            add(
                "crank torque",
                samples.tc / (1e3 * limits["crank_torque"]),
                -1.0,
                1.0,
                "press.capacity.crank_torque_kNm",
            )
    f, b = drives["forward"], drives["backward"]
    heat = trapezoid_heat(f) + trapezoid_heat(b) + f.holding**2 * turns[0] + b.holding**2 * turns[1]
    add("motor RMS torque", heat / period / limits["motor_rms_torque"] ** 2, -math.inf, 1.0, RMS)
    if "grid_cap" in limits:
        _grid_rows(case, add, drives, limits)


def _grid_rows(case: Case, add: Any, drives: dict[str, DriveSamples], limits: dict[str, float]) -> None:
    """The grid's limit (``planning.model.limits.grid``): the bus power ``(T_m omega_m + k T_m^2) / eta_c`` under
    the cap at every sample of both swings (the grid's power where the bus draws; at the standstills the holding
    torque's copper loss, far below any limit). With a storage (``grid_allowance`` among ``limits``) the cap is
    where the storage's power ends, and the energy the bus draws above the limit ``L`` over each swing,
    ``integral (P_bus - L)+ dt`` (a smooth max, trapezoids over the swing's samples), within what the storage can
    give, ``eta_s U``: each swing's draw is carried by the storage apart, which recharges between them (its exact
    periodic schedule over the cycle is the dense check's, ``planning.solver.peak_shaving``)."""
    limit = case.drive.grid.peak_power_kW * 1e3
    eps = EXCESS_SMOOTHING * limit
    for samples in drives.values():
        power = _bus_power(case, samples)
        add("grid peak power", power / limits["grid_cap"], -math.inf, 1.0, GRID)
        if "grid_allowance" in limits:
            excess = (power - limit + ca.sqrt((power - limit) ** 2 + eps**2)) / 2
            energy = trapezoid(excess, samples.times)
            add("storage energy above the grid limit", energy / limits["grid_allowance"], -math.inf, 1.0, GRID)


def bus_peak_rows(case: Case, add: Any, drives: dict[str, DriveSamples], peak: Any, unit: float) -> None:
    """min-grid-peak (``planning.solver.pendulum_rate``): the bus power ``(T_m omega_m + k T_m^2) / eta_c`` at or
    below the epigraph variable ``peak`` [W] at every sample of both swings (``unit`` [W] scales the rows); the
    standstills' holding copper loss is far below any peak."""
    for samples in drives.values():
        add("bus power under its peak", (_bus_power(case, samples) - peak) / unit, -math.inf, 0.0, "planner.objective")


def _bus_power(case: Case, samples: DriveSamples) -> Any:
    """The bus power [W] at a swing's samples, ``(T_m omega_m + k T_m^2) / eta_c`` (``planning.model.limits.grid``)."""
    d = case.drive
    copper = d.motor.copper_loss_at_rated_kW * 1e3 / d.motor.rated_torque_Nm**2
    return bus_power(samples.tm, samples.speed, copper, d.converter_efficiency)


def draw_torque(case: Case, setup: Any, speed: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The drive through a swing's draw at the constant crank ``speed`` [rad/s] (numbers): ``(u [rad], motor
    torque on u [N m], motor speed [rad/s], crank torque on u [N m])`` (``setup``: the swing's ``SwingSetup``)."""
    model = case.drive_model
    u = np.linspace(setup.keys[1], setup.keys[2], DRAW_TORQUE_POINTS)
    h, d1, d2, _ = (np.asarray(x) for x in setup.jets(u))
    forming = forming_on_path(case, setup.name, u, h)
    omega = np.full(u.size, speed)
    tc = crank_torque(omega, 0.0 * u, d1, d2, forming, model, _links(case, setup.name, u))
    return u, motor_torque(tc, 0.0 * u, model), model.i * omega, tc
