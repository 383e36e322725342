"""The crank keeps turning forward, never slower than ``limits.min_crank_speed_rpm``."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import BoundMesh, Check, Dense, Draw, Limit, Row, Transcription
from planning.model.units import RPM, CrankSpeed
from planning.tolerances import LIMIT_REL_TOL, SAME_RELATIVE


class MinCrankSpeedLimit(Limit):
    """crank speed >= the minimum. A law's halves are monotone, so their NLP holds it by the bounds of the
    speeds they join; a free profile holds it at its samples (refined upward, a lower limit)."""

    id = "min_crank_speed"
    name = "crank speed (forward, never stops)"
    unit = "rpm"
    field = "limits.min_crank_speed_rpm"
    order = 45
    section_fields = {
        "min_crank_speed_rpm": (
            CrankSpeed,
            Field(
                1.0,
                title="least crank speed [rpm]",
                description="The crank never turns slower (never stops or reverses).",
            ),
        ),
    }
    parameters = ("min_crank_speed",)
    refined = "min_crank_speed"
    refine_upward = True

    def refuse_draw_speed(self, draw: Draw, speed: float) -> str | None:
        lowest = draw.case.limits.min_crank_speed_rpm
        return f"is below {self.field} = {lowest:g}" if speed < lowest * RPM * (1 - SAME_RELATIVE) else None

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"min_crank_speed": case.limits.min_crank_speed_rpm * RPM}

    def rows(self, nlp: Transcription) -> list[Row]:
        if nlp.lowest_speeds is None:
            return []
        margin = (nlp.lowest_speeds - nlp.param("min_crank_speed")) / nlp.speed_unit
        return [Row("minimum crank speed", margin, 0.0, np.inf, sampled=True)]

    def check(self, dense: Dense) -> list[Check]:
        lowest = dense.case.limits.min_crank_speed_rpm
        slowest = float(np.min(dense.omega)) / RPM
        check = Check.of(self.id, self.name, slowest, lowest, self.unit, "min", LIMIT_REL_TOL * lowest)
        return [check.located(dense.t, dense.theta, dense.omega / RPM, lowest)]

    def bound_speeds(self, mesh: BoundMesh) -> tuple[np.ndarray | None, np.ndarray | None]:
        w_min = mesh.case.limits.min_crank_speed_rpm * RPM
        return np.full(mesh.dtheta.size, w_min**2), None
