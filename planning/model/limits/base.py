"""A limit of the press cycle, stated once, and the contexts in which the algorithms ask for it.

A limit owns its case field, a stable id, its display name and unit, its NLP parameters and its
expression at the sampled states of any transcription, its dense check with a named tolerance, its
part in the time-optimal bound, the highest constant draw speed it allows, and its precheck. The
algorithms (the NLPs, the bound, the verification, the prechecks, ``pressplan check``) iterate over the
list ``planning.model.limits.LIMITS`` and never name a limit; messages and reports find a limit by its
id (toppra's constraint objects, handed to its algorithms as a list, are the model).

The cycle's own structure is not a limit: the key points, the closing of the cycle and the die-height
crossings (events the transcriptions place, like the key points, so that the die-speed limit can hold
the speed there) are the transcriptions'; so are their variables' scales, which read the slider
acceleration limit every case has. The contexts below are the contract between the limits and the
algorithms:

- :class:`Transcription`: an NLP's states at its samples and the extremes it can express (symbols);
- :class:`Dense`: the dense re-simulation of a plan (numpy arrays);
- :class:`BoundMesh`: the time-optimal bound's grid over crank angle and its variables (symbols);
- :class:`Draw`: the draw at constant crank speed, sampled (numpy arrays), for the draw-speed bounds.

Every expression works on numpy arrays and CasADi symbols alike (``press.backend``); nothing here
imports CasADi.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from typing import Any, ClassVar, NamedTuple

import numpy as np

from planning.model.units import RPM, rounded_down
from planning.tolerances import BINDING_SHARE, SAME_RELATIVE, TINY_SCALE
from press.backend import math_module

DRAW_GRID = 4001  # angles from theta2 to theta3 on which the draw-speed bounds are taken


@dataclass(frozen=True)
class Check:
    """One verified constraint ``id`` (display ``name``): measured ``value`` against ``limit`` (``kind``
    max|min|equal) in ``unit``; where on the cycle it peaked (:class:`Peak`, None for a figure of the whole
    cycle)."""

    name: str
    value: float
    limit: float
    unit: str
    kind: str
    passed: bool
    id: str = field(compare=False)
    refine_by: tuple[str, float, float] | None = field(default=None, compare=False)  # (NLP parameter,
    # factor, ceiling): this check's failure sets the parameter to min(itself, ceiling) x factor (the grid's
    # cap or storage allowance; None: the limit's refined parameter lowered by limit / value, the overshoot)
    peak: Peak | None = field(default=None, compare=False)

    @classmethod
    def of(cls, check_id: str, name: str, value: float, limit: float, unit: str, kind: str, tol: float) -> Check:
        """The check of ``value`` against ``limit`` within ``tol`` (same unit); NaN fails."""
        value, limit = float(value), float(limit)
        if not math.isfinite(value):
            ok = False
        elif kind == "max":
            ok = value <= limit + tol
        elif kind == "min":
            ok = value >= limit - tol
        else:
            ok = abs(value - limit) <= tol
        return cls(name, value, limit, unit, kind, ok, check_id)

    @property
    def margin(self) -> float:
        """Distance to the limit, positive when satisfied (for ``equal``: minus the error)."""
        if self.kind == "max":
            return self.limit - self.value
        if self.kind == "min":
            return self.value - self.limit
        return -abs(self.value - self.limit)

    @property
    def binds(self) -> bool:
        """An inequality that sits at its limit, within :data:`BINDING_SHARE` of it."""
        return self.kind in ("max", "min") and abs(self.margin) <= BINDING_SHARE * max(abs(self.limit), TINY_SCALE)

    def located(self, t: np.ndarray, theta: np.ndarray, values: np.ndarray, scale: float) -> Check:
        """This check with where it peaked: ``values`` (the checked quantity at times ``t`` [s from TDC] and
        crank angles ``theta`` [rad]) at their extreme, and the spans of samples within :data:`BINDING_SHARE`
        of ``scale`` (the limit's size) of it."""
        if not len(values):
            return self
        low = self.kind == "min"
        k = int(np.argmin(values) if low else np.argmax(values))
        room = BINDING_SHARE * max(abs(scale), TINY_SCALE)
        near = values <= values[k] + room if low else values >= values[k] - room
        return replace(self, peak=Peak(float(t[k]), float(math.degrees(theta[k])) % 360.0, spans(t, near)))

    def as_dict(self) -> dict:
        """The check as ``result.json`` writes it (stable id, display name, value, limit, unit, kind, passed,
        margin; where it peaked: ``peak_time_s`` from TDC and ``peak_angle_deg``, None for a figure of the
        whole cycle): a script finds a check by its ``id``, the name is for people."""
        out = asdict(self)
        out.pop("refine_by")
        out.pop("peak")
        place = {"peak_time_s": None, "peak_angle_deg": None}
        if self.peak is not None:
            place = {"peak_time_s": self.peak.time_s, "peak_angle_deg": self.peak.angle_deg}
        return {"id": out.pop("id"), **out, "margin": self.margin, **place}


class Peak(NamedTuple):
    """Where a check's quantity peaked: ``time_s`` [s from TDC] and ``angle_deg`` [deg from TDC] of its
    extreme on the dense samples, and ``spans`` ((start, end) [s] runs of samples within
    :data:`BINDING_SHARE` of the limit of the extreme: where it binds when it binds)."""

    time_s: float
    angle_deg: float
    spans: tuple[tuple[float, float], ...]


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """The runs of consecutive True entries of ``mask`` as ``(first, last)`` index pairs, in order."""
    edges = np.diff(np.concatenate([[0], np.asarray(mask).astype(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return [(int(a), int(b)) for a, b in zip(starts, ends, strict=True)]


def spans(t: np.ndarray, mask: np.ndarray) -> tuple[tuple[float, float], ...]:
    """The runs of ``mask`` over the times ``t`` as ``(first, last)`` time pairs [s]."""
    return tuple((float(t[a]), float(t[b])) for a, b in runs(mask))


class Row(NamedTuple):
    """A block of NLP rows ``lo <= expr <= hi`` named ``name``; ``sampled``: the limit holds at the NLP's
    samples only (the dense check may find it exceeded between them: the search then tightens the limit's
    :attr:`Limit.refined` parameter, or the row's own ``refined`` one)."""

    name: str
    expr: Any
    lo: Any
    hi: Any
    sampled: bool = False
    refined: str | None = None


class Extremes(NamedTuple):
    """Expressions whose largest magnitude is a quantity's peak over the cycle: closed-form peaks
    (``signed`` False: each is a magnitude) or the values at the samples (``signed``, ``sampled``)."""

    values: Any
    signed: bool = False
    sampled: bool = False


@dataclass
class Transcription:
    """What an NLP offers the limits (CasADi symbols; inside units).

    ``theta`` [rad], ``omega`` [rad/s], ``alpha`` [rad/s^2], ``times`` [s]: column vectors at the samples,
    in time order, the draw's ``draw_count`` samples last; ``height`` [mm], ``slope`` [mm/rad],
    ``curvature`` [mm/rad^2]: the mechanism's h, dh/dtheta, d2h/dtheta2 there. ``period`` [s];
    ``window_time`` [s]: the robot's time from theta4 to theta1. ``speeds``, ``accelerations``,
    ``jerks``: the crank's extremes as the transcription can state them (``jerks`` None: its variable
    bounds hold the jerk); ``lowest_speeds``: expressions whose minimum is the lowest crank speed (None:
    its variable bounds hold it). ``crossings``: ``(omega, |dh/dtheta|)`` where the slide passes the die
    height outside the draw; ``exit_speeds``: the same at the die exit's fixed angles, from theta3 to the
    crossing the slide rises through (a denser variant's; held at these samples only, refined); ``zone``:
    the crank speed may peak while the slide is below the die height (rows at every sample there).
    ``rate``: the NLP of a target rate. ``speed_unit`` [rad/s] and ``length_unit`` [mm]: scales of rows.
    ``motor_torque`` [N m], ``motor_speed`` [rad/s] and ``crank_torque`` [N m] at the samples in a drive
    NLP, else None. ``param(name)``: a case parameter's symbol. With robots (``planning.model.limits.robots``):
    ``height_at(times)`` the slide's height [mm] at any times [s from theta3] (periodic), ``robot_starts`` their
    start variables, ``draw_start_time`` [s from theta3] when the next draw starts. The optimal law's free draw (a
    draw at constant slide speed) is sampled like its other phases, its samples the last ``free_draw_count``.
    ``accel_shares``: at each sample outside the draw, its segment's share of the slide-acceleration limit
    (``planning.solver.parameters.share_name``; None: the whole limit at every sample).
    """

    theta: Any
    omega: Any
    alpha: Any
    times: Any
    height: Any
    slope: Any
    curvature: Any
    draw_count: int
    period: Any
    window_time: Any
    speeds: Extremes
    accelerations: Extremes
    jerks: Extremes | None
    lowest_speeds: Any | None
    crossings: list[tuple[Any, Any]]
    zone: bool
    rate: bool
    speed_unit: Any
    length_unit: Any
    param: Callable[[str], Any]
    motor_torque: Any = None
    motor_speed: Any = None
    crank_torque: Any = None
    exit_speeds: list[tuple[Any, Any]] = field(default_factory=list)
    height_at: Callable[[list], Any] | None = None  # the slide's height [mm] at NLP times [s from theta3], any
    robot_starts: dict[str, Any] = field(default_factory=dict)  # each robot's start [s from theta3] (variables)
    draw_start_time: Any = None  # [s from theta3] the next draw's start, theta2 (the end of the cycle outside it)
    free_draw_count: int = 0  # a free draw's samples (a draw at constant slide speed): the last of the samples
    # each sample outside the draw: its segment's share of the slide-acceleration limit (None: the whole limit)
    accel_shares: Any = None

    def in_free_draw(self, values: Any) -> Any:
        """The entries of a sample vector in a free draw (its last :attr:`free_draw_count`)."""
        return values[values.shape[0] - self.free_draw_count :]

    def outside_draw(self, values: Any) -> Any:
        """The entries of a sample vector before the draw's."""
        return values[0 : values.shape[0] - self.draw_count]


@dataclass
class Dense:
    """A plan re-simulated densely (numpy arrays, inside units): times ``t`` [s] from TDC and the crank's
    ``theta``, ``omega``, ``alpha``, ``jerk``, the slide's ``h``, ``v``, ``a`` there; the key points'
    times ``key_times`` [s]; the ``plan`` and the ``case``; with a drive, the drive's state on the grid
    (``drive_state``, ``press.dynamics.drive_state``) and the cycle's integrals (``integrals``,
    ``planning.model.drive.cycle_integrals``); with the drive's electrical side, its power chain (``power``);
    the crank speed and the slide at the key points' exact times (``key_motion``: ``omega``, ``h``, ``v``)."""

    case: Any
    plan: Any
    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    jerk: np.ndarray
    h: np.ndarray
    v: np.ndarray
    a: np.ndarray
    key_times: np.ndarray
    drive_state: dict | None = None
    integrals: dict | None = None
    power: Any = None  # the power chain to the grid (planning.model.drive.PowerFigures), drive.electrical
    slide_jerk: np.ndarray | None = None  # [mm/s^3] the slide's jerk at the samples
    slope: np.ndarray | None = None  # [mm/rad] dh/dtheta at the samples
    curvature: np.ndarray | None = None  # [mm/rad^2] d2h/dtheta2 at the samples
    key_motion: dict | None = None  # at the key points' times: crank speed [rad/s], slide height [mm], speed [mm/s]


@dataclass
class BoundMesh:
    """The time-optimal bound's grid (``planning.solver.bound``): ``theta`` [rad], ``h`` [mm], ``d1``
    [mm/rad], ``d2`` [mm/rad^2] at the n + 1 nodes (node n is node 0 a turn on), ``dtheta`` [rad] of the n
    intervals; the symbols ``s`` (crank speed squared at nodes 0 .. n-1 [rad^2/s^2]), ``s_next`` (at
    1 .. n), ``alpha`` (constant crank acceleration of each interval [rad/s^2]), ``tau`` (each interval's
    time [s]), ``tau_next``; ``window``: the intervals of the robot's window theta4 -> theta1; the
    ``case``."""

    case: Any
    theta: np.ndarray
    h: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    dtheta: np.ndarray
    window: np.ndarray
    s: Any = None
    s_next: Any = None
    alpha: Any = None
    tau: Any = None
    tau_next: Any = None


@dataclass
class RelaxedMesh(BoundMesh):
    """The certified upper bound's grid (``planning.solver.upper_bound``): the nodes and symbols of
    :class:`BoundMesh` (``alpha``: each interval's mean crank acceleration over angle, whatever the motion
    does within it), on nodes where ``h`` is monotone and ``d1^2`` monotone over every interval; each
    interval cut into pieces: ``cell`` (the interval of each piece), ``a``, ``b`` [rad] (its ends), ``h_a``,
    ``h_b`` [mm] (heights there), ``slope2_min`` [mm^2/rad^2] (the least ``d1^2`` over the piece); per piece
    the symbols ``s_a`` / ``s_b`` (``s`` at its interval's start / end node)."""

    cell: np.ndarray = field(kw_only=True)
    a: np.ndarray = field(kw_only=True)
    b: np.ndarray = field(kw_only=True)
    h_a: np.ndarray = field(kw_only=True)
    h_b: np.ndarray = field(kw_only=True)
    slope2_min: np.ndarray = field(kw_only=True)
    s_a: Any = None
    s_b: Any = None


@dataclass
class Draw:
    """The draw at constant crank speed, theta2 -> theta3: ``theta`` [rad] on :data:`DRAW_GRID` angles and
    the mechanism's ``h`` [mm], ``d1`` [mm/rad], ``d2`` [mm/rad^2] there; the ``case``."""

    case: Any
    theta: np.ndarray
    h: np.ndarray
    d1: np.ndarray
    d2: np.ndarray

    @classmethod
    def of(cls, case: Any) -> Draw:
        _, th2, th3, _ = case.key_angles
        theta = np.linspace(th2, th3, DRAW_GRID)
        h, d1, d2, _ = case.machine.jets(theta)
        return cls(case, theta, h, d1, d2)


class Envelope(NamedTuple):
    """An upper bound on the crank speed squared [rad^2/s^2] over each piece of the certified upper bound's
    mesh, for every motion that meets the limit: ``value`` (one per piece, affine in the node values; the
    largest the limit allows anywhere in the piece), ``where`` (the pieces on which it holds), ``side``:
    ``"start"`` when it grows from the interval's start node (tight near it), ``"end"`` from its end node."""

    value: Any
    where: np.ndarray
    side: str


class Impossible(NamedTuple):
    """A limit that provably cannot be met, found before solving: ``reason`` (one line), the case
    ``field`` (dotted), its ``value``, what it would have to be (``needed``) and where (``angle_deg``)."""

    reason: str
    field: str
    value: float | None = None
    needed: float | None = None
    angle_deg: float | None = None


class Limit:
    """A limit of the press cycle (module docstring). Class attributes: ``id`` (stable), ``name`` (shown),
    ``unit``, ``field`` (the dotted case field a user changes to relax it), ``order`` (its place in every
    list), ``section_fields`` (the keys it adds to the case's ``limits:`` section: name -> (type, default;
    ``...`` required)), ``parameters`` (its NLP parameters, set by :meth:`parameter_values`), ``refined``
    (the parameter the search tightens when the dense check finds the limit exceeded between an NLP's
    samples; ``refine_upward``: a lower limit, raised instead), ``backoff`` (relative: the NLP holds the
    limit this much inside) and ``harder_backoff`` (a wider one for a second round when no start
    verified; None: not widened), ``overestimated`` (its NLP row can
    overstate the exact figure: where the row is active but the exact check leaves room, the search
    loosens the parameter once by the room), ``motor`` (a limit of the motor: a plan of the NLP without
    the drive's rows cannot be trusted to keep it), ``uses_drive`` (its rows need the drive's torque at
    the samples: drive NLPs only), ``refuses_draw_speed_above_bound`` (a draw speed given in the case above
    the limit's bound is an error in the case, exit 2, rather than an infeasible plan), ``goal`` (a goal of
    the plan, such as a target rate, rather than a limit of the press or the process: a cam, which an
    operator may run faster or slower, is not held to it), ``precheck_at_one_draw_speed`` (its precheck reads the
    draw at one crank speed: it does not run for a draw at constant slide speed, whose crank need not turn at one
    speed; the dense check decides there). Every method has a default that does nothing."""

    id: ClassVar[str]
    name: ClassVar[str]
    unit: ClassVar[str]
    field: ClassVar[str]
    order: ClassVar[int]
    section_fields: ClassVar[dict[str, tuple[Any, Any]]] = {}
    parameters: ClassVar[tuple[str, ...]] = ()
    refined: ClassVar[str | None] = None
    refine_upward: ClassVar[bool] = False
    backoff: ClassVar[float] = 0.0
    harder_backoff: ClassVar[float | None] = None
    overestimated: ClassVar[bool] = False
    motor: ClassVar[bool] = False
    uses_drive: ClassVar[bool] = False
    refuses_draw_speed_above_bound: ClassVar[bool] = False
    goal: ClassVar[bool] = False
    precheck_at_one_draw_speed: ClassVar[bool] = False

    def applies(self, case: Any) -> bool:
        """Whether ``case`` sets this limit (an NLP of the case has its rows only then)."""
        return True

    def validate(self, case: Any) -> None:
        """Raise :class:`~planning.model.errors.CaseError` when the limit's fields do not hold together
        with the rest of the case (read time)."""

    def refuse_draw_speed(self, draw: Draw, speed: float) -> str | None:
        """Why a draw speed ``speed`` [rad/s] given in the case is an error in the case (exit 2), or None:
        above the top crank speed the limit sets (:meth:`top_crank_speed`), or, with
        ``refuses_draw_speed_above_bound``, above its draw-speed bound."""
        top = self.top_crank_speed(draw.case)
        if top is not None and speed > top * (1 + SAME_RELATIVE):
            return f"is above the {top / RPM:.6g} rpm on the crank that {self.field} allows"
        if not self.refuses_draw_speed_above_bound:
            return None
        bound = self.draw_speed_bound(draw)
        if bound is None or speed <= bound * (1 + SAME_RELATIVE):
            return None
        return f"is above the {rounded_down(bound / RPM)} rpm that {self.field} allows"

    def draw_speed_bound(self, draw: Draw) -> float | None:
        """The highest constant draw speed [rad/s] this limit allows (None: it sets none)."""
        return self.top_crank_speed(draw.case)

    def top_crank_speed(self, case: Any) -> float | None:
        """The crank speed [rad/s] this limit keeps the crank below everywhere (None: it sets none)."""
        return None

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        """``pressplan check``'s static checks at draw speed ``speed`` [rad/s] (no plan)."""
        return []

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """A necessary condition before any NLP, at the draw speed ``given`` [rad/s] (None: free, at least
        ``lowest``)."""
        return None

    def parameter_values(self, case: Any) -> dict[str, float]:
        """The values of :attr:`parameters` for ``case`` (inside units)."""
        return {}

    def rows(self, nlp: Transcription) -> list[Row]:
        """The limit's rows in an NLP."""
        return []

    def check(self, dense: Dense) -> list[Check]:
        """The limit's checks on the dense re-simulation."""
        return []

    def bound_speeds(self, mesh: BoundMesh) -> tuple[np.ndarray | None, np.ndarray | None]:
        """The limit's bounds ``(lower, upper)`` on the crank speed squared [rad^2/s^2] at the bound's nodes
        0 .. n-1 (None: none); numbers, known before the bound's variables (``grid`` without symbols)."""
        return None, None

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        """The limit's rows ``(expr, lo, hi)`` over the bound's intervals."""
        return []

    def relaxed_rows(self, mesh: RelaxedMesh) -> list[tuple[Any, Any, Any]] | None:
        """The limit's rows ``(expr, lo, hi)`` in the certified upper bound: conditions every motion that
        meets the limit meets at the grid's nodes and over its intervals (never a restriction). None: the
        limit has no such form and is left out of the upper bound (which stays an upper bound, looser).
        By default: none needed when the limit has no rows in the grid bound (its speed bounds at the
        nodes, :meth:`bound_speeds`, hold at any angle), else None."""
        return [] if type(self).bound_rows is Limit.bound_rows else None

    def relaxed_caps(self, mesh: RelaxedMesh) -> np.ndarray | None:
        """An upper bound on the crank speed squared [rad^2/s^2] valid over each whole piece (numbers;
        None: none), the largest the limit allows anywhere in the piece."""
        return None

    def relaxed_envelopes(self, mesh: RelaxedMesh) -> list[Envelope]:
        """The limit's :class:`Envelope` s of the crank speed squared over the grid's pieces (none by
        default)."""
        return []

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


def sample_vector(values: list[Any]) -> Any:
    """Expressions as one column (CasADi ``vertcat``, numpy ``concatenate``)."""
    m = math_module(*values)
    if m is np:
        return np.concatenate([np.atleast_1d(v) for v in values])
    return m.vertcat(*values)


def total(values: Any) -> Any:
    """The sum of a column (CasADi ``sum1``, numpy ``sum``)."""
    m = math_module(values)
    return np.sum(values) if m is np else m.sum1(values)


def trapezoid(values: Any, times: Any) -> Any:
    """The trapezoidal integral of a column of ``values`` at the sample ``times`` [s]."""
    n = values.shape[0]
    return total((times[1:n] - times[0 : n - 1]) * (values[1:n] + values[0 : n - 1]) / 2)
