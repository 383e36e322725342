"""The motion laws whose half is one shaped segment: quintic, cycloidal, logistic.

A half of duration ``D`` changing the speed by ``dv`` follows the law's normalised shape
(``planning.model.laws.shapes``) as one closed-form segment; its peak acceleration and jerk are the
shape's peaks scaled by ``|dv| / D`` and ``|dv| / D^2``.
"""

from __future__ import annotations

from abc import abstractmethod
from typing import Any

from planning.model.laws.base import MotionLaw, ShapeParameter
from planning.model.laws.shapes import LOGISTIC_MIN_FLEXIBLE, Cycloidal, Logistic, Quintic
from planning.model.profile import Segment, shape_segment


class OneSegmentLaw(MotionLaw):
    """A law whose half is one segment along :meth:`shape`."""

    samples = 20

    @abstractmethod
    def shape(self, param: Any = None) -> Any:
        """The normalised shape (``planning.model.laws.shapes``) for shape parameter ``param``."""

    def half(self, prefix: str, duration: Any, dv: Any, param: Any = None) -> list[Segment]:
        return [shape_segment(prefix, duration, dv, self.shape(param))]

    def peak_rate(self, param: Any = None) -> Any:
        return self.shape(param).peak_rate()

    def peak_jerk(self, param: Any = None) -> Any:
        return self.shape(param).peak_jerk()


class QuinticLaw(OneSegmentLaw):
    name = "quintic"
    continuity = "jerk"
    source = "Liu & Wu (LED die bonder)"

    def shape(self, param: Any = None) -> Quintic:
        return Quintic()


class CycloidalLaw(OneSegmentLaw):
    name = "cycloidal"
    continuity = "jerk"
    source = "cam design"

    def shape(self, param: Any = None) -> Cycloidal:
        return Cycloidal()


class LogisticLaw(OneSegmentLaw):
    name = "logistic"
    continuity = "acceleration"
    source = "Li & Chen (bond-wire winder), Eq. 4"
    parameter = ShapeParameter("flexible", 4.0, 6.0, 5.0, LOGISTIC_MIN_FLEXIBLE, 30.0)

    def shape(self, param: Any = None) -> Logistic:
        return Logistic(param)
