"""The pendulum (swing) stroke: the crank swings through BDC and back, never passing TDC; each swing a stroke.

A cycle is two swings. The forward swing starts at rest at theta_s (before theta1), turns forward through
the case's key angles theta1 .. theta4 and comes to rest at theta_e (after theta4); the crank stands there
``turn_end_s`` [s]; the backward swing turns back through BDC to rest at theta_s, where it stands
``turn_start_s`` [s]. On the way back the slide passes the key heights in the other order of crank angle:
the backward swing's key angles are where the slide is at the same heights on the other side of BDC
(:func:`backward_key_angles`; on an in-line crank-slider ``2 pi - theta_k``).

Each swing is laid out on its own path coordinate ``u`` that grows as the swing goes (a swing is then a
forward motion with speeds >= 0, as a rotary cycle's): ``u = theta`` on the forward swing and
``u = 2 pi - theta`` on the backward one. On the backward swing the mechanism reads ``h_b(u) = h(2 pi -
u)``, so ``h_b' = -h'``, ``h_b'' = h''``: the slide's speed ``h' dtheta/dt = h_b' du/dt`` and acceleration
``h'' (dtheta/dt)^2 + h' d2theta/dt2 = h_b'' (du/dt)^2 + h_b' d2u/dt2`` read the same in either
coordinate, and so do |crank speed|, |acceleration| and |jerk| (the crank's own signs flip). A swing runs,
as a rotary cycle does from the transfer: the feed, one half of the law from rest to the peak wm1 and one
down to the draw speed w2 (at theta2); the draw at constant w2 to theta3; the return, one half up to the
peak wm2 and one down to rest at the swing's end. Every half follows the case's motion law
(``planning.model.laws``). Strokes per minute count swings: ``120 / period``.

Sign conventions: the crank angle [rad] from TDC, the crank speed positive forward (negative on the backward
swing), the slide's height above BDC, its speed positive upward. Time 0 of a pendulum plan is the forward
swing's start (the crank at rest at theta_s, at the end of its standstill there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from planning.model.cycle import BRAKE, BRAKE_PREFIX, HOLD_SEGMENT, brake_time
from planning.model.laws import get_law
from planning.model.limits import limits_of
from planning.model.limits.base import DRAW_GRID, Draw
from planning.model.limits.hold import least_rate
from planning.model.profile import Profile, Segment
from planning.tolerances import (
    ANGLE_ROUND_OFF_RAD,
    ANGLE_TOL_RAD,
    HOLD_STILL_RAD_S,
    MIRROR_HEIGHT_MM,
    SAME_TIME_S,
    TINY,
)
from press.dynamics import table_force

TWO_PI = 2 * math.pi
SWINGS = ("forward", "backward")
STROKES_PER_CYCLE = 2  # a pendulum cycle is two swings, each a stroke
TURN_SEGMENT = "turn:standstill"  # the crank standing at a swing's end
SWING_HALVES = ("feed_accel", "feed_decel", "return_accel", "return_decel")
DRAW_BOUND_LIMITS = ("crank_speed", "motor_speed", "slider_accel", "slider_speed", "draw_start_speed")  # their own
BISECTIONS = 60  # halvings of a bracket to find where the draw crosses the die height
DIE_ZONE_POINTS = 5  # angles of a swing's return in the die zone at which the NLP holds the die speed
MIRROR_PROBES = 361  # angles over a turn at which a mechanism is compared with its mirror (mirror_symmetric)
TIME_BISECTIONS = 200  # halvings of a swing's time to find when it passes an angle (stopped at SAME_TIME_S)


@dataclass(frozen=True)
class SwingParameters:
    """One swing on its path coordinate u [rad] (module docstring): ``draw_speed`` w2, ``feed_peak_speed`` wm1,
    ``return_peak_speed`` wm2 [rad/s, >= 0]; the four halves' durations [s]; ``start``, ``draw_start``,
    ``draw_end``, ``end``: u at the swing's start, theta2, theta3 and its end [rad]; the ``motion_law`` and its
    ``law_parameter`` (0 when it has none); ``hold_angle``: u [rad] of a hold at the bottom (None: none), where
    the crank stands ``hold_time`` [s] (``planning.model.cycle``'s brake, standstill and rise from rest)."""

    draw_speed: Any
    feed_peak_speed: Any
    return_peak_speed: Any
    feed_accel_duration: Any
    feed_decel_duration: Any
    return_accel_duration: Any
    return_decel_duration: Any
    start: Any
    draw_start: Any
    draw_end: Any
    end: Any
    motion_law: str
    law_parameter: Any = 0.0
    hold_angle: Any = None
    hold_time: Any = 0.0

    @property
    def has_hold(self) -> bool:
        """The crank brakes after the draw and stands at the hold (``hold_angle`` on u) for ``hold_time``."""
        return self.hold_angle is not None

    @property
    def brake_duration(self) -> Any:
        """The brake half's duration [s] from w2 to standstill over theta3 -> the hold (0 without a hold): every
        half sweeps ``D (v0 + v1) / 2`` (``planning.model.cycle``)."""
        return brake_time(self.hold_angle, self.draw_end, self.draw_speed) if self.has_hold else 0.0

    @property
    def return_start_speed(self) -> Any:
        """The speed the return rises from [rad/s]: w2, or 0 after a hold."""
        return 0.0 if self.has_hold else self.draw_speed

    def halves(self) -> tuple[str, ...]:
        """The swing's halves: :data:`SWING_HALVES` and, with a hold, the brake."""
        return SWING_HALVES + ((BRAKE,) if self.has_hold else ())

    def half(self, name: str) -> tuple[Any, Any]:
        """``(duration [s], speed change [rad/s])`` of the half ``name`` (:meth:`halves`)."""
        w2, wm1, wm2 = self.draw_speed, self.feed_peak_speed, self.return_peak_speed
        if name == BRAKE:
            return self.brake_duration, -w2
        wr = self.return_start_speed
        dv = {"feed_accel": wm1, "feed_decel": w2 - wm1, "return_accel": wm2 - wr, "return_decel": -wm2}
        return getattr(self, f"{name}_duration"), dv[name]

    @property
    def draw_time(self) -> Any:
        """Duration [s] of the draw at constant w2."""
        return (self.draw_end - self.draw_start) / self.draw_speed

    @property
    def feed_time(self) -> Any:
        """Duration [s] from the swing's start to theta2."""
        return self.feed_accel_duration + self.feed_decel_duration

    @property
    def return_time(self) -> Any:
        """Duration [s] from theta3 to the swing's end (the brake and the hold included)."""
        halves = self.return_accel_duration + self.return_decel_duration
        return halves + self.brake_duration + self.hold_time if self.has_hold else halves

    @property
    def duration(self) -> Any:
        """The swing's time [s] from rest to rest."""
        return self.feed_time + self.draw_time + self.return_time

    def feed_segments(self) -> list[Segment]:
        """The feed's segments on u, from rest at the start to w2 at theta2."""
        law = get_law(self.motion_law)
        out: list[Segment] = []
        for name in SWING_HALVES[:2]:
            out += law.half(name.replace("_", ":"), *self.half(name), self.law_parameter)
        return out

    def return_segments(self) -> list[Segment]:
        """The return's segments on u, from w2 at theta3 to rest at the end (with a hold: the brake to rest at
        the hold, the standstill there, then the rise from rest)."""
        law = get_law(self.motion_law)
        out: list[Segment] = []
        if self.has_hold:
            out += law.half(BRAKE_PREFIX, *self.half(BRAKE), self.law_parameter)
            out.append(Segment(HOLD_SEGMENT, self.hold_time, 0.0, 0.0))
        for name in SWING_HALVES[2:]:
            out += law.half(name.replace("_", ":"), *self.half(name), self.law_parameter)
        return out

    def segments(self) -> list[Segment]:
        """The whole swing's segments on u: feed, draw, return."""
        draw = Segment("draw:constant", self.draw_time, 0.0, 0.0)
        return self.feed_segments() + [draw] + self.return_segments()

    def speed_changes(self) -> list[Any]:
        """|speed change| [rad/s] of each half (:meth:`halves`) as the halves are monotone (the peaks at or above
        the speeds they join, which the NLP holds): wm1, wm1 - w2, wm2 - wr, wm2 (wr the return's start speed),
        and w2 for the brake."""
        w2, wm1, wm2 = self.draw_speed, self.feed_peak_speed, self.return_peak_speed
        return [wm1, wm1 - w2, wm2 - self.return_start_speed, wm2] + ([w2] if self.has_hold else [])

    def peak_accelerations(self) -> list[Any]:
        """Peak |crank acceleration| [rad/s^2] of each half (the law's closed form)."""
        rate = get_law(self.motion_law).peak_rate(self.law_parameter)
        durations = [self.half(n)[0] for n in self.halves()]
        return [rate * dv / D for D, dv in zip(durations, self.speed_changes(), strict=True)]

    def peak_jerks(self) -> list[Any]:
        """Peak |crank jerk| [rad/s^3] of each half (the law's closed form)."""
        jerk = get_law(self.motion_law).peak_jerk(self.law_parameter)
        durations = [self.half(n)[0] for n in self.halves()]
        return [jerk * dv / D**2 for D, dv in zip(durations, self.speed_changes(), strict=True)]


@dataclass(frozen=True)
class PendulumParameters:
    """A pendulum cycle: the ``forward`` and ``backward`` swings (:class:`SwingParameters`, each on its own
    u), the standstills ``turn_end_s`` at theta_e and ``turn_start_s`` at theta_s [s]."""

    forward: SwingParameters
    backward: SwingParameters
    turn_end_s: Any
    turn_start_s: Any

    @property
    def swing_start(self) -> Any:
        """theta_s [rad]: where the forward swing starts and the backward one ends."""
        return self.forward.start

    @property
    def swing_end(self) -> Any:
        """theta_e [rad]: where the forward swing ends and the backward one starts."""
        return self.forward.end

    @property
    def period(self) -> Any:
        """The cycle time [s]: both swings and both standstills."""
        return self.forward.duration + self.turn_end_s + self.backward.duration + self.turn_start_s

    @property
    def motion_law(self) -> str:
        return self.forward.motion_law

    def segments(self) -> list[Segment]:
        """The cycle's segments in the crank's own angle (the backward swing's jerks and speed changes negated):
        forward swing, standstill at theta_e, backward swing, standstill at theta_s."""
        back = [reversed_segment(s) for s in self.backward.segments()]
        return [
            *[_named("forward", s) for s in self.forward.segments()],
            Segment(TURN_SEGMENT, self.turn_end_s, 0.0, 0.0),
            *[_named("backward", s) for s in back],
            Segment(TURN_SEGMENT, self.turn_start_s, 0.0, 0.0),
        ]


def reversed_segment(seg: Segment) -> Segment:
    """A segment of the backward swing on u as the crank turns it: every jerk and speed change negated."""
    return seg._replace(j0=-seg.j0, j1=-seg.j1, dv=-seg.dv)


def _named(swing: str, seg: Segment) -> Segment:
    return seg._replace(name=f"{swing} {seg.name}")


def swing_of(name: str) -> str:
    """The swing a segment ``name`` belongs to (``forward``, ``backward`` or ``turn``)."""
    return name.split(" ", 1)[0] if " " in name else "turn"


def other_side(machine: Any, theta: float) -> float:
    """The crank angle [rad] on the other side of BDC where the slide is at the height it has at ``theta``."""
    bdc = float(machine.bdc_angle)
    if abs(theta - bdc) <= ANGLE_ROUND_OFF_RAD:
        return bdc
    down, up = (float(a) for a in machine.angles_at_height(float(machine.height(theta))))
    return up if theta < bdc else down


def mirror_symmetric(machine: Any) -> bool:
    """Whether the slide's height is the same either side of BDC at 180 deg, ``h(2 pi - theta) = h(theta)`` (an
    in-line crank-slider; not an offset crank, a link drive or a knuckle joint), to :data:`MIRROR_HEIGHT_MM` at
    :data:`MIRROR_PROBES` angles: the backward swing on its u is then the forward swing's problem."""
    theta = np.linspace(0.0, TWO_PI, MIRROR_PROBES)
    gap = np.abs(np.asarray(machine.height(TWO_PI - theta)) - np.asarray(machine.height(theta)))
    return bool(np.max(gap) <= MIRROR_HEIGHT_MM)


def backward_key_angles(case: Any) -> tuple[float, float, float, float]:
    """The backward swing's key angles [rad, the crank's own]: where the slide passes the heights of theta1 ..
    theta4 on the way back (theta1 and theta2 on the far side of BDC, theta3 and theta4 as the draw's end and the
    opening fall); decreasing in order."""
    m = case.machine
    return tuple(other_side(m, float(a)) for a in case.key_angles)  # type: ignore[return-value]


def swing_bounds(case: Any) -> tuple[tuple[float, float], tuple[float, float]]:
    """``((lowest, highest) theta_s, (lowest, highest) theta_e)`` [rad]: theta_s at or before theta1 and the
    backward swing's opening, theta_e at or after theta4 and the backward swing's closing (the slide reaches
    the robot's heights on every swing), neither past TDC."""
    th1, _, _, th4 = (float(a) for a in case.key_angles)
    b1, _, _, b4 = backward_key_angles(case)
    return (0.0, min(th1, b4)), (max(th4, b1), TWO_PI)


def mirrored_jets(machine: Any, u: Any) -> tuple[Any, Any, Any, Any]:
    """The mechanism on the backward swing's coordinate ``u = 2 pi - theta``: ``(h, h_b', h_b'', h_b''')``."""
    h, d1, d2, d3 = machine.jets(TWO_PI - u)
    return h, -d1, d2, -d3


def profile_of(params: PendulumParameters) -> Profile:
    """The cycle as a profile in the crank's own angle from the forward swing's start (at rest at theta_s)."""
    segs = tuple(s for s in params.segments() if float(s.duration) > 0)
    return Profile(segs, float(params.swing_start), 0.0, 0.0)


@dataclass(frozen=True)
class PendulumPlan:
    """A solved pendulum cycle: its ``parameters``, the ``profile`` (time 0 at the forward swing's start), the
    key angles of each swing [rad, the crank's own] (``forward_keys``, ``backward_keys``), the ``solver``'s
    report (``planning.model.plan.SolverInfo``) and the NLP's variable values; ``time_scale``: the profile runs
    this many times as fast as the parameters say (a cam run at another master speed: its swings' times
    divided by it); ``robot_starts_s``: with robots, each robot's start in each window (``at theta_e``, ``at
    theta_s``) [s from the forward swing's start, as planned: divided by ``time_scale`` as run]."""

    parameters: PendulumParameters
    profile: Profile
    forward_keys: tuple[float, float, float, float]
    backward_keys: tuple[float, float, float, float]
    solver: Any
    nlp_values: dict[str, float]
    time_scale: float = 1.0
    robot_starts_s: dict[str, dict[str, float]] = field(default_factory=dict)

    @property
    def slave_turn_deg(self) -> float:
        """[deg] the crank's turn over one cycle: none, the swings bring it back (a cam's slave returns)."""
        return 0.0

    @property
    def period(self) -> float:
        return self.profile.duration

    @property
    def spm(self) -> float:
        """Strokes per minute: swings per minute."""
        return STROKES_PER_CYCLE * 60.0 / self.period

    @property
    def motion_law(self) -> str:
        return self.parameters.motion_law

    def swing_spans(self) -> dict[str, tuple[float, float]]:
        """``name -> (start, end)`` [s] of each swing's motion (the standstills between)."""
        f, b = self.parameters.forward, self.parameters.backward
        k = self.time_scale
        tf = float(f.duration)
        tb0 = tf + float(self.parameters.turn_end_s)
        return {"forward": (0.0, tf / k), "backward": (tb0 / k, (tb0 + float(b.duration)) / k)}

    @property
    def strokes_per_cycle(self) -> int:
        """The strokes of one cycle: its two swings."""
        return STROKES_PER_CYCLE

    def windows(self) -> dict[str, tuple[float, float]]:
        """The robot's two windows, ``name -> (start, end)`` [s from the forward swing's start]: from the forward
        swing's theta4 through the turn at theta_e to the backward swing's theta1, and from the backward swing's
        theta4 through the turn at theta_s to the next forward theta1 (past the period)."""
        return windows_of(self.key_times("forward"), self.key_times("backward"), self.period)

    def transfer_window(self) -> float:
        """The shorter of the robot's two windows [s]."""
        return min(end - start for start, end in self.windows().values())

    def key_times(self, swing: str) -> np.ndarray:
        """Times [s from the forward swing's start] at which ``swing`` passes its four key angles."""
        keys = self.forward_keys if swing == "forward" else self.backward_keys
        lo, hi = self.swing_spans()[swing]
        return np.array([time_at(self.profile, float(a), lo, hi) for a in keys])


def windows_of(forward: np.ndarray, backward: np.ndarray, period: float) -> dict[str, tuple[float, float]]:
    """The robot's two windows of a cycle whose swings pass their key angles at times ``forward`` and
    ``backward`` [s] (:meth:`PendulumPlan.windows`)."""
    f, b = forward, backward
    return {"at theta_e": (float(f[3]), float(b[0])), "at theta_s": (float(b[3]), float(f[0]) + period)}


def time_at(profile: Profile, theta: float, lo: float, hi: float) -> float:
    """The time [s] in ``lo .. hi`` (one swing: the angle monotone there) at which the crank is at ``theta``; an
    angle beyond the swing's ends by at most ``ANGLE_TOL_RAD`` (the key angles' tolerance) is at the nearer end.
    ``ValueError`` for one farther off."""
    th_lo = float(profile.at_time(np.array([lo]))[0][0])
    th_hi = float(profile.at_time(np.array([hi]))[0][0])
    rising = th_hi >= th_lo
    low, high = min(th_lo, th_hi), max(th_lo, th_hi)
    if not low - ANGLE_TOL_RAD <= theta <= high + ANGLE_TOL_RAD:
        raise ValueError("angle outside the swing")
    if not low < theta < high:  # at an end, to the key angles' tolerance
        return lo if abs(theta - th_lo) <= abs(theta - th_hi) else hi
    a, b = lo, hi
    for _ in range(TIME_BISECTIONS):
        mid = 0.5 * (a + b)
        th = float(profile.at_time(np.array([mid]))[0][0])
        if (th < theta) == rising:
            a = mid
        else:
            b = mid
        if b - a <= SAME_TIME_S:
            break
    return 0.5 * (a + b)


@dataclass(frozen=True)
class SwingSetup:
    """What one swing's NLP needs before solving: its ``name``; its key angles ``keys`` on u [rad]; ``jets(u)``
    (the mechanism on u: h and its first three derivatives); ``die_zone``: angles u [rad] of the return in the
    die zone (:func:`die_zone`, empty when the return stays above the die height); ``draw_speed_bound``
    [rad/s]: the highest constant draw speed the limits allow in its draw."""

    name: str
    keys: tuple[float, float, float, float]
    jets: Any
    die_zone: tuple[float, ...]
    draw_speed_bound: float
    hold: float | None = None  # u [rad] of the hold (``process.hold_time_s``): where the slide stands on this swing


def swing_setups(case: Any, limits: dict[str, float]) -> tuple[SwingSetup, SwingSetup]:
    """Both swings' :class:`SwingSetup` (``limits``: the refined values of the sampled limits, by id)."""
    m = case.machine
    fwd = tuple(float(a) for a in case.key_angles)
    back = tuple(TWO_PI - a for a in backward_key_angles(case))
    holds = (None, None) if case.hold_angle is None else hold_angles(case)
    out = []
    for name, keys, hold in zip(SWINGS, (fwd, back), holds, strict=True):
        jets = m.jets if name == "forward" else (lambda u: mirrored_jets(m, u))  # noqa: E731 - one line each
        bound = draw_speed_bound(case, keys, jets, limits, hold)
        out.append(SwingSetup(name, keys, jets, die_zone(case, name, keys), bound, hold))
    return out[0], out[1]


def hold_angles(case: Any) -> tuple[float, float]:
    """The hold's angle on each swing's u [rad]: where the slide passes the hold height on its way down (BDC for
    a hold at BDC)."""
    return float(case.hold_angle), TWO_PI - other_side(case.machine, float(case.hold_angle))


def die_zone(case: Any, swing: str, keys: tuple[float, ...]) -> tuple[float, ...]:
    """:data:`DIE_ZONE_POINTS` angles u [rad] of the swing's return at or below the die height: evenly from where
    the slide comes down through it after theta3 (or, where the draw ends in the zone, one step past theta3) to
    where it rises out of it; empty when the return is above the die height all along."""
    m, die = case.machine, case.limits.die_height_mm
    down, up = (float(a) for a in m.angles_at_height(min(die, m.stroke)))
    entry, leave = (down, up) if swing == "forward" else (TWO_PI - up, TWO_PI - down)
    u3 = keys[2]
    if u3 >= leave:
        return ()
    if u3 < entry:
        return tuple(float(a) for a in np.linspace(entry, leave, DIE_ZONE_POINTS))
    return tuple(float(a) for a in np.linspace(u3, leave, DIE_ZONE_POINTS + 1)[1:])


def draw_speed_bound(
    case: Any, keys: tuple[float, ...], jets: Any, limits: dict[str, float], hold: float | None = None
) -> float:
    """The highest constant draw speed [rad/s] in a swing's draw (``keys`` on u, ``jets`` the mechanism on u):
    each limit's own bound on the draw (``Limit.draw_speed_bound``), the die speed's over the draw's part at
    or below the die height and where the draw crosses it, and with a hold at ``hold`` (u) the speed the crank can
    brake from to the hold (``planning.model.limits.hold``: ``sqrt(2 A (u_h - u3) / rate)``)."""
    theta = np.linspace(keys[1], keys[2], DRAW_GRID)
    h, d1, d2, _ = jets(theta)
    draw = Draw(case, theta, np.asarray(h), np.asarray(d1), np.asarray(d2))
    bounds = [math.inf]
    for limit in limits_of(case):
        if limit.id in DRAW_BOUND_LIMITS:
            b = limit.draw_speed_bound(draw)
            bounds.append(math.inf if b is None else b)
    die, v_die = case.limits.die_height_mm, limits.get("die_speed", case.limits.die_speed_mm_s)
    slopes = list(np.abs(d1[h <= die]))
    inside = np.flatnonzero(np.diff(np.sign(h - die)) != 0)
    for k in inside:  # where the draw crosses the die height: the slope there, by bisection on u
        a, b = theta[k], theta[k + 1]
        for _ in range(BISECTIONS):
            mid = 0.5 * (a + b)
            if (float(jets(mid)[0]) - die) * (float(jets(a)[0]) - die) <= 0:
                b = mid
            else:
                a = mid
        slopes.append(abs(float(jets(0.5 * (a + b))[1])))
    steepest = max(slopes, default=0.0)
    bounds.append(v_die / steepest if steepest > 0 else math.inf)
    accel = limits.get("slider_accel")
    if accel is not None:  # the refined acceleration limit in the draw too
        bounds.append(math.sqrt(accel / max(float(np.max(np.abs(d2))), TINY)))
    top = case.limits.crank_accel_rad_s2
    if hold is not None and top is not None:
        bounds.append(math.sqrt(2 * top * (hold - keys[2]) / least_rate(case)))
    return min(bounds)


def swing_forming_N(case: Any, theta: np.ndarray, omega: np.ndarray, h: np.ndarray) -> np.ndarray:
    """The forming force [N, upward on the slide] on a pendulum stroke at crank angles ``theta`` [rad], speeds
    ``omega`` [rad/s] and slide heights ``h`` [mm]: the case's table (``press.dynamics.table_force``) from theta2
    to BDC turning forward, and on the backward swing over the same arc of the slide's way down, from its theta2
    back to BDC, a hold's standstill within either included; zero elsewhere (``press.dynamics``: a rotary
    stroke's window, on either swing). Needs a drive."""
    theta, omega = np.asarray(theta, dtype=float), np.asarray(omega, dtype=float)
    bdc = float(case.machine.bdc_angle)
    th2, back2 = float(case.key_angles[1]), backward_key_angles(case)[1]
    standing = np.abs(omega) <= HOLD_STILL_RAD_S  # (a hold at rest within either: the force acts there)
    forward = ((omega > 0) | standing) & (theta >= th2) & (theta <= bdc)
    backward = ((omega < 0) | standing) & (theta >= bdc) & (theta <= back2)
    return table_force(h, forward | backward, case.drive_model)


def forming_on_path(case: Any, swing: str, u: Any, h: Any) -> Any:
    """The forming force [N] at path angles ``u`` [rad] of ``swing`` (numbers or symbols; the swing turning its
    way): the table's where u lies between theta2 and BDC on that swing's path (:func:`swing_forming_N`)."""
    bdc = float(case.machine.bdc_angle)
    u2 = float(case.key_angles[1]) if swing == "forward" else TWO_PI - backward_key_angles(case)[1]
    u_bdc = bdc if swing == "forward" else TWO_PI - bdc
    return table_force(h, (u >= u2) * (u <= u_bdc), case.drive_model)
