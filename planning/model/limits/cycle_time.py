"""At the line's rate the cycle time is the target's, ``60 / planner.target_spm`` a stroke (a pendulum's cycle: two)."""

from __future__ import annotations

from typing import Any

import numpy as np

from planning.model.limits.base import Check, Dense, Limit, Row, Transcription
from planning.tolerances import TIME_TOL_S


class CycleTimeLimit(Limit):
    """The cycle time of a plan at a target rate (objectives ``min-rms-torque``, ``min-energy``; a press in a
    line, ``planning.solver.line``): one row of the rate NLP, free until a solve holds it at the parameter
    ``target_period`` (bounds set per solve); checked on every plan of a case planned at a rate (a line's press,
    planned for the most strokes with the line's rate beside it, by the line's own check instead)."""

    id = "cycle_time"
    name = "cycle time at the target rate"
    unit = "s"
    field = "planner.target_spm"
    order = 110
    parameters = ("target_period",)
    goal = True

    def applies(self, case: Any) -> bool:
        return case.drive is not None or case.planner.target_spm is not None

    def parameter_values(self, case: Any) -> dict[str, float]:
        target = case.planner.target_spm
        return {"target_period": 60.0 / target if target else 0.0}

    def rows(self, nlp: Transcription) -> list[Row]:
        if not nlp.rate:
            return []
        return [Row("cycle time", nlp.period - nlp.param("target_period"), -np.inf, np.inf)]

    def check(self, dense: Dense) -> list[Check]:
        planner = dense.case.planner
        if planner.objective == "max-spm" or planner.target_spm is None:
            return []
        plan = dense.plan  # the target's cycle: as many strokes as the plan makes a cycle (a pendulum's two)
        target_s = plan.period * plan.spm / planner.target_spm
        return [Check.of(self.id, self.name, plan.period, target_s, self.unit, "equal", TIME_TOL_S)]
