"""The interface every motion law implements, and the named type of a law's shape parameter."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

from planning.model.profile import Segment


@dataclass(frozen=True)
class ShapeParameter:
    """A law's shape parameter: ``name``; ``low`` .. ``high`` where the NLP optimises it from ``start``;
    ``valid_low`` .. ``valid_high`` where a fixed value (``planner.law_parameter``) may lie."""

    name: str
    low: float
    high: float
    start: float
    valid_low: float
    valid_high: float

    @property
    def valid(self) -> tuple[float, float]:
        """``(valid_low, valid_high)``."""
        return self.valid_low, self.valid_high


HALVES = "halves"  # a cycle of four halves and constant stages (planning.solver.halves_nlp)
FREE = "free"  # a free piecewise-constant-jerk profile, planned whole (planning.solver.free_nlp)


class Law:
    """A motion law of the registry: how the crank moves between the draw and the robot's window.

    Class attributes: ``name``, ``continuity`` (``"acceleration"`` or ``"jerk"``: the highest derivative
    of the speed that is continuous), ``source``, ``transcription`` (:data:`HALVES`: the law shapes the
    halves of a cycle, :class:`MotionLaw`; :data:`FREE`: the profile is planned whole, the optimal law;
    the solver picks the NLP by it), ``needs_jerk_limit`` (it plans under ``limits.crank_jerk_rad_s3`` and
    needs one), ``parameter`` (a :class:`ShapeParameter` or None)."""

    name: ClassVar[str]
    continuity: ClassVar[str]
    source: ClassVar[str]
    transcription: ClassVar[str]
    needs_jerk_limit: ClassVar[bool] = False
    parameter: ClassVar[ShapeParameter | None] = None

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    def __eq__(self, other: object) -> bool:
        return type(self) is type(other)

    def __hash__(self) -> int:
        return hash(type(self))


class MotionLaw(Law, ABC):
    """A law with halves: how the crank speed changes over one half of an S-curve.

    Besides :class:`Law`'s: ``samples`` (slider-acceleration samples the NLP takes per segment of a half;
    the dense verification decides between them), ``one_jerk_per_curve`` (Eq. 14: both halves of an
    S-curve share one jerk). Every method works on floats, numpy arrays and CasADi symbols.
    """

    transcription = HALVES
    samples: ClassVar[int] = 5
    one_jerk_per_curve: ClassVar[bool] = False

    @abstractmethod
    def half(self, prefix: str, duration: Any, dv: Any, param: Any = None) -> list[Segment]:
        """Segments of one half: speed change ``dv`` [rad/s] (either sign) in ``duration`` [s]."""

    @abstractmethod
    def peak_rate(self, param: Any = None) -> Any:
        """Peak |acceleration| of a half in units of ``|dv| / D``."""

    @abstractmethod
    def peak_jerk(self, param: Any = None) -> Any:
        """Peak |jerk| of a half in units of ``|dv| / D^2``."""
