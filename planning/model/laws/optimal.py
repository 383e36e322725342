"""The jerk-limited optimal motion as a law of the registry: outside the draw the crank speed is free.

It has no halves and no fixed shape: the solver (``planning.solver.optimal``) plans a piecewise-constant
jerk profile from theta3 round to theta2 (``planning.model.free_profile``). The class is here so that the
law is named, listed and described like the others; asking it for a half is an error.
"""

from __future__ import annotations

from typing import Any

from planning.model.laws.base import MotionLaw
from planning.model.profile import Segment


class OptimalLaw(MotionLaw):
    name = "optimal"
    continuity = "acceleration"
    source = "this project: jerk-limited time-optimal profile, piecewise-constant jerk"
    free_profile = True

    def half(self, prefix: str, duration: Any, dv: Any, param: Any = None) -> list[Segment]:
        raise NotImplementedError("the optimal law has no halves: its profile is planned as a whole")

    def peak_rate(self, param: Any = None) -> Any:
        raise NotImplementedError("the optimal law has no closed-form peak")

    def peak_jerk(self, param: Any = None) -> Any:
        raise NotImplementedError("the optimal law has no closed-form peak")
