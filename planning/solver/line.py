"""Planning a press line (the model and its equations: ``planning.model.line``), in named steps: each station
alone (its fastest verified plan with its robots), the line's period and what binds it, each station's plan at
that period, the phase offsets, the robots' schedules on the master, the line's verification.

A line is a success only when every station's plan at the line's period passes its own dense verification
(its limits, its robots' clearances at every millisecond and at their curves' crossings) with its cycle
time the line's, and every robot's schedule holds: the transfer robot's load starts at least its transfer
time after its unload ends and its next unload at least that long after the load ends (the feeder's and the
exit's loops within the period).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from planning.model.case import Case
from planning.model.limits.base import Check
from planning.model.line import Line, LineRobot, Station, occupancy_s, phase_offsets_s, tool
from planning.model.outcome import Outcome
from planning.model.pendulum import STROKES_PER_CYCLE, PendulumPlan
from planning.solver.ahead import in_turn, side_by_side
from planning.solver.objectives import solve_at_period, solve_fastest
from planning.solver.outcomes import Infeasible, PlanningError
from planning.solver.pendulum_line import fastest_swings, line_period_s, line_starts_s, shifts_s, swings_at_period
from planning.solver.solution import Solution
from planning.tolerances import SAME_PERIOD_S, SAME_POSITION_MM, TIME_TOL_S

INSIDE_STEP_S = 1e-3  # [s] the robots' overlap check's step (the presses' verification grid's)


class StationError(PlanningError):
    """A station without a verified plan (alone, or at the line's period): its outcome, its name in the reason."""

    def __init__(self, station: Station, exc: PlanningError, when: str):
        self.outcome = exc.outcome
        self.station = station.name
        super().__init__(f"station {station.name} ({station.path.name}) {when}: {exc.reason}")


class LineUnverified(PlanningError):
    """Plans for every station, but the line's verification failed (named in the reason)."""

    outcome = Outcome.UNVERIFIED


@dataclass(frozen=True)
class RobotStretch:
    """One stretch of a line robot's cycle on the line's master: ``what`` it does (``unload draw``, ``to
    trim``, ``wait``, ``load trim``, ``back to draw``, ``away``), from ``start_s`` [s, within the period] for
    ``duration_s`` [s]; ``station``: the press it is inside (None: outside every press)."""

    what: str
    start_s: float
    duration_s: float
    station: str | None = None


@dataclass(frozen=True)
class Bottleneck:
    """What sets the line's period: a press alone with its robots (``kind`` "press") or a robot's loop
    (``kind`` "robot"), by ``name``, with its period [s]."""

    kind: str
    name: str
    period_s: float


@dataclass(frozen=True)
class LineSolution:
    """A planned line: its period [s], each station alone and at the period, the phase offsets [s], each
    robot's loop [s] and schedule, the bottleneck, the line's checks."""

    line: Line
    period_s: float
    alone: tuple[Solution, ...]
    at_line: tuple[Solution, ...]
    offsets_s: tuple[float, ...]
    loops_s: tuple[float, ...]
    schedules: tuple[tuple[RobotStretch, ...], ...]
    bottleneck: Bottleneck
    checks: tuple[Check, ...]

    @property
    def spm(self) -> float:
        return 60.0 / self.period_s

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)


def solve_line(line: Line, side_by_side_workers: bool = False) -> LineSolution:
    """The line's fastest verified plan (module docstring); raises a :class:`PlanningError` without one.
    ``side_by_side_workers``: the presses' solves side by side in two forked workers (``planning.solver.ahead``: the
    same plans in about half the time, for one line: ``pressplan line``); else in turn here, where the NLPs they
    build stay for the next line (a line sweep's points, a sweep's forked workers)."""
    solve_each = side_by_side if side_by_side_workers else in_turn
    alone = _alone_all(line.stations, solve_each)
    loops = tuple(robot.loop_s(line.stations) for robot in line.robots)
    bottleneck = _bottleneck(line, alone, loops)
    period_s = bottleneck.period_s
    _check_slow_enough(line, bottleneck)
    pairs = zip(line.stations, alone, strict=True)
    at_line = tuple(solve_each(_at_period, [(station, period_s, fastest) for station, fastest in pairs]))
    starts = [station_starts_s(solution) for solution in at_line]
    offsets = phase_offsets_s(period_s, line.robots, line.stations, starts)
    schedules = tuple(_schedule(robot, line, period_s, offsets, starts) for robot in line.robots)
    checks = _station_checks(line, at_line, period_s) + _robot_checks(line, schedules)
    checks += _inside_checks(line, at_line, offsets, period_s)
    solution = LineSolution(
        line, period_s, alone, at_line, tuple(float(o) for o in offsets), loops, schedules, bottleneck, checks
    )
    failed = [c for c in checks if not c.passed]
    if failed:
        raise LineUnverified(
            f"the line's verification failed: {failed[0].name} ({failed[0].value:.6g} {failed[0].unit})"
        )
    return solution


def station_starts_s(solution: Solution) -> dict[str, float]:
    """A station's robot starts on its own time [s] as the line's master sees them each cycle: a rotary plan's,
    a pendulum plan's in its window at theta_e (``planning.solver.pendulum_line``)."""
    plan = solution.plan
    return line_starts_s(plan) if isinstance(plan, PendulumPlan) else dict(plan.robot_starts_s)


def horizon_s(at_line: tuple[Solution, ...], period_s: float) -> float:
    """The line's repeat [s]: its master cycle, two with a pendulum press (its swings alternate)."""
    swings = any(isinstance(solution.plan, PendulumPlan) for solution in at_line)
    return STROKES_PER_CYCLE * period_s if swings else period_s


def robot_position_mm(station: Station, solution: Solution, role: str, t_s: np.ndarray) -> np.ndarray:
    """``station``'s ``role`` robot's position on its path [mm] at the station's own times ``t_s`` [s] in its plan
    at the line (a pendulum plan's robot in both its windows)."""
    robot, plan = tool(station, role), solution.plan
    if isinstance(plan, PendulumPlan):
        return robot.position_of_starts(t_s, tuple(plan.robot_starts_s[role].values()), plan.period)
    return robot.position(t_s, plan.robot_starts_s[role], plan.period)


def own_period_s(solution: Solution) -> float:
    """The shortest master cycle a station's plan takes: a rotary plan's cycle, a pendulum plan's swings each in
    one master cycle (``planning.solver.pendulum_line.line_period_s``)."""
    plan = solution.plan
    return line_period_s(plan) if isinstance(plan, PendulumPlan) else plan.period


def _check_slow_enough(line: Line, bottleneck: Bottleneck) -> None:
    """:class:`Infeasible` when a rotary station cannot turn as slowly as the line's period asks: its minimum
    crank speed makes a cycle at most ``Case.longest_cycle_s`` long (a turn at it, ``60 / min_crank_speed_rpm``
    [s], without a hold). A pendulum station stands at its turns (``planning.solver.pendulum_line``)."""
    for station in line.stations:
        if station.case.pendulum:
            continue
        slowest = station.case.limits.min_crank_speed_rpm
        longest = station.case.longest_cycle_s
        if bottleneck.period_s > longest:
            raise Infeasible(
                f"the line's cycle {bottleneck.period_s:.4g} s (set by {bottleneck.kind} {bottleneck.name}) is "
                f"longer than station {station.name} can take: at its limits.min_crank_speed_rpm = {slowest:g} a "
                f"cycle takes at most {longest:.4g} s",
                limit=f"{station.name}.limits.min_crank_speed_rpm",
                value=slowest,
            )


_ALONE: dict[str, Solution] = {}  # each case's fastest plan, once per process (a line sweep's points share them)
ALONE_KEPT = 64  # the most kept


def _key(station: Station) -> str:
    return _planned_alone(station).model_dump_json()


def _planned_alone(station: Station) -> Case:
    return station.case.with_objective("max-spm")  # a line plans for its rate: the case's objective not read


def _alone_all(stations: tuple[Station, ...], solve_each: Callable) -> tuple[Solution, ...]:
    """Each station's fastest verified plan, solved once per process for the same case (the first station of a
    case solves it: its name in an error) by ``solve_each`` (:func:`side_by_side` or :func:`in_turn`)."""
    keys = [_key(station) for station in stations]
    known = {key: _ALONE[key] for key in keys if key in _ALONE}  # read before new ones may push them out
    missing: dict[str, Station] = {}
    for key, station in zip(keys, stations, strict=True):
        if key not in known:
            missing.setdefault(key, station)
    solved = dict(zip(missing, solve_each(_alone, [(s,) for s in missing.values()]), strict=True))
    for key, solution in solved.items():  # (kept already where solved here)
        _keep(key, solution)
    return tuple({**known, **solved}[key] for key in keys)


def _keep(key: str, solution: Solution) -> None:
    """``solution`` kept as the fastest plan of the case of ``key`` (the oldest dropped beyond :data:`ALONE_KEPT`)."""
    if key not in _ALONE:
        if len(_ALONE) >= ALONE_KEPT:
            _ALONE.pop(next(iter(_ALONE)))
        _ALONE[key] = solution


def _alone(station: Station) -> Solution:
    """The station's fastest verified plan, kept (:func:`_keep`: by this process, a worker's in its own)."""
    case = _planned_alone(station)
    try:
        solution = fastest_swings(case) if case.pendulum else solve_fastest(case, case.planner.placement)
    except PlanningError as exc:
        raise StationError(station, exc, "alone") from None
    _keep(_key(station), solution)
    return solution


def _at_period(station: Station, period_s: float, fastest: Solution) -> Solution:
    """The station's verified plan at the line's period (a pendulum press: one swing a master cycle)."""
    try:
        if station.case.pendulum:
            return swings_at_period(station.case, period_s, fastest)
        return solve_at_period(station.case, period_s, fastest)
    except PlanningError as exc:
        raise StationError(station, exc, f"at the line's {60 / period_s:.4g} strokes/min") from None


def _bottleneck(line: Line, alone: tuple[Solution, ...], loops: tuple[float, ...]) -> Bottleneck:
    """The longest of the stations' own periods and the robots' loops (a press where they tie)."""
    own = [own_period_s(solution) for solution in alone]
    press = max(range(len(alone)), key=lambda k: own[k])
    robot = max(range(len(loops)), key=lambda j: loops[j])
    if loops[robot] > own[press] + SAME_PERIOD_S:
        return Bottleneck("robot", line.robots[robot].name, loops[robot])
    return Bottleneck("press", line.stations[press].name, own[press])


def _schedule(
    robot: LineRobot, line: Line, period_s: float, offsets: np.ndarray, starts: list[dict[str, float]]
) -> tuple[RobotStretch, ...]:
    """``robot``'s stretches over one master cycle from its first (an unload, or the feeder's load)."""
    names = [s.name for s in line.stations]
    stretches = []

    def add(what: str, start: float, duration: float, station: str | None = None) -> float:
        stretches.append(RobotStretch(what, float(np.mod(start, period_s)), duration, station))
        return start + duration

    if robot.unloads is not None:
        k = robot.unloads
        start = offsets[k] + starts[k]["unloader"]
        end = add(f"unload {names[k]}", start, occupancy_s(line.stations[k], "unloader"), names[k])
    if robot.loads is None:
        end = add("away", end, robot.away_s)
        return (*stretches, RobotStretch("wait", float(np.mod(end, period_s)), start + period_s - end))
    k = robot.loads
    load = offsets[k] + starts[k]["loader"]
    if robot.unloads is None:  # the feeder: its load first
        end = add(f"load {names[k]}", load, occupancy_s(line.stations[k], "loader"), names[k])
        end = add("away", end, robot.away_s)
        return (*stretches, RobotStretch("wait", float(np.mod(end, period_s)), load + period_s - end))
    load = end + np.mod(load - end, period_s)
    end = add("wait", add(f"to {names[k]}", end, robot.away_s), load - end - robot.away_s)
    end = add(f"load {names[k]}", load, occupancy_s(line.stations[k], "loader"), names[k])
    end = add(f"back to {names[robot.unloads]}", end, robot.away_s)
    return (*stretches, RobotStretch("wait", float(np.mod(end, period_s)), start + period_s - end))


def _station_checks(line: Line, at_line: tuple[Solution, ...], period_s: float) -> tuple[Check, ...]:
    """Each station's plan at the line's period: verified (its failed checks, none allowed), its cycle time (a
    pendulum press's two swings two master cycles, each robot's starts in its two windows one apart)."""
    checks = []
    for station, solution in zip(line.stations, at_line, strict=True):
        failed = len(solution.verification.failures())
        checks.append(Check.of("line_station", f"{station.name}: failed checks", failed, 0, "", "max", 0.0))
        swings = isinstance(solution.plan, PendulumPlan)
        cycle = STROKES_PER_CYCLE * period_s if swings else period_s
        name = f"{station.name}: cycle time" + (" (two swings)" if swings else "")
        checks.append(Check.of("line_period", name, solution.plan.period, cycle, "s", "equal", TIME_TOL_S))
        for robot, shift in (shifts_s(solution.plan) if swings else {}).items():
            name = f"{station.name}: {robot}'s start at theta_s after its start at theta_e"
            checks.append(Check.of("line_period", name, shift, period_s, "s", "equal", TIME_TOL_S))
    return tuple(checks)


def _inside_checks(line: Line, at_line: tuple[Solution, ...], offsets_s: np.ndarray, period_s: float) -> tuple:
    """Each transfer robot on the line's master at :data:`INSIDE_STEP_S`, from the presses' plans and offsets
    (not from its schedule): the samples at which it is off its waiting point in both presses it serves
    (none allowed), over two master cycles with a pendulum press."""
    t = np.arange(0.0, horizon_s(at_line, period_s), INSIDE_STEP_S)
    checks = []
    for robot in line.robots:
        if robot.unloads is None or robot.loads is None:
            continue
        inside = []
        for k, role in ((robot.unloads, "unloader"), (robot.loads, "loader")):
            x = robot_position_mm(line.stations[k], at_line[k], role, t - offsets_s[k])
            inside.append(x < tool(line.stations[k], role).path_mm - SAME_POSITION_MM)
        both = int(np.count_nonzero(inside[0] & inside[1]))
        name = f"{robot.name}: samples inside both presses"
        checks.append(Check.of("line_robot", name, both, 0, "", "max", 0.0))
    return tuple(checks)


def _robot_checks(line: Line, schedules: tuple[tuple[RobotStretch, ...], ...]) -> tuple[Check, ...]:
    """Each robot's cycle: its stretches one after the other from its unload (or the feeder's load) to the next,
    one period in all, so each wait (a transfer's at the next press, the last before the next cycle) is at
    least 0: the load at least its transfer time after the unload, the next unload as long after the load.
    The offsets are built so (``planning.model.line``); the check measures the waits from the presses' own
    robot starts and the offsets, and fails where either drifts."""
    checks = []
    for robot, stretches in zip(line.robots, schedules, strict=True):
        for stretch in stretches:
            if stretch.what == "wait":
                name = f"{robot.name}: wait from {stretch.start_s:.4f} s"
                checks.append(Check.of("line_robot", name, stretch.duration_s, 0.0, "s", "min", TIME_TOL_S))
    return tuple(checks)
