"""The drive's jerk limit on the crank, ``limits.crank_jerk_rad_s3`` (optional; the optimal law plans under it)."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import (
    BoundMesh,
    Check,
    Dense,
    Limit,
    RelaxedMesh,
    Row,
    Transcription,
    sample_vector,
)
from planning.model.profile import max_abs_jerk
from planning.model.units import CrankJerk
from planning.tolerances import LIMIT_REL_TOL


class CrankJerkLimit(Limit):
    """|crank jerk| <= the limit: at the closed-form peaks of a law's halves; a free profile holds it by the
    bounds of its segments' jerks. In the grid bound, between neighbouring intervals
    ``|alpha_{i+1} - alpha_i| <= J (tau_i + tau_{i+1}) / 2`` (linear in the bound's variables, an estimate);
    in the certified upper bound, rows that every motion within the limit meets (:meth:`relaxed_rows`)."""

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
        check = Check.of(self.id, self.name, peak, limit, self.unit, "max", LIMIT_REL_TOL * limit)
        return [check.located(dense.t, dense.theta, np.abs(dense.jerk), limit)]

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        """Neighbouring intervals' accelerations differ by at most J times half their joint time."""
        return _jerk_rows(mesh, 0.5)

    def relaxed_rows(self, mesh: RelaxedMesh) -> list[tuple[Any, Any, Any]]:
        """An interval's mean acceleration over angle is a value the acceleration takes within it, so the
        means of intervals i and i + m - 1 differ by at most ``J`` times the time of the m intervals from
        i to i + m - 1 (the grid bound's half is an estimate, not a bound); for m in :data:`RELAXED_SPANS`:
        on a long jerk ramp the rows over m intervals allow ``m / (m - 1)`` times the jerk (twice it over
        a pair of neighbours, 4/3 over four intervals)."""
        J = mesh.case.limits.crank_jerk_rad_s3
        n = mesh.dtheta.size
        rows = []
        window, m = mesh.tau, 1  # window[i]: the time of the m intervals from i on (cyclic)
        for span in RELAXED_SPANS:
            while m < span:
                window, m = window + _shifted(window, m), 2 * m
            if span > n:
                break
            change = _shifted(mesh.alpha, span - 1) - mesh.alpha
            rows += [
                (change - J * window, np.full(n, -np.inf), np.zeros(n)),
                (change + J * window, np.zeros(n), np.full(n, np.inf)),
            ]
        return rows


RELAXED_SPANS = (2, 4)  # intervals spanned by the relaxed jerk rows (powers of two; 8 and 16 tighten the
# servo-limits case by another 0.03 % at nearly twice the time)


def _shifted(values: Any, k: int) -> Any:
    """``values`` moved k places cyclically: element i is ``values[(i + k) % n]``."""
    return sample_vector([values[k:], values[:k]])


def _jerk_rows(mesh: BoundMesh, share: float) -> list[tuple[Any, Any, Any]]:
    """``|alpha_(i+1) - alpha_i| <= J share (tau_i + tau_(i+1))`` over every pair of neighbouring intervals."""
    J = mesh.case.limits.crank_jerk_rad_s3
    alpha_next = sample_vector([mesh.alpha[1:], mesh.alpha[0]])
    room = J * share * (mesh.tau + mesh.tau_next)
    n = mesh.dtheta.size
    return [
        (alpha_next - mesh.alpha - room, np.full(n, -np.inf), np.zeros(n)),
        (alpha_next - mesh.alpha + room, np.zeros(n), np.full(n, np.inf)),
    ]
