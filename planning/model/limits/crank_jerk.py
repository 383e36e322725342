"""The drive's jerk limit on the crank, ``limits.crank_jerk_rad_s3`` (optional; the optimal law plans under it)."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import (
    REL_TOL,
    BoundGrid,
    Check,
    Dense,
    Limit,
    RelaxedGrid,
    Row,
    Transcription,
    sample_vector,
)
from planning.model.profile import max_abs_jerk
from planning.model.units import CrankJerk


class CrankJerkLimit(Limit):
    """|crank jerk| <= the limit: at the closed-form peaks of a law's halves; a free profile holds it by the
    bounds of its segments' jerks. In the bound, between neighbouring intervals
    ``|alpha_{i+1} - alpha_i| <= J (tau_i + tau_{i+1}) / 2`` (linear in the bound's variables; since tau is
    at least the interval's time it relaxes the jerk limit, and the bound stays an upper bound)."""

    id = "crank_jerk"
    name = "|crank jerk| <= limits.crank_jerk_rad_s3"
    unit = "rad/s^3"
    field = "limits.crank_jerk_rad_s3"
    order = 70
    section_fields = {
        "crank_jerk_rad_s3": (
            CrankJerk | None,
            Field(
                None,
                title="crank jerk limit [rad/s³]",
                description="The drive's |jerk|, on the crank; empty: none (the optimal law needs one).",
            ),
        ),
    }
    parameters = ("crank_jerk_max",)

    def applies(self, case: Any) -> bool:
        return case.limits.crank_jerk_rad_s3 is not None

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"crank_jerk_max": case.limits.crank_jerk_rad_s3}

    def rows(self, nlp: Transcription) -> list[Row]:
        if nlp.jerks is None:
            return []
        lo = -1.0 if nlp.jerks.signed else -np.inf
        return [Row("crank jerk limit", nlp.jerks.values / nlp.param("crank_jerk_max"), lo, 1.0)]

    def check(self, dense: Dense) -> list[Check]:
        limit = dense.case.limits.crank_jerk_rad_s3
        peak = max_abs_jerk(dense.plan.profile)
        return [Check.of(self.id, self.name, peak, limit, self.unit, "max", REL_TOL * limit)]

    def bound_rows(self, grid: BoundGrid) -> list[tuple[Any, Any, Any]]:
        """Neighbouring intervals' accelerations differ by at most J times half their joint time."""
        return _jerk_rows(grid, 0.5)

    def relaxed_rows(self, grid: RelaxedGrid) -> list[tuple[Any, Any, Any]]:
        """The mean accelerations of two neighbouring intervals are values the acceleration takes within
        their joint time, so they differ by at most ``J (tau_i + tau_(i+1))`` (the grid bound's half is an
        estimate, not a bound)."""
        return _jerk_rows(grid, 1.0)


def _jerk_rows(grid: BoundGrid, share: float) -> list[tuple[Any, Any, Any]]:
    """``|alpha_(i+1) - alpha_i| <= J share (tau_i + tau_(i+1))`` over every pair of neighbouring intervals."""
    J = grid.case.limits.crank_jerk_rad_s3
    alpha_next = sample_vector([grid.alpha[1:], grid.alpha[0]])
    room = J * share * (grid.tau + grid.tau_next)
    n = grid.dtheta.size
    return [
        (alpha_next - grid.alpha - room, np.full(n, -np.inf), np.zeros(n)),
        (alpha_next - grid.alpha + room, np.zeros(n), np.full(n, np.inf)),
    ]
