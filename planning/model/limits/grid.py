"""The plant's limit on the press's draw from the grid (``drive.grid.peak_power_kW``), with the DC-bus storage's
schedule (``planning.solver.peak_shaving``; the chain and its signs: ``press.power``).

In a drive NLP the limit caps the bus power at every sample, ``P_bus <= cap`` (the parameter ``grid_cap``; the
row ``(T_m omega_m + P_cu) / (eta_c cap) <= 1``, which a braking sample meets anyway). Without storage the cap is
the limit itself (refined by the measured overshoot between the samples, like the motor's torque). With
storage the grid sees the bus less what the storage gives: the cap is where the storage's power ends (the limit
plus its power limit, or the most the motors can draw), and a second row keeps the energy the bus draws above
the limit over the cycle within what the storage can give, ``integral (P_bus - L)+ dt <= eta_s U`` (the
parameter ``grid_allowance``; a smooth max, trapezoids over the samples). The verification then runs the
storage's best schedule on the dense grid; where the plan needs more storage than there is (the samples saw less
energy above the limit, or the storage cannot recharge in time), the allowance is scaled by the usable energy
over the storage the plan needs and the plan solved again; where no storage size would do (its power), the cap
goes to the highest level at which the storage could hold the limit were that plan's bus power clipped there
(``planning.solver.peak_shaving.bus_cap_for_limit``). The storage's energy budget is in the NLP, its periodic schedule
is not: the plans are verified, not proven the fastest (the README says so).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from planning.model.limits.base import Check, Dense, Impossible, Limit, Row, Transcription, trapezoid
from planning.model.limits.motor import draw_drive_state
from planning.model.units import RPM
from planning.tolerances import GRID_BACKOFF, LIMIT_REL_TOL
from press.power import chain

CAP_HEADROOM = 1.01  # the starting cap with storage: this much above the most the motors can draw from the bus
EXCESS_SMOOTHING = 1e-2  # the energy row's smooth max(P - L, 0): epsilon as a share of the limit L (1e-4 and 1e-3
# left IPOPT at its iteration limit on the cup press with 2 kJ; the bias eps^2 / 4|P - L| away from L is small)
NO_STORAGE_J = 1e15  # [J] the energy row's allowance without storage (the cap row holds the limit then)


class GridPeakLimit(Limit):
    """The grid's power <= ``drive.grid.peak_power_kW`` over the cycle, the storage's schedule the one that
    shaves the peak most (module docstring); checked on the dense grid."""

    id = "grid_peak_power"
    name = "grid peak power"
    unit = "kW"
    field = "drive.grid.peak_power_kW"
    order = 110
    precheck_at_one_draw_speed = True
    parameters = ("grid_cap", "grid_copper", "grid_converter", "grid_limit", "grid_allowance")
    refined = "grid_cap"
    backoff = GRID_BACKOFF
    motor = True
    uses_drive = True

    def applies(self, case: Any) -> bool:
        d = case.drive
        return d is not None and d.grid is not None and d.grid.peak_power_kW is not None

    def parameter_values(self, case: Any) -> dict[str, float]:
        d = case.drive
        limit = d.grid.peak_power_kW * 1e3
        cap = limit * (1 - self.backoff)
        s = d.storage
        if _storage_counts(case):
            top = _most_bus_power(case) * CAP_HEADROOM
            if s.max_power_kW is not None:
                top = min(top, limit + s.max_power_kW * 1e3)
            cap = max(cap, top)
        rated = d.motor.rated_torque_Nm
        return {
            "grid_cap": cap,
            "grid_copper": d.motor.copper_loss_at_rated_kW * 1e3 / rated**2,
            "grid_converter": d.converter_efficiency,
            "grid_limit": limit,
            "grid_allowance": s.efficiency * s.usable_energy_kJ * 1e3 if _storage_counts(case) else NO_STORAGE_J,
        }

    def rows(self, nlp: Transcription) -> list[Row]:
        """The bus power under the cap at every sample; with storage also the energy the bus draws above the
        limit over the cycle within what the storage can give, ``integral (P_bus - L)+ dt <= eta_s U`` (the
        storage's energy budget; smooth max, trapezoids over the samples; without storage the allowance is
        out of reach and the cap is the limit)."""
        bus = bus_power(nlp.motor_torque, nlp.motor_speed, nlp.param("grid_copper"), nlp.param("grid_converter"))
        limit = nlp.param("grid_limit")
        above = bus - limit
        eps = EXCESS_SMOOTHING * limit
        excess = (above + (above**2 + eps**2) ** 0.5) / 2
        energy = trapezoid(excess, nlp.times) / nlp.param("grid_allowance")
        return [
            Row("grid peak power", bus / nlp.param("grid_cap"), -np.inf, 1.0, True),
            Row("storage energy above the grid limit", energy, -np.inf, 1.0),
        ]

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """The draw runs at constant speed, so its bus power is known before any plan; at the lowest draw
        speed the case allows it is the least (the power grows with the speed, and so does the energy above
        the limit, ``integral (P - L) dtheta / w2``). Above the limit the storage must carry the excess: its
        power, and its energy within ``eta_s`` times the usable energy (it cannot start fuller)."""
        d = case.drive
        limit = d.grid.peak_power_kW * 1e3
        w2 = given if given is not None else lowest
        theta, state = draw_drive_state(case, w2)
        bus = drive_chain(state["motor_torque_Nm"], state["motor_power_W"], d)["bus_power_W"]
        k = int(np.argmax(bus))
        if bus[k] <= limit * (1 + LIMIT_REL_TOL):
            return None
        excess = np.maximum(bus - limit, 0.0)
        energy = float(np.sum(np.diff(theta) * (excess[1:] + excess[:-1]) / 2)) / w2  # [J]
        s = d.storage
        if s is not None:
            power_ok = s.max_power_kW is None or excess[k] <= s.max_power_kW * 1e3
            if power_ok and energy <= s.efficiency * s.usable_energy_kJ * 1e3 * (1 - 1e-3):
                return None
        where = f"at {math.degrees(theta[k]):.1f} deg the draw at {w2 / RPM:.3g} rpm needs {bus[k] / 1e3:.0f} kW"
        carry = (
            f"; the storage cannot carry the {energy / 1e3:.1f} kJ above the limit"
            if s is not None
            else " (no drive.storage to carry it)"
        )
        return Impossible(
            f"{self.field} = {d.grid.peak_power_kW:g} is below the draw's power: {where}{carry}",
            self.field,
            d.grid.peak_power_kW,
            float(bus[k]) / 1e3,
            math.degrees(theta[k]),
        )

    def check(self, dense: Dense) -> list[Check]:
        """The grid's peak with the storage's best schedule against the limit. Above it with storage, the NLP's
        allowance is scaled by the usable energy over the storage the plan would need (its samples saw less
        energy above the limit than the dense grid does), or, where no storage size would do (its power),
        the cap is scaled by the level at which the storage could hold the limit over the plan's bus peak
        (the peak between the samples included); without storage the cap is lowered by the measured
        overshoot."""
        limit = dense.case.drive.grid.peak_power_kW
        p = dense.power
        check = Check.of(self.id, self.name, p.grid_peak_kW, limit, self.unit, "max", LIMIT_REL_TOL * limit)
        if not _storage_counts(dense.case):  # planned as without storage: the cap lowered by the overshoot
            return [check]
        needed, usable = p.storage_for_limit_kJ, p.storage_usable_kJ
        if needed is not None and needed > usable:  # at most the energy the plan needs, scaled by what there is
            eta = dense.case.drive.storage.efficiency
            return [replace(check, refine_by=("grid_allowance", usable / needed, eta * needed * 1e3))]
        if p.bus_cap_for_limit_kW is not None and p.bus_peak_kW > p.bus_cap_for_limit_kW:
            # at most the plan's bus peak, scaled by the level the storage could hold over that peak
            factor = p.bus_cap_for_limit_kW / p.bus_peak_kW
            return [replace(check, refine_by=("grid_cap", factor, p.bus_peak_kW * 1e3))]
        return [check]

    def relaxed_rows(self, mesh: Any) -> None:
        """Not in the upper bound (the storage's state couples the whole cycle): left out."""
        return None


def bus_power(motor_torque_Nm: Any, motor_speed_rad_s: Any, copper: Any, converter: Any) -> Any:
    """The bus's power [W] an NLP's rows hold (numbers or symbols): ``(T_m omega_m + k T_m^2) / eta_c``, ``k``
    the copper coefficient [W/(N m)^2], ``eta_c`` the converter's efficiency (a braking sample's is below the
    cap anyway)."""
    return (motor_torque_Nm * motor_speed_rad_s + copper * motor_torque_Nm**2) / converter


def _storage_counts(case: Any) -> bool:
    """Whether the case's storage enters the plan: it can give more than the energy row's smoothing adds on its
    own (eps / 2 over the robot's transfer time, a lower bound of the cycle). A smaller storage is planned as
    none (the grid held at the limit by the cap alone); the verification still runs its schedule."""
    d = case.drive
    s = d.storage
    if s is None:
        return False
    smoothing = EXCESS_SMOOTHING * d.grid.peak_power_kW * 1e3 / 2 * case.transfer_time_s  # [J]
    return s.efficiency * s.usable_energy_kJ * 1e3 > smoothing


def _most_bus_power(case: Any) -> float:
    """The most the motors can draw from the bus [W]: the peak torque at the base speed (the envelope's
    constant power), with its copper loss, through the converter."""
    m = case.drive.motor
    return float(drive_chain(m.peak_torque_Nm, m.peak_torque_Nm * m.base_speed_rpm * RPM, case.drive)["bus_power_W"])


def drive_chain(motor_torque_Nm: Any, shaft_power_W: Any, drive: Any) -> dict[str, Any]:
    """``press.power.chain`` with the case's ``drive`` section's figures."""
    m = drive.motor
    return chain(
        motor_torque_Nm, shaft_power_W, m.rated_torque_Nm, m.copper_loss_at_rated_kW * 1e3, drive.converter_efficiency
    )
