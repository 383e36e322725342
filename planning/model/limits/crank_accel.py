"""The drive's acceleration limit on the crank, ``limits.crank_accel_rad_s2`` (optional)."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import REL_TOL, BoundGrid, Check, Dense, Limit, Row, Transcription
from planning.model.units import CrankAccel


class CrankAccelLimit(Limit):
    """|crank acceleration| <= the limit: at the closed-form peaks of a law's halves (3/2 J T for the improved
    S-curve), at a free profile's knots (it is piecewise linear there), on the bound's intervals."""

    id = "crank_accel"
    name = "|crank acceleration| <= limits.crank_accel_rad_s2"
    unit = "rad/s^2"
    field = "limits.crank_accel_rad_s2"
    order = 60
    section_fields = {
        "crank_accel_rad_s2": (
            CrankAccel | None,
            Field(
                None,
                title="crank acceleration limit [rad/s²]",
                description="The drive's |acceleration|, on the crank; empty: none.",
            ),
        ),
    }
    parameters = ("crank_accel_max",)

    def applies(self, case: Any) -> bool:
        return case.limits.crank_accel_rad_s2 is not None

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"crank_accel_max": case.limits.crank_accel_rad_s2}

    def rows(self, nlp: Transcription) -> list[Row]:
        peaks = nlp.accelerations
        lo = -1.0 if peaks.signed else -np.inf
        return [Row("crank acceleration limit", peaks.values / nlp.param("crank_accel_max"), lo, 1.0)]

    def check(self, dense: Dense) -> list[Check]:
        limit = dense.case.limits.crank_accel_rad_s2
        peak = float(np.max(np.abs(dense.alpha)))
        return [Check.of(self.id, self.name, peak, limit, self.unit, "max", REL_TOL * limit)]

    def bound_rows(self, grid: BoundGrid) -> list[tuple[Any, Any, Any]]:
        limit = grid.case.limits.crank_accel_rad_s2
        n = grid.dtheta.size
        return [(grid.alpha, -limit * np.ones(n), limit * np.ones(n))]
