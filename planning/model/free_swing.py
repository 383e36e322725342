"""A pendulum swing under the optimal law: piecewise-constant crank jerk from rest to the draw and back to rest.

A swing on its path coordinate ``u`` (``planning.model.pendulum``: u grows as the swing goes, its speeds >= 0)
runs three parts: the **feed**, :data:`FEED_SEGMENTS` segments of one step ``h_f`` [s] each, of constant jerks
``j_k`` [rad/s^3], from rest at the swing's start (speed and acceleration 0) to theta2, arriving at the draw speed
w2 with zero acceleration; the **draw** at the constant w2 from theta2 to theta3; the **return**,
:data:`RETURN_SEGMENTS` segments of one step ``h_r``, from theta3 (w2, acceleration 0) to rest at the swing's end
(speed and acceleration 0). The acceleration is piecewise linear and continuous, the jerk steps at the knots:
the jerk-limited time-optimal motion of a swing, as ``planning.model.free_profile`` is a rotary cycle's. There
are no halves: the peaks are read off the profile.

The ends are linear in the jerks when the steps stay: a jerk ``j_k`` over ``h`` followed by ``S`` seconds adds
``j_k h`` of acceleration, ``j_k (h^2 / 2 + h S)`` of speed and ``j_k (h^3 / 6 + h^2 S / 2 + h S^2 / 2)`` of
angle; :func:`closed_part_jerks` moves the solved jerks by the least norm that meets a part's end state exactly
(the NLP meets it to IPOPT's tolerance, the verification asks the crank to stand still at a turn to 1e-9 rad/s).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from planning.model.laws import get_law
from planning.model.laws.optimal import OptimalLaw
from planning.model.profile import Segment, knot_states

FEED_SEGMENTS = 24  # the feed's segments of a swing (from rest to the draw)
RETURN_SEGMENTS = 24  # the return's segments of a swing (from the draw to rest)
FREE_LAW = OptimalLaw.name  # the law whose swings these are
FREE_SAMPLES = 5  # the points of each segment at which a swing's NLP holds the crank's and the slide's limits


def samples_per_segment(motion_law: str) -> int:
    """The points of each segment of a swing's feed and return at which its NLP holds the sampled limits: the
    law's own (``Law.samples``), :data:`FREE_SAMPLES` for the optimal law's segments."""
    return FREE_SAMPLES if motion_law == FREE_LAW else get_law(motion_law).samples


def part_segments(prefix: str, step: Any, jerks: tuple) -> list[Segment]:
    """The segments ``PREFIX:k`` of one step ``step`` [s] and constant ``jerks`` [rad/s^3]."""
    return [Segment(f"{prefix}:{k + 1}", step, j, 0.0) for k, j in enumerate(jerks)]


@dataclass(frozen=True)
class FreeSwingParameters:
    """One swing of the optimal law on its path coordinate u [rad] (module docstring): the draw speed ``draw_speed``
    w2 [rad/s], the feed's and the return's steps ``feed_step`` / ``return_step`` [s] and jerks ``feed_jerks`` /
    ``return_jerks`` [rad/s^3]; ``start``, ``draw_start``, ``draw_end``, ``end``: u at the swing's start, theta2,
    theta3 and its end [rad]. The rest is what :class:`planning.model.pendulum.SwingParameters` answers too (no
    hold, no law parameter), so that a pendulum cycle (``PendulumParameters``) takes either."""

    draw_speed: Any
    feed_step: Any
    return_step: Any
    feed_jerks: tuple
    return_jerks: tuple
    start: Any
    draw_start: Any
    draw_end: Any
    end: Any
    motion_law: str = FREE_LAW
    law_parameter: Any = 0.0
    hold_angle: Any = None
    hold_time: Any = 0.0

    has_hold = False
    brake_duration = 0.0

    @property
    def return_start_speed(self) -> Any:
        """The speed the return starts from [rad/s]: w2."""
        return self.draw_speed

    @property
    def draw_time(self) -> Any:
        """Duration [s] of the draw at constant w2."""
        return (self.draw_end - self.draw_start) / self.draw_speed

    @property
    def feed_time(self) -> Any:
        """Duration [s] from the swing's start to theta2."""
        return len(self.feed_jerks) * self.feed_step

    @property
    def return_time(self) -> Any:
        """Duration [s] from theta3 to the swing's end."""
        return len(self.return_jerks) * self.return_step

    @property
    def duration(self) -> Any:
        """The swing's time [s] from rest to rest."""
        return self.feed_time + self.draw_time + self.return_time

    def feed_segments(self) -> list[Segment]:
        """The feed's segments on u, from rest at the start to w2 at theta2."""
        return part_segments("feed", self.feed_step, self.feed_jerks)

    def return_segments(self) -> list[Segment]:
        """The return's segments on u, from w2 at theta3 to rest at the end."""
        return part_segments("return", self.return_step, self.return_jerks)

    def segments(self) -> list[Segment]:
        """The whole swing's segments on u: feed, draw, return."""
        draw = Segment("draw:constant", self.draw_time, 0.0, 0.0)
        return self.feed_segments() + [draw] + self.return_segments()

    def _parts(self) -> tuple[tuple[list[Segment], tuple[float, float, float]], ...]:
        """The feed and the return of a numeric swing: each one's segments and its start state (angle, speed,
        acceleration)."""
        return (
            (self.feed_segments(), (float(self.start), 0.0, 0.0)),
            (self.return_segments(), (float(self.draw_end), float(self.draw_speed), 0.0)),
        )

    @staticmethod
    def _peak_speed(segments: list[Segment], start: tuple[float, float, float]) -> float:
        """The highest speed [rad/s] of a numeric part: at its knots and where its (linear) acceleration is 0."""
        states = knot_states(*start, segments)
        best = max(float(om) for _, om, _ in states)
        for seg, (_, om, al) in zip(segments, states[:-1], strict=True):
            j, h = float(seg.j0), float(seg.duration)
            if j != 0.0 and 0.0 < -al / j < h:  # a speed extremum inside the segment
                tau = -al / j
                best = max(best, float(om + al * tau + j * tau**2 / 2))
        return best

    @property
    def feed_peak_speed(self) -> float:
        """The highest speed of the feed [rad/s] (numeric plans)."""
        return self._peak_speed(*self._parts()[0])

    @property
    def return_peak_speed(self) -> float:
        """The highest speed of the return [rad/s] (numeric plans)."""
        return self._peak_speed(*self._parts()[1])

    def peak_accelerations(self) -> list[float]:
        """Peak |crank acceleration| [rad/s^2] of the feed and of the return (at their knots: it is linear between)."""
        return [max(abs(float(al)) for _, _, al in knot_states(*start, segs)) for segs, start in self._parts()]

    def peak_jerks(self) -> list[float]:
        """Peak |crank jerk| [rad/s^3] of the feed and of the return."""
        return [max(abs(float(j)) for j in self.feed_jerks), max(abs(float(j)) for j in self.return_jerks)]


def closed_part_jerks(step: float, jerks: tuple, start: tuple[float, float, float], end: tuple) -> tuple:
    """The jerks [rad/s^3] nearest ``jerks`` (least norm) with which a part of equal steps ``step`` [s] from the
    state ``start`` (angle, speed, acceleration) meets the state ``end`` exactly (module docstring)."""
    j = np.asarray(jerks, dtype=float)
    n = j.size
    after = step * np.arange(n - 1, -1, -1)  # from each segment's end to the part's end [s]
    rows = np.array(
        [
            step**3 / 6 + step**2 * after / 2 + step * after**2 / 2,
            step**2 / 2 + step * after,
            np.full(n, step),
        ]
    )
    reached = knot_states(*start, part_segments("part", step, tuple(j)))[-1]
    residual = np.array([float(x) for x in reached]) - np.asarray(end, dtype=float)
    return tuple((j - np.linalg.lstsq(rows, residual, rcond=None)[0]).tolist())
