"""The drive's top speed on the crank, ``limits.crank_speed_rpm`` (optional)."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.errors import CaseError
from planning.model.limits.base import Draw, Row, Transcription
from planning.model.limits.canonical import SpeedCap
from planning.model.units import RPM, CrankSpeed
from planning.tolerances import SAME_RELATIVE


class CrankSpeedLimit(SpeedCap):
    """crank speed <= the limit (a speed cap with ``k = 1``): at the speeds a law's halves join (its peaks),
    or at a free profile's samples; a bound on the draw speed and on the bound's speeds."""

    id = "crank_speed"
    name = "crank speed <= limits.crank_speed_rpm"
    unit = "rpm"
    field = "limits.crank_speed_rpm"
    order = 50
    section_fields = {
        "crank_speed_rpm": (
            CrankSpeed | None,
            Field(
                None, title="crank speed limit [rpm]", description="The drive's top speed, on the crank; empty: none."
            ),
        ),
    }
    parameters = ("crank_speed_max",)
    refined = "crank_speed_max"
    unit_divisor = RPM

    def applies(self, case: Any) -> bool:
        return case.limits.crank_speed_rpm is not None

    def validate(self, case: Any) -> None:
        top, lowest = case.limits.crank_speed_rpm, case.limits.min_crank_speed_rpm
        if top is not None and top <= lowest:
            raise CaseError(self.field, f"must be above limits.min_crank_speed_rpm = {lowest:g}", top)

    def limit(self, case: Any) -> float:
        return case.limits.crank_speed_rpm

    def crank_factor(self, case: Any) -> float:
        return 1.0

    def top_crank_speed(self, case: Any) -> float | None:
        top = case.limits.crank_speed_rpm
        return None if top is None else top * RPM

    def refuse_draw_speed(self, draw: Draw, speed: float) -> str | None:
        top = self.top_crank_speed(draw.case)
        if speed <= top * (1 + SAME_RELATIVE):
            return None
        return f"is above {self.field} = {draw.case.limits.crank_speed_rpm:g}"

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"crank_speed_max": case.limits.crank_speed_rpm * RPM}

    def rows(self, nlp: Transcription) -> list[Row]:
        peaks = nlp.speeds
        return [Row("crank speed limit", peaks.values / nlp.param("crank_speed_max"), -np.inf, 1.0, peaks.sampled)]
