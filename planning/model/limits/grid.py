"""The plant's limit on the press's draw from the grid (``drive.grid.peak_power_kW``), with the DC-bus storage's
schedule (``planning.solver.grid``; the chain and its signs: ``press.power``)."""

from __future__ import annotations

from typing import Any

from planning.model.limits.base import REL_TOL, Check, Dense, Limit


class GridPeakLimit(Limit):
    """The grid's power <= ``drive.grid.peak_power_kW`` over the cycle, the storage's schedule the one that
    shaves the peak most (checked on the dense grid)."""

    id = "grid_peak_power"
    name = "grid peak power"
    unit = "kW"
    field = "drive.grid.peak_power_kW"
    order = 110
    motor = True
    uses_drive = True

    def applies(self, case: Any) -> bool:
        d = case.drive
        return d is not None and d.grid is not None and d.grid.peak_power_kW is not None

    def check(self, dense: Dense) -> list[Check]:
        limit = dense.case.drive.grid.peak_power_kW
        peak = dense.power.grid_peak_kW
        return [Check.of(self.id, self.name, peak, limit, self.unit, "max", REL_TOL * limit)]

    def relaxed_rows(self, grid: Any) -> None:
        """Not in the upper bound (the storage's state couples the whole cycle): left out."""
        return None
