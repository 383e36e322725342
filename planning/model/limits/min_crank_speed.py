"""The crank keeps turning forward, never slower than ``limits.min_crank_speed_rpm``."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import Draw, Row, Transcription
from planning.model.limits.canonical import SpeedCap
from planning.model.units import RPM, CrankSpeed
from planning.tolerances import SAME_RELATIVE


class MinCrankSpeedLimit(SpeedCap):
    """crank speed >= the minimum (a lower speed cap, ``k = 1``). A law's halves are monotone, so their NLP
    holds it by the bounds of the speeds they join; a free profile holds it at its samples (refined upward, a
    lower limit)."""

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
    lower = True
    unit_divisor = RPM

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

    def limit(self, case: Any) -> float:
        return case.limits.min_crank_speed_rpm

    def crank_factor(self, case: Any) -> float:
        return 1.0
