"""One press cycle assembled from a motion law and constant-speed stages (paper Fig. 6).

Stages, in the order the optimizer lays them out (time 0 at the end of the draw, crank angle theta3):

    return   w2 -> wm2 -> w1: accel half (duration D_ra), decel half (D_rd)
    transfer constant w1 for T_c (around TDC; the robot's window theta4 -> theta1 lies here and in the
             neighbouring halves)
    feed     w1 -> wm1 -> w2: accel half (D_fa), decel half (D_fd), ends at theta2
    draw     constant w2 from theta2 to theta3, duration (theta3 - theta2) / w2

With a hold at the bottom (``process.hold_time_s``) the crank brakes after the draw, one half of the law
from w2 to 0 over theta3 -> theta_h (so of duration D_b = 2 (theta_h - theta3) / w2: every half sweeps
D (v0 + v1) / 2), stands at theta_h for the hold time t_h (the slide still at its hold height), and the return
rises from 0 instead of w2. The stages then run ``hold (brake, standstill), return, transfer, feed, draw``
from theta3, and the cycle time gains D_b + t_h.

Each half follows the motion law (``planning.model.laws``). The cycle closes after exactly 2 pi when the
angle of every stage adds up (a constraint of the NLP). Time in the written plan starts at TDC, as
in the paper's Figs. 7-9.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from planning.model.laws import DEFAULT_LAW, get_law
from planning.model.laws import improved_scurve as sc
from planning.model.profile import Segment

HALVES = ("feed_accel", "feed_decel", "return_accel", "return_decel")
BRAKE = "brake"  # the hold's half: the crank brakes from the draw speed to standstill
BRAKE_PREFIX = "hold:decel"  # its segments' names (``hold:decel1`` ...)
HOLD_SEGMENT = "hold:standstill"  # the crank standing at the hold
DRAW_SEGMENT = "draw:constant"  # the draw at constant crank speed
RISING = {"feed_accel": 1.0, "feed_decel": -1.0, "return_accel": 1.0, "return_decel": -1.0, BRAKE: -1.0}


@dataclass(frozen=True)
class CycleParameters:
    """The free numbers of a cycle (all inside units).

    ``transfer_speed`` w1, ``draw_speed`` w2, ``feed_peak_speed`` wm1, ``return_peak_speed`` wm2
    [rad/s]; ``feed_accel_duration`` ... ``return_decel_duration``: the duration of each half [s];
    ``transfer_dwell``: the constant-w1 segment [s]; ``law_parameter``: the shape parameter of the law
    (0 when it has none); ``draw_start`` / ``draw_end``: theta2, theta3 [rad]; ``motion_law``: its name;
    ``hold_time`` [s] and ``hold_angle`` [rad]: the hold at the bottom (None: no hold; module docstring).
    """

    transfer_speed: Any
    draw_speed: Any
    feed_peak_speed: Any
    return_peak_speed: Any
    feed_accel_duration: Any
    feed_decel_duration: Any
    return_accel_duration: Any
    return_decel_duration: Any
    transfer_dwell: Any
    law_parameter: Any
    draw_start: Any
    draw_end: Any
    motion_law: str = DEFAULT_LAW
    hold_time: Any = 0.0
    hold_angle: Any = None

    @property
    def has_hold(self) -> bool:
        """The crank stands still after the draw (a hold at the bottom)."""
        return self.hold_angle is not None

    @property
    def brake_duration(self) -> Any:
        """The brake half's duration [s] from w2 to standstill over theta3 -> theta_h (0 without a hold)."""
        return brake_time(self.hold_angle, self.draw_end, self.draw_speed) if self.has_hold else 0.0

    @property
    def return_start_speed(self) -> Any:
        """The speed the return rises from [rad/s]: w2, or 0 after a hold."""
        return 0.0 if self.has_hold else self.draw_speed

    def as_dict(self) -> dict[str, Any]:
        """Field name -> value."""
        return asdict(self)

    @property
    def draw_time(self) -> Any:
        """Duration of the constant-speed draw [s]."""
        return (self.draw_end - self.draw_start) / self.draw_speed

    @property
    def period(self) -> Any:
        """Cycle time [s] (Eq. 20 over all stages)."""
        halves = self.feed_accel_duration + self.feed_decel_duration
        halves += self.return_accel_duration + self.return_decel_duration
        period = halves + self.transfer_dwell + self.draw_time
        return period + self.brake_duration + self.hold_time if self.has_hold else period

    def half(self, name: str) -> tuple[Any, Any]:
        """``(duration [s], speed change [rad/s])`` of the half ``name`` (one of :data:`HALVES`, or ``brake``:
        the hold's, w2 -> 0)."""
        w1, w2, wm1, wm2 = self.transfer_speed, self.draw_speed, self.feed_peak_speed, self.return_peak_speed
        if name == BRAKE:
            return self.brake_duration, -w2
        wr = self.return_start_speed
        dv = {"feed_accel": wm1 - w1, "feed_decel": w2 - wm1, "return_accel": wm2 - wr, "return_decel": w1 - wm2}
        return getattr(self, f"{name}_duration"), dv[name]

    def peak_accelerations(self) -> list[Any]:
        """Peak |crank acceleration| [rad/s^2] of each half, in :data:`HALVES` order."""
        rate = get_law(self.motion_law).peak_rate(self.law_parameter)
        return [rate * RISING[name] * dv / D for name, (D, dv) in self._halves()]

    def peak_jerks(self) -> list[Any]:
        """Peak |crank jerk| [rad/s^3] of each half, in :data:`HALVES` order."""
        jerk = get_law(self.motion_law).peak_jerk(self.law_parameter)
        return [jerk * RISING[name] * dv / D**2 for name, (D, dv) in self._halves()]

    def _halves(self) -> list[tuple[str, tuple[Any, Any]]]:
        names = HALVES + ((BRAKE,) if self.has_hold else ())
        return [(name, self.half(name)) for name in names]

    # improved S-curve only: the paper's jerks and sub-segment lengths (Eqs. 10, 13)
    @property
    def feed_jerk(self) -> Any:
        """J of the feed S-curve [rad/s^3] (improved S-curve; Eq. 13 on the acceleration half)."""
        T = self.feed_accel_duration / sc.SUBSEGMENTS
        return (self.feed_peak_speed - self.transfer_speed) / (sc.SPEED_GAIN * T**2)

    @property
    def return_jerk(self) -> Any:
        """J of the return S-curve [rad/s^3] (improved S-curve)."""
        T = self.return_accel_duration / sc.SUBSEGMENTS
        return (self.return_peak_speed - self.return_start_speed) / (sc.SPEED_GAIN * T**2)


def brake_time(hold_angle: Any, draw_end: Any, draw_speed: Any) -> Any:
    """[s] one half of the law from the draw speed to rest over ``draw_end -> hold_angle`` [rad]: every half
    sweeps ``D (v0 + v1) / 2``, so ``D_b = 2 (theta_h - theta3) / w2`` (module docstring)."""
    return 2 * (hold_angle - draw_end) / draw_speed


def cycle_segments(p: CycleParameters) -> list[Segment]:
    """The segments of a cycle from the end of the draw, named ``stage:part``."""
    law = get_law(p.motion_law)
    segs: list[Segment] = []
    if p.has_hold:  # the crank brakes to the hold and stands there (module docstring)
        segs += law.half(BRAKE_PREFIX, *p.half(BRAKE), p.law_parameter)
        segs.append(Segment(HOLD_SEGMENT, p.hold_time, 0.0, 0.0))
    for name in ("return_accel", "return_decel"):
        segs += law.half(name.replace("_", ":"), *p.half(name), p.law_parameter)
    segs.append(Segment("transfer:dwell", p.transfer_dwell, 0.0, 0.0))
    for name in ("feed_accel", "feed_decel"):
        segs += law.half(name.replace("_", ":"), *p.half(name), p.law_parameter)
    segs.append(Segment(DRAW_SEGMENT, p.draw_time, 0.0, 0.0))
    return segs
