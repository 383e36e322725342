"""The drive's acceleration limit on the crank, ``limits.crank_accel_rad_s2`` (optional)."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import RelaxedMesh
from planning.model.limits.canonical import AccelLimit
from planning.model.units import CrankAccel


class CrankAccelLimit(AccelLimit):
    """``|alpha| <= C`` (canonical: ``a = 1``, ``b = 0``): at the closed-form peaks of a law's halves (3/2 J T for
    the improved S-curve), at a free profile's knots (it is piecewise linear there), on the bound's
    intervals; in the certified upper bound ``mu = 1``, ``I = 2 theta`` (``ds/dtheta = 2 alpha``)."""

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
    parameter = "crank_accel_max"
    row_name = "crank acceleration limit"
    crank_only = True

    def applies(self, case: Any) -> bool:
        return case.limits.crank_accel_rad_s2 is not None

    def coefficients(self, theta: Any, d1: Any, d2: Any) -> tuple[Any, Any]:
        return 1.0, 0.0

    def cap(self, case: Any) -> float:
        return case.limits.crank_accel_rad_s2

    def integrating_factor(self, mesh: RelaxedMesh) -> tuple[Any, Any, Any, Any, Any]:
        return np.ones(mesh.theta.size), 1.0, 2 * mesh.theta, 2 * mesh.a, 2 * mesh.b

    def relaxed_rows(self, mesh: RelaxedMesh) -> list[tuple[Any, Any, Any]]:
        """The canonical relaxed rows divided by ``I_(i+1) - I_i = 2 (theta_(i+1) - theta_i)``: each interval's
        mean acceleration over angle, ``(s_(i+1) - s_i) / (2 dtheta)`` (the mesh's ``alpha``), lies within the
        limit as every value does: the grid bound's rows on the means."""
        return self.bound_rows(mesh)
