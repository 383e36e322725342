"""The slide moves no faster than ``limits.slider_speed_mm_s`` anywhere in the cycle (optional): a press
whose guides, lubrication or die set cap the slide's speed."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import (
    Check,
    Draw,
    Impossible,
    Row,
    Transcription,
)
from planning.model.limits.canonical import SpeedCap
from planning.model.units import SliderSpeed
from planning.tolerances import SAME_RELATIVE, SPEED_BACKOFF


class SliderSpeedLimit(SpeedCap):
    """|v| = |dh/dtheta w| <= the limit (a speed cap, ``k = h'``): at every sample of an NLP outside the draw
    (refined against the dense check), in the draw at constant speed (a bound on the draw speed: the largest
    |dh/dtheta| there), at every node of the bound (a bound on the speed squared, ``(v / |dh/dtheta|)^2``)."""

    id = "slider_speed"
    name = "|slider speed|"
    unit = "mm/s"
    field = "limits.slider_speed_mm_s"
    order = 47
    section_fields = {
        "slider_speed_mm_s": (
            SliderSpeed | None,
            Field(
                None,
                title="slide speed limit [mm/s]",
                description="The slide's |speed| anywhere in the cycle; empty: none.",
            ),
        ),
    }
    parameters = ("slider_speed_max",)
    refined = "slider_speed_max"
    backoff = SPEED_BACKOFF

    def applies(self, case: Any) -> bool:
        return case.limits.slider_speed_mm_s is not None

    def limit(self, case: Any) -> float:
        return case.limits.slider_speed_mm_s

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        limit = draw.case.limits.slider_speed_mm_s
        fastest = float(np.max(np.abs(draw.d1))) * speed
        name = "|slider speed| during the draw <= limits.slider_speed_mm_s"
        return [Check.of(self.id, name, fastest, limit, self.unit, "max", 0.0)]

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        if given is None:
            return None
        bound = self.draw_speed_bound(Draw.of(case))
        if given <= bound * (1 + SAME_RELATIVE):
            return None
        limit = case.limits.slider_speed_mm_s
        return Impossible(
            f"at the draw speed {case.process.draw_speed_rpm:g} rpm the slider moves at up to "
            f"{limit * given / bound:.1f} mm/s in the draw > limits.slider_speed_mm_s = {limit:g}",
            self.field,
            limit,
            limit * given / bound,
        )

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"slider_speed_max": case.limits.slider_speed_mm_s * (1 - self.backoff)}

    def rows(self, nlp: Transcription) -> list[Row]:
        speed = nlp.outside_draw(nlp.slope * nlp.omega)
        return [Row("slider speed", speed / nlp.param("slider_speed_max"), -1.0, 1.0, sampled=True)]
