"""The slide meets the blank no faster than ``limits.draw_start_speed_mm_s``: its speed at theta2."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import Check, Dense, Draw, Limit, Row, Transcription
from planning.model.units import SliderSpeed
from planning.tolerances import LIMIT_REL_TOL


class DrawStartSpeedLimit(Limit):
    """|slide speed| at theta2 <= the limit. The draw runs at constant crank speed, so this bounds the draw
    speed alone (the NLPs hold it through the draw speed's bounds); a free draw's NLP holds it at theta2."""

    id = "draw_start_speed"
    name = "slider speed at the draw start"
    unit = "mm/s"
    field = "limits.draw_start_speed_mm_s"
    order = 20
    section_fields = {
        "draw_start_speed_mm_s": (
            SliderSpeed,
            Field(
                ...,
                title="draw-start speed [mm/s]",
                description="The slide's highest speed at θ2, where it meets the blank.",
            ),
        ),
    }
    refuses_draw_speed_above_bound = True

    def draw_speed_bound(self, draw: Draw) -> float:
        slope = abs(float(draw.d1[0]))  # the draw's first angle is theta2
        return draw.case.limits.draw_start_speed_mm_s / slope if slope > 0 else math.inf

    parameters = ("draw_start_speed",)

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"draw_start_speed": case.limits.draw_start_speed_mm_s}

    def rows(self, nlp: Transcription) -> list[Row]:
        """A free draw (a draw at constant slide speed) starts at its first sample, theta2: the slide's speed
        there (the draw speed's bounds hold it otherwise)."""
        if not nlp.free_draw_count:
            return []
        first = nlp.in_free_draw(nlp.slope * nlp.omega)[0]
        return [Row("slider speed at the draw start", first / nlp.param("draw_start_speed"), -1.0, 1.0)]

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        limit = draw.case.limits.draw_start_speed_mm_s
        v = abs(float(draw.d1[0])) * speed
        return [
            Check.of(
                self.id, "slider speed at draw start <= limits.draw_start_speed_mm_s", v, limit, self.unit, "max", 0.0
            )
        ]

    def check(self, dense: Dense) -> list[Check]:
        plan, case = dense.plan, dense.case
        v2 = abs(float(dense.key_motion["v"][1]))  # at theta2's time: the draw speed times h' there
        limit = case.limits.draw_start_speed_mm_s
        check = Check.of(self.id, self.name, v2, limit, self.unit, "max", LIMIT_REL_TOL * limit)
        t2 = dense.key_times[1:2]
        return [check.located(t2, np.array(plan.key_angles[1:2]), np.array([v2]), limit)]
