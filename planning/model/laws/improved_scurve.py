"""The improved 10-segment S-curve of Wang, Wu & Ding, "Slider movement planning based on
improved S-curve acceleration algorithms for servo presses" (Eqs. 10-21).

One S-curve takes the crank from a start speed ``v_s`` to an extreme speed ``v_max`` and on to an
end speed ``v_e``. Between the constant-speed segments 1 and 10 lie four acceleration sub-segments of
one length ``T_a`` (the paper's T2 = T3 = T4 = T5) and four deceleration sub-segments of one length
``T_d`` (T6 = ... = T9). The jerk follows Eq. 10 with one jerk ``J`` for both halves (Eq. 14)::

    accel half:  J,  J - J tau/T_a,  -J tau/T_a,  -J
    decel half: -J, -J + J tau/T_d,   J tau/T_d,   J

so the acceleration (Eq. 11) is continuous, peaks at ``3/2 J T_a`` (Eq. 21) and bottoms at
``-3/2 J T_d`` (Eq. 17); the jerk steps at the knots. The speed changes by ``11/3 J T^2`` in each
half (Eqs. 12, 13, 19). The angle swept by a half, from integrating Eq. 12 (the paper does not print
it; derived here and checked against the evaluated profile in the tests)::

    accel half: 4 T_a v_s   + 22/3 J T_a^3
    decel half: 4 T_d v_max - 22/3 J T_d^3

Speeds are in rad/s, times in s, jerks in rad/s^3 inside the project; the relations are unit-free.
A negative ``J`` mirrors the curve (a dip to a minimum speed).
"""

from __future__ import annotations

from typing import Any

from planning.model.laws.base import MotionLaw
from planning.model.profile import Segment

SPEED_GAIN = 11.0 / 3.0  # Eq. 13: v_max - v_s = 11/3 J T_a^2
ANGLE_GAIN = 22.0 / 3.0  # angle of a half beyond the start speed: 22/3 J T^3
PEAK_ACCEL = 1.5  # Eq. 21: a_max = 3/2 J T_a
SUBSEGMENTS = 4


def accel_half(T: Any, J: Any, prefix: str = "accel") -> list[Segment]:
    """Eq. 10, segments 2-5: four sub-segments of length ``T`` [s] with jerk ``J`` [rad/s^3]."""
    return [
        Segment(f"{prefix}1", T, J, 0.0),
        Segment(f"{prefix}2", T, J, -J / T),
        Segment(f"{prefix}3", T, 0.0, -J / T),
        Segment(f"{prefix}4", T, -J, 0.0),
    ]


def decel_half(T: Any, J: Any, prefix: str = "decel") -> list[Segment]:
    """Eq. 10, segments 6-9: four sub-segments of length ``T`` [s] with jerk ``J`` [rad/s^3]."""
    return [
        Segment(f"{prefix}1", T, -J, 0.0),
        Segment(f"{prefix}2", T, -J, J / T),
        Segment(f"{prefix}3", T, 0.0, J / T),
        Segment(f"{prefix}4", T, J, 0.0),
    ]


def segments(T_a: Any, T_d: Any, J: Any, T_start: Any = 0.0, T_end: Any = 0.0, prefix: str = "") -> list[Segment]:
    """All ten segments of Eq. 10: constant ``T_start`` [s], accel half, decel half, constant ``T_end`` [s]."""
    out = [Segment(f"{prefix}const_start", T_start, 0.0, 0.0)]
    out += accel_half(T_a, J, f"{prefix}accel")
    out += decel_half(T_d, J, f"{prefix}decel")
    out.append(Segment(f"{prefix}const_end", T_end, 0.0, 0.0))
    return out


def speed_change(J: Any, T: Any) -> Any:
    """Eq. 13 / 19: speed change [rad/s] of one half with jerk ``J`` [rad/s^3] and sub-segment ``T`` [s]."""
    return SPEED_GAIN * J * T**2


def peak_accel(J: Any, T: Any) -> Any:
    """Eqs. 17, 21: extreme acceleration [rad/s^2] of a half, ``3/2 J T``."""
    return PEAK_ACCEL * J * T


def half_angle(v_start: Any, J: Any, T: Any, accelerating: bool = True) -> Any:
    """Angle [rad] swept by one half starting at ``v_start`` [rad/s] (derived from Eq. 12)."""
    sign = 1.0 if accelerating else -1.0
    return SUBSEGMENTS * T * v_start + sign * ANGLE_GAIN * J * T**3


def jerk_from_peak(a_max: Any, T: Any) -> Any:
    """Eq. 14: ``J = 2 a_max / (3 T)`` [rad/s^3] from the peak acceleration [rad/s^2] and ``T`` [s]."""
    return 2.0 * a_max / (3.0 * T)


def jerk_from_speed_change(a_max: Any, dv: Any) -> Any:
    """Eq. 14: ``J = 44 a_max^2 / (27 dv)`` [rad/s^3] from the peak acceleration and the speed change."""
    return 44.0 * a_max**2 / (27.0 * dv)


def subsegment_time(dv: Any, a_max: Any) -> Any:
    """Eqs. 15, 16: sub-segment length [s] ``9 dv / (22 a_max)`` for a speed change ``dv`` [rad/s]."""
    return 9.0 * dv / (22.0 * a_max)


def constant_time(T_f: Any, a_max: Any, a_min: Any, T_a: Any) -> Any:
    """Eq. 18: length [s] of each constant segment when both are equal and the total is ``T_f`` [s]."""
    return T_f / 2.0 - 2.0 * (a_max - a_min) * T_a / a_max


class ImprovedSCurve(MotionLaw):
    """The improved S-curve as a motion law: a half is four sub-segments of ``D / 4`` (Eq. 10) whose
    jerk makes the speed change (Eq. 13); both halves of an S-curve share one jerk (Eq. 14)."""

    name = "improved-s-curve"
    continuity = "acceleration"
    source = "Wang, Wu & Ding, Eqs. 10-21"
    one_jerk_per_curve = True

    def half(self, prefix: str, duration: Any, dv: Any, param: Any = None) -> list[Segment]:
        T = duration / SUBSEGMENTS
        return accel_half(T, dv / (SPEED_GAIN * T**2), prefix)

    def peak_rate(self, param: Any = None) -> Any:
        return PEAK_ACCEL * SUBSEGMENTS / SPEED_GAIN  # Eq. 21 with J from Eq. 13: 18/11

    def peak_jerk(self, param: Any = None) -> Any:
        return SUBSEGMENTS**2 / SPEED_GAIN  # J = dv / (11/3 (D/4)^2)
