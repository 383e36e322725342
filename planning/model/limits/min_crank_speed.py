"""The crank keeps turning forward, never slower than ``limits.min_crank_speed_rpm`` (but in a hold's planned stop)."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import BoundMesh, Check, Dense, Draw, Row, Transcription
from planning.model.limits.canonical import SpeedCap
from planning.model.units import RPM, CrankSpeed
from planning.tolerances import HOLD_STILL_RAD_S, SAME_RELATIVE

IN_A_HOLD = "crank speed (forward, stopping only in the hold)"  # the check's name in a case with a hold
IN_THE_STOP = "crank speed in the hold's stop (forward or standing)"  # and the stop's own


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
                description="The crank never turns slower (never stops or reverses; a hold's stop excepted).",
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

    def check(self, dense: Dense) -> list[Check]:
        """The least crank speed over the cycle but the hold's planned stop (``Plan.in_planned_stop``): there
        the crank brakes to rest, stands and rises again by design, and only turns forward or stands (never
        backwards beyond :data:`~planning.tolerances.HOLD_STILL_RAD_S`)."""
        stop = dense.plan.in_planned_stop(dense.theta, dense.case)
        if not stop.any():
            return super().check(dense)
        moving = ~stop
        fields = ("t", "theta", "omega", "alpha", "jerk", "h", "v", "a", "slope")
        kept = {f: getattr(dense, f)[moving] for f in fields if getattr(dense, f) is not None}
        out = [replace(c, name=IN_A_HOLD) for c in super().check(replace(dense, **kept))]
        k = int(np.argmin(np.where(stop, dense.omega, np.inf)))
        lowest = float(dense.omega[k]) / RPM
        # at least "standing" (-HOLD_STILL_RAD_S): a standstill (0) is no binding limit of the strokes
        forward = Check.of(self.id, IN_THE_STOP, lowest, -HOLD_STILL_RAD_S / RPM, self.unit, "min", 0.0)
        return out + [forward.located(dense.t[k : k + 1], dense.theta[k : k + 1], np.array([lowest]), 1.0)]

    def bound_speeds(self, mesh: BoundMesh) -> tuple[np.ndarray | None, np.ndarray | None]:
        """None with a hold (the crank stops there, and where its stop begins and ends is the plan's: the bounds
        leave the least crank speed out, which only loosens them), else the cap's."""
        if mesh.case.hold_angle is not None:
            return None, None
        return super().bound_speeds(mesh)

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
