"""The classic seven-segment S-curve (Li & Chen; Wang & Zhang; Zhang, Chen & Hu) as a motion law.

One half of duration ``D`` changes the speed by ``dv`` in three segments: a jerk phase ``r D / 2``, a
constant-acceleration plateau ``(1 - r) D``, a jerk phase ``r D / 2``. With plateau acceleration ``a``
the speed change is ``dv = a (1 - r/2) D`` and the jerk ``J = a / (r D / 2)``. The plateau vanishes at
``r = 1``; the jerk share ``r`` is the law's shape parameter.
"""

from __future__ import annotations

from typing import Any

from planning.model.laws.base import MotionLaw, ShapeParameter
from planning.model.profile import Segment


class SevenSegment(MotionLaw):
    name = "seven-segment"
    continuity = "acceleration"
    source = "Li & Chen; Wang & Zhang; Zhang, Chen & Hu"
    parameter = ShapeParameter("jerk_share", 0.2, 1.0, 0.6, 0.01, 1.0)

    def half(self, prefix: str, duration: Any, dv: Any, param: Any = None) -> list[Segment]:
        r = param
        a = dv / (duration * (1 - r / 2))  # the plateau acceleration: dv = a (1 - r/2) D
        J = a / (r * duration / 2)
        return [
            Segment(f"{prefix}1", r * duration / 2, J, 0.0),
            Segment(f"{prefix}2", (1 - r) * duration, 0.0, 0.0),
            Segment(f"{prefix}3", r * duration / 2, -J, 0.0),
        ]

    def peak_rate(self, param: Any = None) -> Any:
        return 1 / (1 - param / 2)

    def peak_jerk(self, param: Any = None) -> Any:
        return 2 / (param * (1 - param / 2))
