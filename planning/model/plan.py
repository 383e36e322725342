"""The solved press cycle: a numeric profile starting at TDC plus what the solver reported."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from planning.model.case import Placement
from planning.model.cycle import CycleParameters, cycle_segments
from planning.model.free_profile import (
    FreeProfileParameters,
    Layout,
    closed_jerks,
    draws_freely,
    holds,
    phase_ends,
)
from planning.model.laws import DEFAULT_LAW
from planning.model.profile import Profile, Segment, advance_segment, knot_states, split_segment
from planning.tolerances import ANGLE_TOL_RAD, KNOT_TIME_S, TIME_TOL_S, TINY


@dataclass(frozen=True)
class SolverInfo:
    """``iterations`` of IPOPT, ``wall_time_s`` [s] of the whole solve, ``starts`` tried, IPOPT ``status``."""

    iterations: int
    wall_time_s: float
    starts: int
    status: str


PlanParameters = CycleParameters | FreeProfileParameters  # a law's cycle of halves, or the optimal law's free profile


@dataclass(frozen=True)
class Plan:
    """One press cycle with its key points.

    ``parameters``: the cycle's free numbers (inside units): a law's :class:`CycleParameters`, or the
    optimal law's :class:`FreeProfileParameters`; both give the speeds, the transfer dwell and the
    peaks a report reads. ``profile``: the crank motion over one period,
    time 0 at TDC (theta = 0, unwrapped to 2 pi at the end); ``key_angles`` theta1..theta4 [rad];
    ``placement``: free | published; ``structure``: where theta1 and theta4 fall (segment names).
    """

    parameters: PlanParameters
    profile: Profile
    key_angles: tuple[float, float, float, float]
    placement: Placement
    solver: SolverInfo
    motion_law: str = DEFAULT_LAW
    structure: dict[str, str] = field(default_factory=dict)
    nlp_values: dict[str, float] = field(default_factory=dict, repr=False)  # the NLP variables (warm starts)
    robot_starts_s: dict[str, float] = field(default_factory=dict)  # [s from TDC] each robot leaves its waiting point
    robot_time_scale: float = 1.0  # the robots run their cams this many times as fast as planned (a cam's speed)

    @property
    def period(self) -> float:
        """Cycle time [s]."""
        return self.profile.duration

    @property
    def spm(self) -> float:
        """Strokes per minute."""
        return 60.0 / self.period

    @property
    def slave_turn_deg(self) -> float:
        """[deg] the crank's turn over one cycle (a cam's slave after one master turn): a rotary stroke's 360."""
        return 360.0

    @property
    def strokes_per_cycle(self) -> int:
        """The strokes of one cycle: a rotary stroke's one."""
        return 1

    def key_times(self) -> np.ndarray:
        """Times [s] from TDC at which the crank reaches theta1..theta4."""
        return np.array([self.profile.time_at_angle(a) for a in self.key_angles])

    def segment_at(self, t: float) -> str:
        """Where time ``t`` [s] lies, in words: ``stage, segment, NN % in`` (:func:`segment_in_words`); a knot
        counts as the end of the earlier segment (``feed, 1st acceleration sub-segment, 100 % in`` is the
        knot where the second sub-segment starts), also when ``t``
        lies within :data:`KNOT_TIME_S` after it (round-off)."""
        tk = self.profile.knot_times
        k = self._segment_index(t)
        share = (t - tk[k]) / max(tk[k + 1] - tk[k], TINY)
        return f"{segment_in_words(self.profile.segments[k].name)}, {100 * share:.0f} % in"

    def segment_name_at(self, t: float) -> str:
        """The name (``stage:part``) of the segment time ``t`` [s] lies in, a knot counted as :meth:`segment_at`
        counts it."""
        return self.profile.segments[self._segment_index(t)].name

    def segment_indices(self, t: Any) -> np.ndarray:
        """The indices in ``profile.segments`` of the segments times ``t`` [s] lie in, a knot counted as
        :meth:`segment_at` counts it."""
        tk = self.profile.knot_times
        k = np.searchsorted(tk, np.asarray(t, dtype=float) - KNOT_TIME_S, side="left") - 1
        return np.clip(k, 0, len(self.profile.segments) - 1)

    def _segment_index(self, t: float) -> int:
        return int(self.segment_indices(t))

    def holds_as(self, case: Any) -> bool:
        """Whether the plan holds at the bottom as ``case`` asks: no hold for a case without one, else the same
        hold time (to :data:`~planning.tolerances.TIME_TOL_S`) at the same crank angle."""
        p = self.parameters
        planned = getattr(p, "has_hold", False)
        if not planned or case.hold_angle is None:
            return not planned and case.hold_angle is None
        same_time = abs(float(p.hold_time) - case.standstill_s) <= TIME_TOL_S
        return bool(same_time and abs(float(p.hold_angle) - case.hold_angle) <= ANGLE_TOL_RAD)

    def in_planned_stop(self, theta: np.ndarray, case: Any) -> np.ndarray:
        """Whether each crank angle ``theta`` [rad] lies in the hold's planned stop: from theta3, where the crank
        brakes, through the standstill to the end of the return's rise from rest; all False without a hold or
        when the plan does not hold as ``case`` asks (:meth:`holds_as`: a stop the case did not ask for is no
        planned stop). By angle, so that a cam's realised motion (its own segments and times) is read the same
        way; an angle a turn on counts too (a rise that ends past TDC)."""
        stop = self.planned_stop()
        if stop is None or not self.holds_as(case):
            return np.zeros(np.shape(theta), dtype=bool)
        turn = np.mod(np.asarray(theta, dtype=float), 2 * math.pi)
        return ((turn >= stop[0]) & (turn <= stop[1])) | (turn + 2 * math.pi <= stop[1])

    def planned_stop(self) -> tuple[float, float] | None:
        """``(from, to)`` [rad]: the crank angles of the hold's planned stop, theta3 to the end of the return's
        rise from rest (a law's half sweeps ``D (0 + wm2) / 2``; the optimal law's rises to its first speed
        peak); None without a hold."""
        p = self.parameters
        if not getattr(p, "has_hold", False):
            return None
        if isinstance(p, FreeProfileParameters):  # the optimal law's rise ends at its first speed peak
            return float(p.draw_end), p.stop_end_angle()
        rise = float(p.return_accel_duration) * float(p.return_peak_speed) / 2
        return float(p.draw_end), float(p.hold_angle) + rise

    def transfer_window(self) -> float:
        """Achieved time [s] from theta4 to theta1 through TDC."""
        t = self.key_times()
        return float(t[0] + self.period - t[3])


def profile_from_tdc(params: CycleParameters) -> Profile:
    """The cycle of ``params`` (numeric) as a profile that starts at TDC and runs one period.

    The NLP lays the cycle out from theta3; here it is rotated so that time 0 is the TDC crossing,
    splitting the segment that holds it. Segments of zero length are dropped.
    """
    return rotate_to_tdc(
        [_numeric(s) for s in cycle_segments(params)], float(params.draw_end), float(params.draw_speed)
    )


def rotate_to_tdc(segs: list, th3: float, w2: float, a3: float = 0.0) -> Profile:
    """The cycle of numeric segments ``segs`` laid out from theta3 [rad] at speed ``w2`` [rad/s] and
    acceleration ``a3`` [rad/s^2] (0 but after a free draw) as a profile from TDC over one period; the segment
    holding TDC is split."""
    states = knot_states(th3, w2, a3, segs)
    two_pi = 2 * math.pi
    k = next(i for i in range(len(segs)) if states[i + 1][0] >= two_pi)
    probe = Profile((segs[k],), *states[k])
    tau = probe.time_at_angle(two_pi)
    first, second = split_segment(segs[k], tau)
    _, om, al, _ = advance_segment(segs[k], *states[k], tau)
    order = [second] + segs[k + 1 :] + segs[:k] + [first]
    order = [s for s in order if s.duration > 0]
    return Profile(tuple(order), 0.0, float(om), float(al))


def _numeric(seg):
    """``seg`` with plain floats (a shape keeps its own parameter, already a float here)."""
    return seg._replace(
        duration=float(seg.duration),
        j0=float(seg.j0),
        j1=float(seg.j1),
        dv=float(seg.dv),
        span=None if seg.span is None else float(seg.span),
    )


def plan_of(
    case: Any, values: dict[str, float], placement: Placement, info: SolverInfo, layout: Layout | None = None
) -> Plan:
    """The plan of an NLP's variable ``values`` (inside units) for ``case``: a law's cycle of halves rotated to
    start at TDC, or (``layout``: the optimal law's phases) the free profile propagated from theta3 through
    its segments' closed forms, then the draw; with where theta1 and theta4 fall (``structure``) and the values
    themselves (a neighbour's warm start; ``plan.json``'s plan)."""
    th1, th2, th3, th4 = (float(a) for a in case.key_angles)
    if layout is None:
        params: PlanParameters = params_from_numbers(values, th2, th3, case.planner.motion_law, hold_of(case))
        profile = profile_from_tdc(params)
    else:
        durations, jerks = [], []
        for phase, n in layout:
            durations += [values[f"{phase}_step"]] * n
            jerks += [values[f"{phase}_jerk_{k}"] for k in range(n)]
        # the phases' ends met exactly: the shooting's defects gathered at the end taken out (closed_jerks)
        hold = hold_of(case) if holds(layout) else {}
        ends = phase_ends(layout, (th1, th2, th3, th4), hold.get("hold_angle"))
        free = draws_freely(layout)  # a draw at constant slide speed: a phase of its own, from theta3's accel
        a0 = values.get("draw_accel", 0.0) if free else 0.0
        jerks = closed_jerks(tuple(durations), tuple(jerks), values["draw_speed"], ends, layout, a0)
        params = FreeProfileParameters(
            tuple(durations), tuple(jerks), values["draw_speed"], th2, th3, layout=layout, draw_accel=a0, **hold
        )
        segs = [seg for seg in params.segments() if seg.duration > 0]
        segs += [] if free else [Segment("draw:constant", params.draw_time, 0.0, 0.0)]
        profile = rotate_to_tdc(segs, th3, params.draw_speed, a0)
    plan = Plan(params, profile, (th1, th2, th3, th4), placement, info, motion_law=params.motion_law)
    t = plan.key_times()
    structure = {"closing": plan.segment_at(float(t[0])), "opening": plan.segment_at(float(t[3]))}
    robots = {  # the NLP's starts count from theta3
        robot.name: float(np.mod(values[f"{robot.name}_start"] + t[2], plan.period))
        for robot in case.robots_on_path
        if f"{robot.name}_start" in values
    }
    return replace(plan, structure=structure, nlp_values=dict(values), robot_starts_s=robots)


def hold_of(case: Any) -> dict[str, Any]:
    """The hold of ``case`` as :class:`CycleParameters` fields: ``hold_time`` [s] and ``hold_angle`` [rad]
    (0 and None without a hold)."""
    if case.process.hold_time_s is None:
        return {}
    return {"hold_time": float(case.process.hold_time_s), "hold_angle": case.hold_angle}


FROM_CASE = ("draw_start", "draw_end", "motion_law", "hold_time", "hold_angle")  # CycleParameters not NLP variables


def params_from_numbers(
    values: dict[str, float], theta2: float, theta3: float, law: str, hold: dict[str, Any] | None = None
) -> CycleParameters:
    """A numeric :class:`CycleParameters` of motion law ``law`` from the NLP variable values (inside units);
    ``hold``: :func:`hold_of` the case."""
    keys = [f for f in CycleParameters.__dataclass_fields__ if f not in FROM_CASE]
    numbers = {k: float(values[k]) for k in keys}
    return CycleParameters(**numbers, draw_start=theta2, draw_end=theta3, motion_law=law, **(hold or {}))


SUB_SEGMENTS = {"accel": "acceleration", "decel": "deceleration"}


def _ordinal(n: int) -> str:
    return f"{n}{'th' if 10 <= n % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(n % 10, 'th')}"


STAGE_WORDS = {"transfer": "dwell"}  # a law's constant-speed stage between the return and the feed: the dwell
WINDOW_PHASE = "window"  # the optimal law's phase from theta4 to theta1: the robot's window


def stage_of(name: str) -> str:
    """The stage a segment ``name`` (``stage:part``) belongs to, in the words the reports use: a law's
    ``transfer:dwell`` is the ``dwell`` (the crank at constant speed between the return and the feed, wherever
    the robot's window lies), the optimal law's ``transfer:24`` the ``window`` (its phase from theta4 to
    theta1); the others as they are (``feed``, ``draw``, ``return``)."""
    stage, _, part = name.partition(":")
    if stage == "transfer":
        return WINDOW_PHASE if part.isdigit() else STAGE_WORDS[stage]
    return stage


def segment_in_words(name: str) -> str:
    """A segment's name (``stage:part``) as a press engineer reads it: ``feed:accel4`` -> ``feed, 4th
    acceleration sub-segment``; ``feed:accel`` -> ``feed, acceleration``; ``draw:constant`` -> ``draw,
    constant speed``; ``transfer:dwell`` -> ``dwell, constant speed``; the optimal law's ``transfer:24``
    -> ``window, interval 24`` (:func:`stage_of`)."""
    _, _, part = name.partition(":")
    stage = stage_of(name)
    if part.isdigit():
        return f"{stage}, interval {part}"
    if part in ("constant", "dwell"):
        return f"{stage}, constant speed"
    kind, number = part.rstrip("0123456789"), part[len(part.rstrip("0123456789")) :]
    if kind in SUB_SEGMENTS:
        words = SUB_SEGMENTS[kind]
        return f"{stage}, {_ordinal(int(number))} {words} sub-segment" if number else f"{stage}, {words}"
    return f"{stage}, {part}" if part else stage
