"""One press cycle assembled from the improved S-curve and constant-speed stages (paper Fig. 6).

Stages, in the order the optimizer lays them out (time 0 at the end of the draw, crank angle theta3):

    return   S-curve w2 -> wm2 -> w1 (accel half T_ra, decel half T_rd, jerk J_r)
    transfer constant w1 for T_c (around TDC; the robot's window theta4 -> theta1 lies here and in the
             neighbouring S-curve halves)
    feed     S-curve w1 -> wm1 -> w2 (accel half T_fa, decel half T_fd, jerk J_f), ends at theta2
    draw     constant w2 from theta2 to theta3, duration (theta3 - theta2) / w2

The cycle closes after exactly 2 pi when the angle of every stage adds up (a constraint of the NLP).
Time in the written plan starts at TDC, as in the paper's Figs. 7-9.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from planning.laws import improved_scurve as sc
from planning.profile import Segment

STAGES = ("return", "transfer", "feed", "draw")


@dataclass(frozen=True)
class CycleParameters:
    """The free numbers of an improved-S-curve cycle (all inside units).

    ``transfer_speed`` w1 [rad/s], ``draw_speed`` w2 [rad/s], ``feed_jerk`` / ``return_jerk`` [rad/s^3],
    ``feed_accel_time`` / ``feed_decel_time`` / ``return_accel_time`` / ``return_decel_time``: the
    sub-segment length of each half [s], ``transfer_dwell``: the constant-w1 segment [s],
    ``draw_start`` / ``draw_end``: theta2, theta3 [rad].
    """

    transfer_speed: Any
    draw_speed: Any
    feed_jerk: Any
    feed_accel_time: Any
    feed_decel_time: Any
    return_jerk: Any
    return_accel_time: Any
    return_decel_time: Any
    transfer_dwell: Any
    draw_start: Any
    draw_end: Any

    def as_dict(self) -> dict[str, Any]:
        """Field name -> value."""
        return asdict(self)

    @property
    def draw_time(self) -> Any:
        """Duration of the constant-speed draw [s]."""
        return (self.draw_end - self.draw_start) / self.draw_speed

    @property
    def feed_peak_speed(self) -> Any:
        """wm1 [rad/s], Eq. 13."""
        return self.transfer_speed + sc.speed_change(self.feed_jerk, self.feed_accel_time)

    @property
    def return_peak_speed(self) -> Any:
        """wm2 [rad/s], Eq. 13."""
        return self.draw_speed + sc.speed_change(self.return_jerk, self.return_accel_time)

    @property
    def period(self) -> Any:
        """Cycle time [s] (Eq. 20 over all stages)."""
        n = sc.SUBSEGMENTS
        return (
            n * (self.return_accel_time + self.return_decel_time + self.feed_accel_time + self.feed_decel_time)
            + self.transfer_dwell
            + self.draw_time
        )


def cycle_segments(p: CycleParameters) -> list[Segment]:
    """The 18 segments of a cycle from the end of the draw, named ``stage:part``."""
    segs = sc.accel_half(p.return_accel_time, p.return_jerk, "return:accel")
    segs += sc.decel_half(p.return_decel_time, p.return_jerk, "return:decel")
    segs.append(Segment("transfer:dwell", p.transfer_dwell, 0.0, 0.0))
    segs += sc.accel_half(p.feed_accel_time, p.feed_jerk, "feed:accel")
    segs += sc.decel_half(p.feed_decel_time, p.feed_jerk, "feed:decel")
    segs.append(Segment("draw:constant", p.draw_time, 0.0, 0.0))
    return segs
