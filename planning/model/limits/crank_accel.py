"""The drive's acceleration limit on the crank, ``limits.crank_accel_rad_s2`` (optional)."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import (
    BoundMesh,
    Check,
    Dense,
    Envelope,
    Limit,
    RelaxedMesh,
    Row,
    Transcription,
)
from planning.model.units import CrankAccel
from planning.tolerances import LIMIT_REL_TOL


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
        accel = np.abs(dense.alpha)
        check = Check.of(self.id, self.name, float(np.max(accel)), limit, self.unit, "max", LIMIT_REL_TOL * limit)
        return [check.located(dense.t, dense.theta, accel, limit)]

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        limit = mesh.case.limits.crank_accel_rad_s2
        n = mesh.dtheta.size
        return [(mesh.alpha, -limit * np.ones(n), limit * np.ones(n))]

    def relaxed_rows(self, mesh: RelaxedMesh) -> list[tuple[Any, Any, Any]]:
        """Each interval's mean acceleration over angle lies within the limit as every value does: the grid
        bound's rows on the means."""
        return self.bound_rows(mesh)

    def relaxed_envelopes(self, mesh: RelaxedMesh) -> list[Envelope]:
        """``ds/dtheta = 2 alpha``: over a piece [a, b] of interval i, ``s <= s_i + 2 A_c (b - theta_i)`` and
        ``s <= s_(i+1) + 2 A_c (theta_(i+1) - a)``."""
        limit = mesh.case.limits.crank_accel_rad_s2
        every = np.ones(mesh.cell.size, dtype=bool)
        start, end = mesh.theta[mesh.cell], mesh.theta[mesh.cell + 1]
        return [
            Envelope(mesh.s_a + 2 * limit * (mesh.b - start), every, "start"),
            Envelope(mesh.s_b + 2 * limit * (end - mesh.a), every, "end"),
        ]
