"""Motion laws: how the crank speed changes between two constant speeds, behind one interface.

A press cycle (``planning.cycle``) has four *halves*: the feed S-curve rises from the transfer speed to
its peak and falls to the draw speed, the return S-curve rises from the draw speed to its peak and
falls to the transfer speed. A motion law turns one half -- duration ``D`` [s], speed change ``dv``
[rad/s], optionally its shape parameter -- into closed-form segments (``planning.profile``), and states
its peak acceleration and jerk in closed form (for the drive limits) and its continuity.

=================  ====================================================  ===========================
law                one half                                              continuous up to
=================  ====================================================  ===========================
improved-s-curve   paper 003 Eq. 10: four sub-segments of D/4, linear     acceleration (jerk steps)
                   jerk; one jerk for both halves of an S-curve (Eq. 14)
seven-segment      seeds 000/002/004: jerk phase r D/2, constant          acceleration (jerk steps)
                   acceleration (1 - r) D, jerk phase r D/2; r optimised
quintic            seed 001: s = 10u^3 - 15u^4 + 6u^5                     jerk
logistic           seed 000 Eq. 4 with its end slope removed, flexible a  acceleration (small jerk steps)
cycloidal          cam classic, acceleration 1 - cos(2 pi u)              jerk
=================  ====================================================  ===========================

The peak speed between the halves is a point (no constant-speed segment at the peak); the seven-
segment law's degenerate cases -- the plateau vanishes at ``r = 1``, the constant-speed segments at
the ends vanish when the optimizer sets them to zero -- are all inside its parameter range.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal, get_args

from planning.laws import improved_scurve as sc
from planning.laws.shapes import LOGISTIC_MIN_FLEXIBLE, Cycloidal, Logistic, Quintic
from planning.profile import Segment, shape_segment


@dataclass(frozen=True)
class MotionLaw:
    """A motion law. ``parameter``: ``(name, low, high, start)`` of its shape parameter when it has
    one (optimised by the NLP within the bounds unless the case fixes it within ``valid``), else
    None. ``samples``: slider-acceleration samples the NLP takes per segment of a half (the dense
    verification decides between them)."""

    name: str
    continuity: str  # "acceleration" or "jerk": the highest derivative of the speed that is continuous
    source: str
    parameter: tuple[str, float, float, float] | None = None
    valid: tuple[float, float] = (0.0, 0.0)  # where a fixed shape parameter (planner.law_parameter) may lie
    samples: int = 5
    one_jerk_per_curve: bool = False  # Eq. 14: both halves of an S-curve share one jerk
    notes: str = field(default="", compare=False)

    def half(self, prefix: str, duration: Any, dv: Any, param: Any = None) -> list[Segment]:
        """Segments of one half: speed change ``dv`` [rad/s] (either sign) in ``duration`` [s]."""
        if self.name == "improved-s-curve":
            T = duration / sc.SUBSEGMENTS
            return sc.accel_half(T, dv / (sc.SPEED_GAIN * T**2), prefix)
        if self.name == "seven-segment":
            r = param
            a = dv / (duration * (1 - r / 2))  # the plateau acceleration: dv = a (1 - r/2) D
            J = a / (r * duration / 2)
            return [
                Segment(f"{prefix}1", r * duration / 2, J, 0.0),
                Segment(f"{prefix}2", (1 - r) * duration, 0.0, 0.0),
                Segment(f"{prefix}3", r * duration / 2, -J, 0.0),
            ]
        return [shape_segment(prefix, duration, dv, self.shape(param))]

    def shape(self, param: Any = None):
        """The normalised shape of a one-segment law (``planning.laws.shapes``)."""
        if self.name not in SHAPES:
            raise ValueError(f"{self.name} is not a one-segment law")
        return SHAPES[self.name](param)

    def peak_rate(self, param: Any = None) -> Any:
        """Peak |acceleration| of a half in units of ``|dv| / D``."""
        if self.name == "improved-s-curve":
            return sc.PEAK_ACCEL * sc.SUBSEGMENTS / sc.SPEED_GAIN  # Eq. 21 with J from Eq. 13: 18/11
        if self.name == "seven-segment":
            return 1 / (1 - param / 2)
        return self.shape(param).peak_rate()

    def peak_jerk(self, param: Any = None) -> Any:
        """Peak |jerk| of a half in units of ``|dv| / D^2``."""
        if self.name == "improved-s-curve":
            return sc.SUBSEGMENTS**2 / sc.SPEED_GAIN  # J = dv / (11/3 (D/4)^2)
        if self.name == "seven-segment":
            return 2 / (param * (1 - param / 2))
        return self.shape(param).peak_jerk()


SHAPES = {  # one-segment laws: shape from the law's parameter
    "quintic": lambda _: Quintic(),
    "cycloidal": lambda _: Cycloidal(),
    "logistic": Logistic,
}
LAWS: dict[str, MotionLaw] = {
    law.name: law
    for law in (
        MotionLaw("improved-s-curve", "acceleration", "paper 003, Eqs. 10-21", one_jerk_per_curve=True),
        MotionLaw(
            "seven-segment", "acceleration", "seeds 000, 002, 004", ("jerk_share", 0.2, 1.0, 0.6), valid=(0.01, 1.0)
        ),
        MotionLaw("quintic", "jerk", "seed 001", samples=20),
        MotionLaw(
            "logistic",
            "acceleration",
            "seed 000, Eq. 4",
            ("flexible", 4.0, 6.0, 5.0),
            samples=20,
            valid=(LOGISTIC_MIN_FLEXIBLE, 30.0),
        ),
        MotionLaw("cycloidal", "jerk", "cam design", samples=20),
    )
}
DEFAULT_LAW = "improved-s-curve"
LawName = Literal["improved-s-curve", "seven-segment", "quintic", "logistic", "cycloidal"]
assert set(get_args(LawName)) == set(LAWS)


def get_law(name: str) -> MotionLaw:
    """The law called ``name`` (:data:`LAWS`)."""
    return LAWS[name]
