"""The free profile of the optimal law: piecewise-constant crank jerk from theta3 round to theta2.

The cycle starts at theta3 with the draw speed w2 and zero acceleration and runs through three phases
of segments of constant jerk ``j_k`` [rad/s^3]: the return (theta3 -> theta4, :data:`PHASES` gives the
number of segments), the robot's window (theta4 -> theta1) and the feed (theta1 -> theta2), every
segment of a phase lasting the phase's step ``h`` [s]; it arrives at theta2 + 2 pi with w2 and zero
acceleration and draws at w2 to theta3. A draw at constant slide speed (``Case.free_draw``) is a fourth phase
(:data:`DRAW_PHASE`, theta2 + 2 pi -> theta3 + 2 pi): the cycle then starts at theta3 with the speed ``w2`` and the
acceleration ``draw_accel`` it returns to there (:data:`FREE_DRAW`).
A hold at the bottom (``process.hold_time_s``) puts three phases before the return (:func:`first_layout`): the
brake (:data:`BRAKE_PHASE`, theta3 -> the hold's angle theta_h, arriving at rest with zero acceleration, the crank
never turning back), the standstill (:data:`STAND_PHASE`: one segment of the hold's time, its jerk zero) and the
rise (:data:`RISE_PHASE`: from rest, the crank speeding up all the way, to an angle the planner chooses); the
return then runs from there to theta4. The least crank speed does not hold in these three (:data:`STOP_PHASES`:
the planned stop).
The acceleration is continuous everywhere (piecewise linear); the jerk steps at the knots. There are no
halves, peaks or dwell: :class:`FreeProfileParameters` reports what a press engineer reads off any
plan (speed at TDC, highest speed before and after the draw, peak acceleration and jerk).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planning.model.laws.optimal import OptimalLaw
from planning.model.profile import Profile, Segment, knot_states

Layout = tuple[tuple[str, int], ...]  # (phase, segments) in the order theta3 -> theta4 -> theta1 -> theta2
PHASES: Layout = (("return", 40), ("transfer", 24), ("feed", 40))  # the layout every solve starts with
DRAW_PHASE = ("draw", 40)  # a draw at constant slide speed: the crank's speed planned through it too
FREE_DRAW: Layout = (*PHASES, DRAW_PHASE)  # the first layout of a case whose draw is free (Case.free_draw)
BRAKE_PHASE = ("brake", 16)  # a hold's brake: theta3 -> the hold's angle, to rest
STAND_PHASE = ("stand", 1)  # a hold's standstill: one segment of the hold's time, no jerk
RISE_PHASE = ("rise", 16)  # a hold's rise from rest: the crank speeding up, to an angle of the planner's
REST_PHASES = (BRAKE_PHASE[0], STAND_PHASE[0])  # the phases that end at rest
STOP_PHASES = (*REST_PHASES, RISE_PHASE[0])  # the planned stop: the least crank speed does not hold there
STAND_SEGMENT = f"{STAND_PHASE[0]}:1"  # the standstill's segment (a cam's points stand at its ends)


def first_layout(free_draw: bool, hold: bool = False) -> Layout:
    """The layout a solve starts with: :data:`PHASES`, or :data:`FREE_DRAW` for a draw at constant slide speed;
    with a ``hold`` the brake and the standstill first."""
    layout = FREE_DRAW if free_draw else PHASES
    return (BRAKE_PHASE, STAND_PHASE, RISE_PHASE, *layout) if hold else layout


def holds(layout: Layout) -> bool:
    """Whether ``layout`` brakes to a hold and stands there (its first phases :data:`REST_PHASES`)."""
    return any(phase == STAND_PHASE[0] for phase, _ in layout)


def phase_ends(layout: Layout, key_angles: tuple, hold_angle=None) -> tuple:  # noqa: ANN001 - floats or symbols
    """Each phase's end angle [rad] counted on from theta3's (0): the brake's and the standstill's the hold's
    angle, the rise's None (the planner's), the return's theta4, the window's theta1 a turn on, the feed's theta2
    a turn on, a free draw's theta3 a turn on (``key_angles`` theta1 .. theta4)."""
    th1, th2, th3, th4 = key_angles
    two_pi = 2 * math.pi
    ends = {"return": th4 - th3, "transfer": th1 + two_pi - th3, "feed": th2 + two_pi - th3, "draw": two_pi}
    if hold_angle is not None:
        ends |= {"brake": hold_angle - th3, "stand": hold_angle - th3, RISE_PHASE[0]: None}
    return tuple(ends[phase] for phase, _ in layout)


def draws_freely(layout: Layout) -> bool:
    """Whether ``layout`` plans the draw as a phase of its own (a draw at constant slide speed)."""
    return any(phase == DRAW_PHASE[0] for phase, _ in layout)


FINE_FACTOR = 2.5  # the finer layout: this many times the segments of each phase (finer)


def finer(layout: Layout, factor: float = FINE_FACTOR) -> Layout:
    """``layout`` with ``factor`` times the segments in each phase (a hold's standstill stays one)."""
    return tuple((phase, n if phase == STAND_PHASE[0] else round(n * factor)) for phase, n in layout)


def free_segments(durations, jerks, layout: Layout = PHASES) -> list[Segment]:  # noqa: ANN001 - floats or symbols
    """The segments of durations ``T_k`` [s] and constant jerks ``j_k`` [rad/s^3], named ``PHASE:k``."""
    names = [f"{phase}:{k + 1}" for phase, n in layout for k in range(n)]
    return [Segment(name, T, j, 0.0) for name, T, j in zip(names, durations, jerks, strict=True)]


def closed_jerks(
    durations: tuple[float, ...],
    jerks: tuple[float, ...],
    w2: float,
    ends: tuple[float, ...],
    layout: Layout,
    a0: float = 0.0,
) -> tuple[float, ...]:
    """The jerks [rad/s^3] nearest ``jerks`` (least squares) with which the profile from theta3 (speed ``w2``,
    acceleration ``a0``: 0 but for a free draw) meets its ends exactly: each phase's end angle ``ends`` [rad]
    (:func:`phase_ends`), the speed ``w2`` with the acceleration ``a0`` at the last; a hold's brake ends at rest
    (speed and acceleration 0) and its standstill's jerk is not moved (it stays 0).

    The NLP joins its shooting nodes to IPOPT's constraint tolerance, so the profile propagated through the
    segments' closed forms gathers their defects at its end (1e-9 rad/s of speed over 104 segments: more than
    round-off, which the verification's closure allows). The ends are linear in the jerks when the durations
    stay: a jerk ``j_k`` over ``T_k`` followed by ``S`` seconds adds ``j_k T_k`` of acceleration,
    ``j_k (T_k^2 / 2 + T_k S)`` of speed and ``j_k (T_k^3 / 6 + T_k^2 S / 2 + T_k S^2 / 2)`` of angle; the
    least-norm correction of those five rows is one linear least-squares solve, and moves the jerks by as little as the
    defects are (a relative 1e-9)."""
    T, j = np.asarray(durations, dtype=float), np.asarray(jerks, dtype=float)
    cut = np.cumsum([n for _, n in layout])  # the phases' last segments (+1)
    rows, targets, values = [], [], []
    for end, ((phase, _), index, target) in enumerate(zip(layout, cut, ends, strict=True)):
        after = np.concatenate([np.cumsum(T[:index][::-1])[::-1][1:], [0.0]])  # from each segment's end to this
        gain = np.zeros_like(T)
        gain[:index] = T[:index] ** 3 / 6 + T[:index] ** 2 * after / 2 + T[:index] * after**2 / 2
        span = float(np.sum(T[:index]))
        if target is not None:  # (a hold's rise ends where the planner put it)
            rows.append(gain)
            targets.append(target)
            values.append(w2 * span + a0 * span**2 / 2 + float(gain @ j))  # the angle past theta3 there
        if end == len(cut) - 1 or phase == BRAKE_PHASE[0]:  # the cycle closes, or the crank comes to rest
            speed = np.zeros_like(T)
            speed[:index] = T[:index] ** 2 / 2 + T[:index] * after
            rows += [speed, np.where(np.arange(T.size) < index, T, 0.0)]
            w_end, a_end = (w2, a0) if end == len(cut) - 1 else (0.0, 0.0)
            targets += [w_end, a_end]
            values += [w2 + a0 * span + float(speed @ j), a0 + float(T[:index] @ j[:index])]
    A, residual = np.array(rows), np.array(values) - np.array(targets)
    fixed = np.repeat([phase == STAND_PHASE[0] for phase, _ in layout], [n for _, n in layout])
    A[:, fixed] = 0.0  # (the least-norm correction leaves the standstill's jerk as it is)
    correction = np.linalg.lstsq(A, residual, rcond=None)[0]  # the least-norm one (least squares if degenerate)
    return tuple((j - correction).tolist())


@dataclass(frozen=True)
class FreeProfileParameters:
    """A solved free profile (inside units): ``durations`` [s] and ``jerks`` [rad/s^3] of the segments from
    theta3, ``draw_speed`` w2 [rad/s], ``draw_start`` / ``draw_end`` theta2, theta3 [rad], the phases'
    ``layout`` (:data:`PHASES` or :func:`finer`). The fields a
    report reads of every plan are derived: ``transfer_speed`` (the speed at TDC), ``feed_peak_speed`` and
    ``return_peak_speed`` (the highest speed before theta2 and after theta3, on either side of TDC)."""

    durations: tuple[float, ...]
    jerks: tuple[float, ...]
    draw_speed: float
    draw_start: float
    draw_end: float
    motion_law: str = OptimalLaw.name
    transfer_dwell: float = 0.0
    law_parameter: float = 0.0
    layout: Layout = PHASES
    draw_accel: float = 0.0  # [rad/s^2] at theta3: a free draw's (0 after a draw at constant crank speed)
    hold_angle: float | None = None  # [rad] where a hold's standstill stands (None: no hold)
    hold_time: float = 0.0  # [s] the standstill's time

    @property
    def has_hold(self) -> bool:
        """The crank brakes after the draw and stands at ``hold_angle`` for ``hold_time``."""
        return self.hold_angle is not None

    @property
    def window_time(self) -> float:
        """[s] the robot's window phase, theta4 -> theta1 (at a line's rate the spare time goes there)."""
        return float(sum(T for T, name in zip(self.durations, self._phase_names(), strict=True) if name == "transfer"))

    @property
    def brake_duration(self) -> float:
        """[s] the brake from theta3 to the hold (0 without one)."""
        return float(sum(T for T, name in zip(self.durations, self._phase_names(), strict=True) if name == "brake"))

    def _phase_names(self) -> list[str]:
        return [phase for phase, n in self.layout for _ in range(n)]

    def stop_end_angle(self) -> float:
        """[rad] where a hold's stop ends: the end of the rise from rest (:data:`RISE_PHASE`)."""
        last = sum(n for phase, n in self.layout if phase in STOP_PHASES)  # the knot where the rise ends
        return float(self._knots()[last, 0])

    def segments(self) -> list[Segment]:
        return free_segments(self.durations, self.jerks, self.layout)

    @property
    def free_draw(self) -> bool:
        """The draw is a phase of the profile (a draw at constant slide speed), ``draw_speed`` the speed at
        theta3."""
        return draws_freely(self.layout)

    @property
    def draw_time(self) -> float:
        if self.free_draw:
            return float(sum(self.durations[-dict(self.layout)[DRAW_PHASE[0]] :]))
        return (self.draw_end - self.draw_start) / self.draw_speed

    @property
    def period(self) -> float:
        return float(sum(self.durations)) + (0.0 if self.free_draw else self.draw_time)

    def _knots(self) -> np.ndarray:
        return np.array(knot_states(self.draw_end, self.draw_speed, self.draw_accel, self.segments()), dtype=float)

    def _speeds(self) -> tuple[float, float, float]:
        """Speed at TDC, highest speed on the return side (theta3 -> TDC) and the feed side (TDC -> theta2)."""
        profile = Profile(tuple(self.segments()), self.draw_end, self.draw_speed, self.draw_accel)
        t = np.linspace(0.0, profile.duration, 4001)
        th, om, _, _ = profile.at_time(t)
        tdc = profile.time_at_angle(2 * math.pi)
        return_side, feed_side = t <= tdc, (t >= tdc) & (th <= self.draw_start + 2 * math.pi)  # not a free draw
        w_tdc = float(profile.at_time(tdc)[1])
        return w_tdc, float(np.max(om[return_side], initial=w_tdc)), float(np.max(om[feed_side], initial=w_tdc))

    @property
    def transfer_speed(self) -> float:
        return self._speeds()[0]

    @property
    def return_peak_speed(self) -> float:
        return self._speeds()[1]

    @property
    def feed_peak_speed(self) -> float:
        return self._speeds()[2]

    def peak_accelerations(self) -> list[float]:
        """The largest |crank acceleration| [rad/s^2] (at a knot: it is piecewise linear)."""
        return [float(np.max(np.abs(self._knots()[:, 2])))]

    def peak_jerks(self) -> list[float]:
        """The largest |crank jerk| [rad/s^3] of a segment that lasts."""
        return [max((abs(j) for T, j in zip(self.durations, self.jerks, strict=True) if T > 0), default=0.0)]
