"""The drive's electrical side, from the motor shaft to the plant's grid (README, "From the motor to the grid").

Signs: every power is positive when it flows from the grid toward the crank (the motors draw), negative when
the crank drives the motors back (braking). SI inside: W, N m, J.

- Copper loss of the motors (all together): ``P_cu = P_cu,rated (T_m / T_rated)^2``, never negative.
- Electrical power of the motors: ``P_el = T_m omega_m + P_cu``.
- DC bus (the converter between the bus and the motors, efficiency ``eta_c`` both ways):
  ``P_bus = P_el / eta_c`` when ``P_el >= 0``, ``P_el eta_c`` when braking.
- Storage on the bus: it takes ``c >= 0`` from the bus (stores ``eta_s c``) or gives ``d >= 0`` to it (takes
  ``d / eta_s`` from its store); the bus's net need from outside is ``x = P_bus + c - d``.
- Grid: ``P_grid = x`` when ``x >= 0``; when ``x < 0`` the grid takes back ``r |x|`` (``r``:
  ``drive.regen_efficiency``), ``P_grid = r x``, and the braking resistor burns ``(1 - r) |x|``.

Every function works on numpy arrays and on CasADi symbols (``press.backend``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from press.backend import math_module


def _where(condition: Any, yes: Any, no: Any) -> Any:
    m = math_module(yes, no)
    return np.where(condition, yes, no) if m is np else m.if_else(condition, yes, no)


def copper_loss(motor_torque_Nm: Any, rated_torque_Nm: float, loss_at_rated_W: float) -> Any:
    """The motors' copper loss [W]: ``P_cu,rated (T_m / T_rated)^2``."""
    return loss_at_rated_W * (motor_torque_Nm / rated_torque_Nm) ** 2


def electrical_power(shaft_power_W: Any, copper_loss_W: Any) -> Any:
    """The motors' electrical power [W]: shaft power plus copper loss."""
    return shaft_power_W + copper_loss_W


def bus_power(electrical_power_W: Any, converter_efficiency: float) -> Any:
    """The DC bus's power [W] to the motors' converter: ``P_el / eta_c`` driving, ``P_el eta_c`` braking."""
    p = electrical_power_W
    return _where(p >= 0, p / converter_efficiency, p * converter_efficiency)


def grid_power(net_power_W: Any, regen_efficiency: float) -> Any:
    """The grid's power [W] for the bus's net need ``x`` (bus power plus storage charging minus discharging):
    ``x`` when it is positive, ``r x`` when negative (the grid takes back the share ``r``)."""
    x = net_power_W
    return _where(x >= 0, x, regen_efficiency * x)


def resistor_power(net_power_W: Any, regen_efficiency: float) -> Any:
    """The braking resistor's power [W] (never negative): ``(1 - r) max(-x, 0)``."""
    m = math_module(net_power_W)
    x = net_power_W
    surplus = np.maximum(-x, 0.0) if m is np else m.fmax(-x, 0)
    return (1.0 - regen_efficiency) * surplus


def storage_rate(charge_W: Any, discharge_W: Any, efficiency: float) -> Any:
    """The storage's energy rate [W]: ``eta_s c - d / eta_s``."""
    return efficiency * charge_W - discharge_W / efficiency


def storage_loss(charge_W: Any, discharge_W: Any, efficiency: float) -> Any:
    """The storage's loss [W]: ``(1 - eta_s) c + (1 / eta_s - 1) d``."""
    return (1.0 - efficiency) * charge_W + (1.0 / efficiency - 1.0) * discharge_W


def chain(
    motor_torque_Nm: Any,
    shaft_power_W: Any,
    rated_torque_Nm: float,
    loss_at_rated_W: float,
    converter_efficiency: float,
) -> dict[str, Any]:
    """The chain from the shaft to the DC bus [W]: ``copper_loss_W``, ``electrical_power_W``, ``bus_power_W``."""
    cu = copper_loss(motor_torque_Nm, rated_torque_Nm, loss_at_rated_W)
    el = electrical_power(shaft_power_W, cu)
    return {"copper_loss_W": cu, "electrical_power_W": el, "bus_power_W": bus_power(el, converter_efficiency)}
