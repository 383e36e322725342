"""Motion laws: how the crank speed changes between two constant speeds, behind one interface.

A press cycle (``planning.model.cycle``) has four *halves*: the feed S-curve rises from the transfer speed to
its peak and falls to the draw speed, the return S-curve rises from the draw speed to its peak and
falls to the transfer speed. A motion law turns one half -- duration ``D`` [s], speed change ``dv``
[rad/s], optionally its shape parameter -- into closed-form segments (``planning.model.profile``), and states
its peak acceleration and jerk in closed form (for the drive limits) and its continuity.

=================  ====================================================  ===========================
law                one half                                              continuous up to
=================  ====================================================  ===========================
improved-s-curve   Wang, Wu & Ding Eq. 10: four sub-segments of D/4,      acceleration (jerk steps)
                   linear jerk; one jerk for both halves (Eq. 14)
seven-segment      Li & Chen; Wang & Zhang; Zhang, Chen & Hu: jerk       acceleration (jerk steps)
                   phase r D/2, constant acceleration (1 - r) D, jerk
                   phase r D/2; r optimised
quintic            Liu & Wu: s = 10u^3 - 15u^4 + 6u^5                     jerk
logistic           Li & Chen Eq. 4 with its end slope removed,            acceleration (small jerk steps)
                   flexible a
cycloidal          cam classic, acceleration 1 - cos(2 pi u)              jerk
optimal            no halves: a piecewise-constant jerk profile from       acceleration (jerk steps)
                   theta3 round to theta2, planned whole under |jerk| <= J
=================  ====================================================  ===========================

Each law is a class in a file of its own (``base.MotionLaw`` for a law with halves; the optimal law is a
``base.Law`` with a transcription of its own); this module is the registry. The
peak speed between the halves is a point (no constant-speed segment at the peak); the seven-
segment law's degenerate cases -- the plateau vanishes at ``r = 1``, the constant-speed segments at
the ends vanish when the optimizer sets them to zero -- are all inside its parameter range.
"""

from __future__ import annotations

from typing import Literal, get_args

from planning.model.laws.base import FREE, HALVES, Law, MotionLaw, ShapeParameter
from planning.model.laws.improved_scurve import ImprovedSCurve
from planning.model.laws.one_segment import CycloidalLaw, LogisticLaw, QuinticLaw
from planning.model.laws.optimal import OptimalLaw
from planning.model.laws.seven_segment import SevenSegment

LAWS: dict[str, Law] = {
    law.name: law
    for law in (ImprovedSCurve(), SevenSegment(), QuinticLaw(), LogisticLaw(), CycloidalLaw(), OptimalLaw())
}
DEFAULT_LAW = ImprovedSCurve.name
SHAPED_LAWS = tuple(name for name, law in LAWS.items() if law.transcription == HALVES)  # the laws with halves
LawName = Literal["improved-s-curve", "seven-segment", "quintic", "logistic", "cycloidal", "optimal"]
assert set(get_args(LawName)) == set(LAWS)

__all__ = [
    "DEFAULT_LAW",
    "FREE",
    "HALVES",
    "LAWS",
    "SHAPED_LAWS",
    "Law",
    "LawName",
    "MotionLaw",
    "ShapeParameter",
    "get_law",
]


def get_law(name: str) -> Law:
    """The law called ``name`` (:data:`LAWS`)."""
    return LAWS[name]
