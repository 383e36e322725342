"""The plant's limit on the press's draw from the grid (``drive.grid.peak_power_kW``), with the DC-bus storage's
schedule (``planning.solver.grid``; the chain and its signs: ``press.power``).

In a drive NLP the limit caps the bus power at every sample, ``P_bus <= cap`` (the parameter ``grid_cap``; the
row ``(T_m omega_m + P_cu) / (eta_c cap) <= 1``, which a braking sample meets anyway). Without storage the cap is
the limit itself (refined by the measured overshoot between the samples, like the motor's torque). With
storage the grid sees the bus less what the storage gives, and the cap starts where the storage could carry any
excess (the limit plus the storage's power limit, or the most the motors can draw): the plan the other limits
allow comes first, and when the storage's best schedule (the peak-shaving programme) leaves the grid above its
limit, the cap goes to the highest level at which the storage could hold the limit were that plan's bus power
clipped there (``planning.solver.grid.bus_cap_for_limit``), and the plan is solved again. That is a
search over the one cap, not the storage's state inside the NLP: its plans are verified, not proven the fastest
(the README says so).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from planning.model.limits.base import REL_TOL, Check, Dense, Impossible, Limit, Row, Transcription
from planning.model.limits.motor import draw_drive_state
from planning.model.units import RPM
from press.power import chain

CAP_HEADROOM = 1.01  # the starting cap with storage: this much above the most the motors can draw from the bus


class GridPeakLimit(Limit):
    """The grid's power <= ``drive.grid.peak_power_kW`` over the cycle, the storage's schedule the one that
    shaves the peak most (module docstring); checked on the dense grid."""

    id = "grid_peak_power"
    name = "grid peak power"
    unit = "kW"
    field = "drive.grid.peak_power_kW"
    order = 110
    parameters = ("grid_cap", "grid_copper", "grid_converter")
    refined = "grid_cap"
    backoff = 5e-5
    motor = True
    uses_drive = True

    def applies(self, case: Any) -> bool:
        d = case.drive
        return d is not None and d.grid is not None and d.grid.peak_power_kW is not None

    def parameter_values(self, case: Any) -> dict[str, float]:
        d = case.drive
        limit = d.grid.peak_power_kW * 1e3
        cap = limit * (1 - self.backoff)
        if d.storage is not None:
            top = _most_bus_power(case) * CAP_HEADROOM
            if d.storage.max_power_kW is not None:
                top = min(top, limit + d.storage.max_power_kW * 1e3)
            cap = max(cap, top)
        rated = d.motor.rated_torque_Nm
        return {
            "grid_cap": cap,
            "grid_copper": d.motor.copper_loss_at_rated_kW * 1e3 / rated**2,
            "grid_converter": d.converter_efficiency,
        }

    def rows(self, nlp: Transcription) -> list[Row]:
        tm = nlp.motor_torque
        electrical = tm * nlp.motor_speed + nlp.param("grid_copper") * tm**2
        expr = electrical / (nlp.param("grid_converter") * nlp.param("grid_cap"))
        return [Row("grid peak power", expr, -np.inf, 1.0, True)]

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """The draw runs at constant speed, so its bus power is known before any plan; at the lowest draw
        speed the case allows it is the least (the power grows with the speed, and so does the energy above
        the limit, ``integral (P - L) dtheta / w2``). Above the limit the storage must carry the excess: its
        power, and its energy within ``eta_s`` times the usable energy (it cannot start fuller)."""
        d = case.drive
        limit = d.grid.peak_power_kW * 1e3
        w2 = given if given is not None else lowest
        theta, state = draw_drive_state(case, w2)
        bus = _chain(state["motor_torque_Nm"], state["motor_power_W"], d)["bus_power_W"]
        k = int(np.argmax(bus))
        if bus[k] <= limit * (1 + REL_TOL):
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
        limit = dense.case.drive.grid.peak_power_kW
        p = dense.power
        refine_to = None  # without storage: the cap lowered by the measured overshoot
        if p.bus_cap_for_limit_kW is not None:  # with storage: the cap at which it could hold the limit
            refine_to = p.bus_cap_for_limit_kW * 1e3
        check = Check.of(self.id, self.name, p.grid_peak_kW, limit, self.unit, "max", REL_TOL * limit)
        return [replace(check, refine_to=refine_to)]

    def relaxed_rows(self, grid: Any) -> None:
        """Not in the upper bound (the storage's state couples the whole cycle): left out."""
        return None


def _most_bus_power(case: Any) -> float:
    """The most the motors can draw from the bus [W]: the peak torque at the base speed (the envelope's
    constant power), with its copper loss, through the converter."""
    m = case.drive.motor
    return float(_chain(m.peak_torque_Nm, m.peak_torque_Nm * m.base_speed_rpm * RPM, case.drive)["bus_power_W"])


def _chain(motor_torque_Nm: Any, shaft_power_W: Any, drive: Any) -> dict[str, Any]:
    """``press.power.chain`` with the case's ``drive`` section's figures."""
    m = drive.motor
    return chain(
        motor_torque_Nm, shaft_power_W, m.rated_torque_Nm, m.copper_loss_at_rated_kW * 1e3, drive.converter_efficiency
    )
