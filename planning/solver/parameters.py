"""The parameter vector of an NLP: every number of a case that an NLP reads, in one layout per NLP.

An NLP is built once per process and reused for every case of its kind (``planning.solver.nlp``): the
case enters as parameters, laid out here, in order: the mechanism's geometry (``press.mechanism``), the
cycle's structure (the key angles, the die-height crossings, the length unit of the rows), the
parameters of each limit the NLP holds (``planning.model.limits``), the drive model's (drive NLPs), the
objectives' (the rate NLP) and the forming force at the draw's samples (drive NLPs, last). A name is
looked up in the layout; no module counts positions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from planning.model.case import RPM, Case
from planning.model.limits import BY_ID
from planning.model.limits.base import Limit
from press.dynamics import forming_force
from press.mechanism import Formula

# the cycle's structure, in inside units
STRUCTURE = (
    "theta1",  # closing [rad]
    "theta2",  # draw start
    "theta3",  # draw end
    "theta4",  # opening
    "die_down_angle",  # the descending die-height crossing [rad] (its row is off when it lies in the draw)
    "die_down_slope",  # |dh/dtheta| there [mm/rad], 0 when the crossing lies in the draw
    "die_down_active",  # 1 when the crossing lies outside the draw, else 0 (its time is then fixed)
    "die_up_angle",
    "die_up_slope",
    "die_up_active",
    "length_unit",  # [mm] the mechanism's characteristic length (half the stroke)
)
# the drive model (``press.dynamics``), SI units
DRIVE = (
    "drive_M",  # slide-side mass [kg]
    "drive_J0",  # crank-side inertia [kg m^2]
    "drive_F_cb",  # counterbalance [N]
    "drive_i",  # gear ratio
    "drive_eta",  # gear efficiency
    "drive_J_m",  # motor-side inertia [kg m^2]
    "motor_base_speed",  # [rad/s] at the motor: the envelope's kink, the scale of the objectives' smoothing
)
# each massive link of a linkage (``press.dynamics.LinkMass``), after the drive's: its mass [kg], where its
# centre of gravity lies [mm] and its inertia [kg m^2]
LINK = ("mass", "along", "across", "inertia")
# the objective of the rate NLP (``planning.solver.objectives``): f = weight_period * period + weight_heat *
# heat + weight_energy * supply energy - weight_dwell * transfer dwell (+ weight_peak * bus peak, its peak variant)
OBJECTIVE = (
    "weight_period",  # [1/s]
    "weight_heat",  # [1/(N^2 m^2 s)] heat = integral T_m^2 dt over the cycle
    "weight_energy",  # [1/J] supply energy = integral (r P + (1 - r) smoothmax(P, 0)) dt
    "weight_dwell",  # [1/s] the constant-speed transfer dwell
    "regen",  # r, the share of the returned energy the supply takes back, 0 ... 1
    "power_smoothing",  # [W] epsilon of smoothmax(P, 0) = (P + sqrt(P^2 + epsilon^2)) / 2
    "weight_peak",  # [1/W] the bus power's peak (the rate NLP's peak variant)
    "copper_coefficient",  # [W/(N m)^2] copper loss = k T_m^2 (drive.motor.copper_loss_at_rated_kW / rated^2)
    "converter_efficiency",  # eta_c, the bus power's P_el / eta_c
    "weight_draw",  # [1/s] the draw's time (the optimal law's free draw at a rate: the slide at its set speed first)
)
# the die exit (a halves NLP's denser variant): where the draw ends with the slide below the die height, the
# die speed is held at fixed crank angles from theta3 to the die-height crossing (smooth rows, exact there)
EXIT_SAMPLES = 12
EXIT = tuple(f"die_exit_{part}_{k}" for k in range(EXIT_SAMPLES) for part in ("angle", "slope")) + ("die_exit_active",)
HOLD = ("hold_time", "hold_angle")  # the hold at the bottom: its time [s] and crank angle [rad]
DRAW_SAMPLES_DRIVE = 80  # with a drive the draw is sampled finer: the forming force changes fast there
FORMING_SAMPLES = DRAW_SAMPLES_DRIVE + 1  # forming force [N] at the draw's samples, theta2 ... theta3
POWER_SMOOTHING = 1e-3  # epsilon of the rate NLP's smooth max(P, 0), as a share of rated torque x base speed


@dataclass(frozen=True)
class ParameterLayout:
    """The parameters of one NLP: the ``formula`` of its mechanism, the ``limit_ids`` it holds, with the
    drive's torque (``drive``; the masses of the mechanism's ``links`` named, :func:`drive_links`) and the
    objectives of a target rate (``rate``)."""

    formula: Formula
    limit_ids: tuple[str, ...]
    drive: bool = False
    rate: bool = False
    links: tuple[str, ...] = ()
    die_exit: bool = False  # the die exit's angles (:data:`EXIT`; a halves NLP's denser variant)
    hold: bool = False  # the hold at the bottom (:data:`HOLD`)
    # the segments whose slide-acceleration samples each carry a share of the limit (:func:`share_name`)
    shared_segments: tuple[str, ...] = ()

    @property
    def limits(self) -> tuple[Limit, ...]:
        return tuple(BY_ID[i] for i in self.limit_ids)

    @cached_property
    def names(self) -> tuple[str, ...]:
        """Every parameter's name but the forming force's, in vector order."""
        names = [f"geometry_{g}" for g in self.formula.geometry_names] + list(STRUCTURE)
        names += EXIT if self.die_exit else ()
        names += HOLD if self.hold else ()
        names += [share_name(segment) for segment in self.shared_segments]
        for limit in self.limits:
            names += [p for p in limit.parameters if p not in names]
        if self.drive:
            names += DRIVE
            names += [link_parameter(link, part) for link in self.links for part in LINK]
        if self.rate:
            names += OBJECTIVE
        return tuple(names)

    @cached_property
    def _index(self) -> dict[str, int]:
        return {name: i for i, name in enumerate(self.names)}

    def index(self, name: str) -> int:
        """The position of parameter ``name``."""
        return self._index[name]

    @property
    def size(self) -> int:
        return len(self.names) + (FORMING_SAMPLES if self.drive else 0)

    @property
    def forming(self) -> slice:
        """The forming force's positions (drive NLPs)."""
        return slice(len(self.names), self.size)

    def symbols(self, p: Any) -> dict[str, Any]:
        """Name -> the entry of the parameter vector ``p`` (a CasADi symbol)."""
        return {name: p[i] for i, name in enumerate(self.names)}

    def geometry(self, symbols: dict[str, Any]) -> list[Any]:
        """The mechanism's geometry vector (``Mechanism.jets``) from the parameter symbols."""
        return [symbols[f"geometry_{g}"] for g in self.formula.geometry_names]

    def values(self, case: Case) -> np.ndarray:
        """The vector of ``case`` (inside units)."""
        names = (f"geometry_{g}" for g in self.formula.geometry_names)
        values = dict(zip(names, case.machine.geometry, strict=True))
        values |= structure_values(case)
        if self.die_exit:
            values |= exit_values(case)
        if self.hold:
            values |= {"hold_time": case.process.hold_time_s, "hold_angle": case.hold_angle}
        values |= {share_name(segment): 1.0 for segment in self.shared_segments}
        for limit in self.limits:
            values |= limit.parameter_values(case)
        if self.drive:
            values |= drive_values(case)
            values |= link_values(case, self.links)
        if self.rate:
            values |= objective_values(case)
        out = np.array([values[name] for name in self.names], dtype=float)
        if self.drive:
            out = np.concatenate([out, forming_values(case)])
        return out


def share_name(segment: str) -> str:
    """The parameter of segment ``segment``'s share of the sampled slide-acceleration limit: 1 in a case's
    vector; the search lowers it where the dense check finds the limit exceeded between that segment's
    samples (``planning.solver.search``), so that a refinement tightens the limit where it failed only."""
    return f"share:{segment}"


def structure_values(case: Case) -> dict[str, float]:
    """The key angles, the die-height crossings (a crossing inside the draw is covered by the draw-speed
    bound: its rows are switched off; a descending one in a hold's brake, after theta3, is held there: its
    angle a turn back, as the NLP counts it from theta3) and the mechanism's length unit."""
    m = case.machine
    th1, th2, th3, th4 = case.key_angles
    down, up = (float(a) for a in m.angles_at_height(case.limits.die_height_mm))
    braking = brake_crossing(case)
    held = down < th2 or braking
    return {
        "theta1": th1,
        "theta2": th2,
        "theta3": th3,
        "theta4": th4,
        "die_down_angle": down - 2 * math.pi if braking else down,
        "die_down_slope": abs(float(m.derivatives(down)[0])) if held else 0.0,
        "die_down_active": 1.0 if held else 0.0,
        "die_up_angle": up,
        "die_up_slope": abs(float(m.derivatives(up)[0])) if up > th3 else 0.0,
        "die_up_active": 1.0 if up > th3 else 0.0,
        "length_unit": m.length_scale,
    }


def brake_crossing(case: Case) -> bool:
    """Whether the slide enters the die zone while the crank brakes to a hold (the descending die-height
    crossing between theta3 and the hold's angle)."""
    if case.hold_angle is None:
        return False
    down = float(case.machine.angles_at_height(case.limits.die_height_mm)[0])
    return bool(case.key_angles[2] < down < case.hold_angle)


def exit_values(case: Case) -> dict[str, float]:
    """The die exit's angles, evenly inside theta3 ... the die-height crossing the slide rises through, and
    ``|dh/dtheta|`` there; inactive (``die_exit_active`` 0, every slope 0) where the draw ends above the die
    height."""
    m = case.machine
    th3 = float(case.key_angles[2])
    up = float(m.angles_at_height(case.limits.die_height_mm)[1])
    active = up > th3
    share = np.arange(1, EXIT_SAMPLES + 1) / (EXIT_SAMPLES + 1)
    angles = th3 + (up - th3) * share if active else np.full(EXIT_SAMPLES, th3)
    slopes = np.abs(m.derivatives(angles)[0]) if active else np.zeros(EXIT_SAMPLES)
    out = {"die_exit_active": 1.0 if active else 0.0}
    for k in range(EXIT_SAMPLES):
        out[f"die_exit_angle_{k}"], out[f"die_exit_slope_{k}"] = float(angles[k]), float(slopes[k])
    return out


def drive_values(case: Case) -> dict[str, float]:
    """The drive model in inside units (``press.dynamics.DriveModel``) and the motor's base speed."""
    d = case.drive_model
    return {
        "drive_M": d.M,
        "drive_J0": d.J0,
        "drive_F_cb": d.F_cb,
        "drive_i": d.i,
        "drive_eta": d.eta,
        "drive_J_m": d.J_m,
        "motor_base_speed": case.drive.motor.base_speed_rpm * RPM,
    }


def drive_links(case: Case) -> tuple[str, ...]:
    """The names of the case's links that have mass or inertia, in the mechanism's order (an NLP holds the
    link terms of these only; a crank-slider whose rod is split holds none)."""
    model = case.drive_model
    massive = {link.name for link in model.links} if model is not None else set()
    return tuple(name for name in case.machine.formula.link_names if name in massive)


def link_parameter(link: str, part: str) -> str:
    """The parameter name of ``part`` (:data:`LINK`) of ``link``."""
    return f"link_{link}_{part}"


def link_values(case: Case, links: tuple[str, ...]) -> dict[str, float]:
    """The parameters of ``links`` (:data:`LINK`) from the case's drive model."""
    by_name = {link.name: link for link in case.drive_model.links}
    return {link_parameter(name, part): float(getattr(by_name[name], part)) for name in links for part in LINK}


def objective_values(case: Case) -> dict[str, float]:
    """The objective of the most strokes (the period alone); ``planning.solver.objectives`` sets the weights
    per solve. Without a drive (a kinematic case at a line's rate) the drive's figures are placeholders its NLP
    never reads."""
    if case.drive is None:
        return {name: 0.0 for name in OBJECTIVE} | {"weight_period": 1.0, "power_smoothing": 1.0}
    motor = case.drive.motor
    return {
        "weight_period": 1.0,
        "weight_heat": 0.0,
        "weight_energy": 0.0,
        "weight_dwell": 0.0,
        "regen": case.drive.regen_efficiency,
        "power_smoothing": POWER_SMOOTHING * motor.rated_torque_Nm * motor.base_speed_rpm * RPM,
        "weight_peak": 0.0,
        "copper_coefficient": motor.copper_loss_at_rated_kW * 1e3 / motor.rated_torque_Nm**2,
        "converter_efficiency": case.drive.converter_efficiency,
        "weight_draw": 0.0,
    }


def forming_values(case: Case) -> np.ndarray:
    """The forming force [N] at the draw's :data:`FORMING_SAMPLES` samples, theta2 ... theta3."""
    _, th2, th3, _ = case.key_angles
    theta = th2 + np.linspace(0.0, 1.0, FORMING_SAMPLES) * (th3 - th2)
    return forming_force(theta, case.machine.height(theta), case.drive_model)


def time_limit(case: Case) -> float:
    """[s] the least upper bound on a time variable: every time of a cycle lies within one period, at most the
    longest the least crank speed allows (``Case.longest_cycle_s``); the bound scales with the case, 600 s
    keeps the usual cases' numerics."""
    if case.hold_angle is None:
        return max(MAX_TIME_S, 1.01 * case.longest_cycle_s)
    return max(MAX_TIME_S, 1.01 * (case.longest_cycle_s - case.standstill_s)) + case.standstill_s


MAX_TIME_S = 600.0  # [s] least upper bound on a time variable (:func:`time_limit`)
