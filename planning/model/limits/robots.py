"""The robots on their interference curves (``robots:``): at every instant the slide is at least as high as
each robot's tool needs it where the tool is (``press.robot``: its fastest moves, its curve).

The model (docs/robots.md): each robot leaves its waiting point at its start ``s`` [s], moves in to the die
centre (its fastest move, ``T_in``), dwells ``T_d`` and moves out (``T_in`` again), once per cycle of period
``P``; the planner decides ``s``. With ``n(t)`` the height its tool needs at time ``t`` (its curve at its
position) and ``h(t)`` the slide's height, the clearance ``c(t) = h(t) - n(t) >= 0`` at every ``t``. Each
robot's dwell at the die centre (the unloader gripping, the loader dropping the blank) lies between the draw's
end (theta3) and the next draw's start (theta2); the loader reaches the die centre once the unloader's tool,
moving out, is clear of the die (``overlapping``), or leaves its waiting point once the unloader is back at its
own (``in-turns``). Each occupancy (in, dwell, out) fits in one period.

In an NLP (a transcription that offers ``height_at`` and the robots' start variables) the clearance is held
at :data:`ROBOT_SAMPLES` times of each occupancy, the curve's crossings among them (where its kinks and its
step are), each need scaled by ``robots_need_factor`` (1 at first; raised by the search when the dense check
finds the clearance lost between the samples). The dense verification checks it at every sample of the plan
and at the crossings' exact times, and each robot's speed and acceleration by differences of its position.

In the time-optimal bound and the certified upper bound (over crank angle, no time of a robot) the robots
enter by what every schedule must give them: for each height ``H`` a tool needs, the slide spends at least as
long at or above ``H`` as the robots need it there (both robots' times added where they cannot overlap),
and the period is at least each occupancy. Necessary conditions only: the bounds stay bounds.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from planning.model.limits.base import (
    BoundMesh,
    Check,
    Dense,
    Impossible,
    Limit,
    Peak,
    Row,
    Transcription,
    sample_vector,
    total,
)
from planning.model.units import RPM
from planning.tolerances import LIMIT_REL_TOL, REFINE_MARGIN, SAME_POSITION_MM, TIME_TOL_S
from press.robot import Robot, crossings, sample_points, time_needing, time_to_clear_s

ROBOT_SAMPLES = 48  # times of each robot's occupancy at which an NLP holds its clearance
ROBOTS = ("unloader", "loader")  # the case's robots (``planning.model.case.ROBOT_NAMES``), in their order
PER_ROBOT = ("occupancy", "in", "dwell", "present")  # [s, s, s, 1|0]


def _robot_parameters() -> tuple[str, ...]:
    names = []
    for r in ROBOTS:
        names += [f"robot_{r}_{part}" for part in PER_ROBOT]
        names += [f"robot_{r}_{kind}_{k}" for k in range(ROBOT_SAMPLES) for kind in ("offset", "need")]
    return (
        *names,
        "robots_order_lead",
        "robots_order_clear",
        "robots_in_turns",
        "robots_order_active",
        "robots_need_factor",
    )


def robots_by_name(case: Any) -> dict[str, Robot]:
    """The case's robots by name."""
    return {robot.name: robot for robot in case.robots_on_path}


def order_terms(case: Any) -> tuple[float, float]:
    """``(lead, clear)`` [s]: the loader's start plus ``lead`` is at least the unloader's plus ``clear``
    (overlapping: the loader reaches the die centre once the unloader's tool, moving out, is clear of the die;
    in turns: the loader leaves its waiting point once the unloader is back at its own)."""
    robots = robots_by_name(case)
    unloader, loader = robots.get("unloader"), robots.get("loader")
    if unloader is None or loader is None:
        return 0.0, 0.0
    if case.robots.order == "in-turns":
        return 0.0, unloader.occupancy_s
    return loader.move.duration_s, unloader.move.duration_s + unloader.dwell_s + time_to_clear_s(unloader)


def least_period_s(case: Any) -> float:
    """The shortest cycle [s] any schedule of the robots allows: each occupancy; in turns both (the loader
    after the unloader, back before the next one leaves); overlapping, the unloader's dwell and clearing and the
    loader's dwell (between theta3 and theta2 of one cycle)."""
    robots = robots_by_name(case)
    longest = max(r.occupancy_s for r in robots.values())
    if len(robots) < 2:
        return longest
    u, ld = robots["unloader"], robots["loader"]
    if case.robots.order == "in-turns":
        return u.occupancy_s + ld.occupancy_s
    return max(longest, u.dwell_s + time_to_clear_s(u) + ld.dwell_s)


def demands(case: Any, draw_speed: float) -> list[tuple[float, tuple[float, str], str, str]]:
    """What any schedule of the robots needs against the longest cycle the minimum crank speed allows, at
    draw speed ``draw_speed`` [rad/s]: ``(need [s], (room [s], what the room is), what is needed, the field to
    change)``: the shortest cycle (:func:`least_period_s`) within the longest; between the draws (from theta3 to
    theta2, the draw itself at ``draw_speed``) the robots' part there (:func:`between_draws_s`)."""
    w_min = case.limits.min_crank_speed_rpm * RPM
    longest = case.longest_cycle_s
    _, th2, th3, _ = case.key_angles
    outside = longest - (th3 - th2) / draw_speed
    field = _slowest_field(case)
    high, level, arc = _highest_demand(case)
    above = f"longest time the slide can stay at or above {level:g} mm (limits.min_crank_speed_rpm)"
    return [
        (least_period_s(case), (longest, "the longest cycle (limits.min_crank_speed_rpm)"), "shortest cycle", field),
        (between_draws_s(case), (outside, "the longest time between the draws"), "time between the draws", field),
        (high, (arc / w_min, above), f"time over a slide at or above {level:g} mm", field),
    ]


ARC_GRID = 7201  # crank angles over a turn on which the arc above a height is measured (a 0.05 deg step)


def _highest_demand(case: Any) -> tuple[float, float, float]:
    """``(time [s], level [mm], arc [rad])``: of the heights the robots' curves name, the one whose time (the
    robots' at or above it, :func:`_time_needing`) is largest against the crank angle over which the slide is
    at or above it (``arc``: the grid's intervals that reach it, never less than the true arc); the slide stays
    there at most ``arc / w_min``."""
    robots = robots_by_name(case)
    theta = np.linspace(0.0, 2 * np.pi, ARC_GRID)
    h = case.machine.height(theta)
    top = np.maximum(h[:-1], h[1:])
    step = theta[1] - theta[0]
    best = (0.0, 0.0, 2 * np.pi)
    for level in levels(robots):
        arc = float(np.count_nonzero(top >= level) * step)
        need = _time_needing(case, robots, level)
        if arc <= 0 or need / arc > best[0] / best[2]:
            best = (need, level, arc)
    return best


def _slowest_field(case: Any) -> str:
    """The field of the robot that takes longest: its dwell where that is most of it, else its speed."""
    robots = robots_by_name(case)
    name = max(robots, key=lambda r: robots[r].occupancy_s)
    robot = robots[name]
    return f"robots.{name}.{'dwell_s' if robot.dwell_s > 2 * robot.move.duration_s else 'speed_mm_s'}"


def between_draws_s(case: Any) -> float:
    """The least time [s] the robots need between theta3 and theta2 of one cycle: each robot's dwell at the
    die centre lies there, and the order between them (in turns: the unloader's dwell and way out, the
    loader's way in and dwell; overlapping: the unloader's dwell and clearing, the loader's dwell); and each
    tool's time over a slide higher than it is anywhere in the draw (it cannot be there in the draw)."""
    robots = robots_by_name(case)
    m = case.machine
    _, th2, th3, _ = case.key_angles
    above_draw = float(max(m.height(th2), m.height(th3))) + SAME_POSITION_MM  # the draw's highest slide
    need = max(max(time_needing(r, above_draw), r.dwell_s) for r in robots.values())
    if len(robots) == 2:
        u, ld = robots["unloader"], robots["loader"]
        if case.robots.order == "in-turns":
            need = max(need, u.dwell_s + u.move.duration_s + ld.move.duration_s + ld.dwell_s)
        else:
            need = max(need, u.dwell_s + time_to_clear_s(u) + ld.dwell_s)
    return need


def span_s(case: Any) -> float:
    """The least time [s] from the first robot leaving its waiting point to the last one back there: the
    robots' share of a cycle (in turns: the occupancies added; overlapping: the unloader in, at the die and
    clear of it, then the loader at the die and out, or the longer occupancy)."""
    robots = robots_by_name(case)
    if len(robots) == 1:
        return next(iter(robots.values())).occupancy_s
    u, ld = robots["unloader"], robots["loader"]
    if case.robots.order == "in-turns":
        return u.occupancy_s + ld.occupancy_s
    lead, clear = order_terms(case)
    return max(u.occupancy_s, ld.occupancy_s, clear - lead + ld.occupancy_s)


class RobotsLimit(Limit):
    """The slide above what each robot's tool needs, at every instant (module docstring)."""

    id = "robots"
    name = "slide above the robots' interference curves"
    unit = "mm"
    field = "robots"
    order = 12
    parameters = _robot_parameters()
    refined = "robots_need_factor"
    refine_upward = True

    def applies(self, case: Any) -> bool:
        return case.robots is not None

    def parameter_values(self, case: Any) -> dict[str, float]:
        robots = robots_by_name(case)
        values: dict[str, float] = {}
        for r in ROBOTS:
            robot = robots.get(r)
            if robot is None:
                values |= {f"robot_{r}_{part}": 0.0 for part in PER_ROBOT}
                offsets = needs = np.zeros(ROBOT_SAMPLES)
            else:
                values |= {
                    f"robot_{r}_occupancy": robot.occupancy_s,
                    f"robot_{r}_in": robot.move.duration_s,
                    f"robot_{r}_dwell": robot.dwell_s,
                    f"robot_{r}_present": 1.0,
                }
                offsets, needs = sample_points(robot, ROBOT_SAMPLES)
            values |= {f"robot_{r}_offset_{k}": float(v) for k, v in enumerate(offsets)}
            values |= {f"robot_{r}_need_{k}": float(v) for k, v in enumerate(needs)}
        lead, clear = order_terms(case)
        both = float(len(robots) == 2)
        turns = float(case.robots.order == "in-turns")
        return values | {
            "robots_order_lead": lead,
            "robots_order_clear": clear,
            "robots_in_turns": turns,
            "robots_order_active": both,
            "robots_need_factor": 1.0,
        }

    def at_draw_speed(self, draw: Any, speed: float) -> list[Check]:
        """The robots' shortest cycle within the longest the minimum crank speed allows, and their time
        between the draws within the longest time outside the draw at ``speed`` [rad/s] (:func:`demands`)."""
        case = draw.case
        out = []
        for need, room, words, _ in demands(case, speed):
            out.append(Check.of(self.id, f"robots' {words} <= {room[1]}", need, room[0], "s", "max", TIME_TOL_S))
        return out

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """:meth:`at_draw_speed`'s conditions at the given draw speed (free: the highest the limits allow)."""
        from planning.model.limits import draw_speed_bounds

        speed = given if given is not None else min(draw_speed_bounds(case).values())
        for need, (room, where), words, field in demands(case, speed):
            if need > room + TIME_TOL_S:
                reason = (
                    f"{field}: the robots' {words} takes {need:.3f} s (robots.order = {case.robots.order}), "
                    f"more than the {room:.3f} s of {where}"
                )
                return Impossible(reason, field, need, room)
        return None

    def rows(self, nlp: Transcription) -> list[Row]:
        if nlp.height_at is None:
            raise ValueError("this transcription cannot state the robots' rows (no height_at)")
        p, out = nlp.param, []
        for r in ROBOTS:
            start, present = nlp.robot_starts[r], p(f"robot_{r}_present")
            offsets = [p(f"robot_{r}_offset_{k}") for k in range(ROBOT_SAMPLES)]
            needs = [p(f"robot_{r}_need_{k}") for k in range(ROBOT_SAMPLES)]
            height = nlp.height_at([start + tau for tau in offsets])
            clearance = (height - sample_vector(needs) * p("robots_need_factor")) / nlp.length_unit
            out.append(Row(f"{r}: slide above its tool", clearance, 0.0, np.inf, sampled=True))
            # at the die centre (its dwell: the unloader gripping, the loader dropping) after theta3 and before
            # theta2 (time 0 is theta3)
            arrives = start + p(f"robot_{r}_in")
            leaves = arrives + p(f"robot_{r}_dwell")
            frame = sample_vector([present * arrives, present * (nlp.draw_start_time - leaves)])
            out.append(Row(f"{r}: at the die between the draws", frame, 0.0, np.inf))
            within = present * (nlp.period - p(f"robot_{r}_occupancy"))
            out.append(Row(f"{r}: in and out within the cycle", within, 0.0, np.inf))
        s_u, s_l = nlp.robot_starts["unloader"], nlp.robot_starts["loader"]
        both, turns = p("robots_order_active"), p("robots_in_turns")
        first = s_l + p("robots_order_lead") - s_u - p("robots_order_clear")
        wrap = s_u + nlp.period - s_l - p("robot_loader_occupancy")  # in turns: back before the next unloader
        out.append(
            Row("the loader after the unloader", sample_vector([both * first, both * turns * wrap]), 0.0, np.inf)
        )
        return out

    def check(self, dense: Dense) -> list[Check]:
        case, plan = dense.case, dense.plan
        missing = [robot.name for robot in case.robots_on_path if robot.name not in plan.robot_starts_s]
        if missing:  # a plan made without these robots (a neighbour's, another case's): no schedule to check
            name = f"{', '.join(missing)}: scheduled in the plan"
            return [Check.of("robots_order", name, float("nan"), 0.0, "s", "min", TIME_TOL_S)]
        k, period = plan.robot_time_scale, plan.period
        within = [within_check(robot, robot.occupancy_s / k, period) for robot in case.robots_on_path]
        if not all(c.passed for c in within):  # a robot longer than the cycle has no periodic schedule
            return within
        out, clearances = [], []
        for robot in case.robots_on_path:
            schedule = robot_schedule(dense, robot)
            clearances.append((clearance_check(dense, schedule), schedule.least_ratio))
            out.append(clearances[-1][0])
            out += path_checks(robot, k)
        return worst_refined(out, clearances) + within + _order_checks(case, plan, dense)

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        """For each height a tool needs: the intervals that reach it take at least the robots' time there;
        the period at least the robots' shortest cycle (:func:`least_period_s`; module docstring). With a
        hold the bounds cut its standstill out of the motion (``planning.solver.bound``): the standstill's
        time counts towards the period and towards every height at or below the hold's, and the crank may
        stop (no interval's time is capped by the least crank speed)."""
        case = mesh.case
        robots = robots_by_name(case)
        top = np.maximum(mesh.h[:-1], mesh.h[1:])  # an interval's highest slide position (h monotone on it)
        stood = case.standstill_s
        rows = [(total(mesh.tau), least_period_s(case) - stood, np.inf)]
        if case.hold_angle is None:
            # the crank never slower than its minimum speed: each interval at most its angle at it (the
            # robots' rows could otherwise stretch a cycle past the longest the limits allow)
            w_min = case.limits.min_crank_speed_rpm * RPM
            rows.append((mesh.tau - mesh.dtheta / w_min, -np.inf, 0.0))
        for level in levels(robots):
            above = np.flatnonzero(top >= level).tolist()
            need = _time_needing(case, robots, level) - (stood if case.hold_height_mm >= level else 0.0)
            if need > 0 and above:  # (a level no node reaches: refused by the case's checks, above the stroke)
                rows.append((total(mesh.tau[above]), need, np.inf))
        return rows

    def relaxed_rows(self, mesh: Any) -> list[tuple[Any, Any, Any]]:
        """The same necessary conditions over the certified mesh (h monotone on each interval)."""
        return self.bound_rows(mesh)


def within_check(robot: Robot, occupancy_s: float, period_s: float, what: str = "in and out") -> Check:
    """The robot in and out within the cycle (its occupancy as it runs, at most the period; ``what`` it does
    in a cycle)."""
    name = f"{robot.name}: {what} within the cycle"
    return Check.of("robots_order", name, occupancy_s, period_s, "s", "max", TIME_TOL_S)


def clearance_check(dense: Dense, schedule: RobotSchedule) -> Check:
    """The slide's height where the robot's tool is closest against what it needs there, located; a tool
    that never needs height has nothing to keep (passes)."""
    check_id = RobotsLimit.id
    if not np.isfinite(schedule.least_clearance_mm):
        return Check.of(check_id, f"{schedule.name}: its tool never needs the slide up", 0.0, 0.0, "mm", "min", 0.0)
    need = schedule.tightest_need_mm
    c = Check.of(
        check_id,
        f"{schedule.name}: slide height where its tool is closest",
        need + schedule.least_clearance_mm,
        need,
        RobotsLimit.unit,
        "min",
        LIMIT_REL_TOL * max(need, 1.0),
    )
    at = schedule.least_at_s
    angle = float(np.degrees(dense.plan.profile.at_time(np.array([at]))[0][0])) % 360.0
    return replace(c, peak=Peak(at, angle, ((at, at),)))


def worst_refined(checks: list[Check], clearances: list[tuple[Check, float]]) -> list[Check]:
    """``checks`` with the worst failed clearance (of ``clearances``: each check with the schedule's least
    height over need) carrying the refinement: the search raises the needs at the NLP's samples once, by that
    shortfall."""
    failed = [(c, ratio) for c, ratio in clearances if not c.passed]
    if not failed:
        return checks
    worst, ratio = min(failed, key=lambda pair: pair[1])
    factor = (1 / max(ratio, 0.5)) * (1 + REFINE_MARGIN) / (1 - REFINE_MARGIN)
    out = list(checks)
    out[out.index(worst)] = replace(worst, refine_by=("robots_need_factor", factor, np.inf))
    return out


def levels(robots: dict[str, Robot]) -> list[float]:
    """The heights the robots' curves name (each a level the bounds hold)."""
    return sorted({float(h) for robot in robots.values() for h in robot.curve.needed_height_mm if h > 0})


def _time_needing(case: Any, robots: dict[str, Robot], level: float) -> float:
    """A lower bound on the time [s] per cycle the slide must be at or above ``level`` [mm] for the robots:
    each robot's own; in turns both added; overlapping, the unloader's way in and dwell and the loader's
    dwell and way out added (those never overlap: the loader is at the die only once the unloader is clear)."""
    own = [time_needing(r, level) for r in robots.values()]
    if len(robots) < 2:
        return max(own)
    u, ld = robots["unloader"], robots["loader"]
    if case.robots.order == "in-turns":
        return sum(own)
    first = time_needing(u, level, (0.0, u.move.duration_s + u.dwell_s + time_to_clear_s(u)))
    last = time_needing(ld, level, (ld.move.duration_s, ld.occupancy_s))
    return max(*own, first + last)


@dataclass(frozen=True)
class RobotSchedule:
    """One robot's moves in a plan, from its dense re-simulation: ``start_s`` [s from TDC] it leaves its
    waiting point; ``events_s``: it leaves, reaches the die centre, leaves it, is back [s from TDC, within the
    period]; ``least_clearance_mm`` at ``least_at_s`` [s from TDC] (the slide's height minus what the tool
    needs, at every dense sample and at the curve's crossings); ``least_ratio`` (the slide's height over the
    need where the tool needs height; 1 where it never does); ``over_die_s`` [s per cycle] the tool needs
    height (inside the die space); ``tightest_need_mm`` what the tool needs where the clearance is least."""

    name: str
    start_s: float
    events_s: tuple[float, float, float, float]
    least_clearance_mm: float
    least_at_s: float
    least_ratio: float
    over_die_s: float
    tightest_need_mm: float


def robot_schedule(dense: Dense, robot: Robot) -> RobotSchedule:
    """The :class:`RobotSchedule` of ``robot`` in the plan of ``dense`` (its moves as planned, run
    ``plan.robot_time_scale`` times as fast: the robot's cam on a master run at that speed)."""
    plan, case = dense.plan, dense.case
    k = plan.robot_time_scale
    period = plan.period
    start = plan.robot_starts_s[robot.name]  # [s of the planned schedule, period k * period]
    offsets, at_points = crossings(robot)  # each with its point's own need (a step's needing side)
    exact = np.mod(start + offsets, k * period) / k
    theta = plan.profile.at_time(exact)[0]
    t = np.concatenate([dense.t, exact])
    h = np.concatenate([dense.h, case.machine.height(np.asarray(theta))])
    need = np.concatenate([robot.needed_height(k * dense.t, start, k * period), at_points])
    needing = need > 0  # where the tool is over the die (elsewhere the slide is free, down to BDC)
    clearance = np.where(needing, h - need, np.inf)
    i = int(np.argmin(clearance))
    ratio = float(np.min(h[needing] / need[needing])) if np.any(needing) else 1.0
    move = robot.move.duration_s
    events = np.mod(start + np.array([0.0, move, move + robot.dwell_s, robot.occupancy_s]), k * period) / k
    over = time_needing(robot, float(np.nextafter(0.0, 1.0))) / k  # any height at all
    return RobotSchedule(
        robot.name, start / k, tuple(events.tolist()), float(clearance[i]), float(t[i]), ratio, over, float(need[i])
    )


PATH_GRID = 4001  # times over an occupancy at which a robot's speed and acceleration are differenced


def path_checks(robot: Robot, scale: float) -> list[Check]:
    """The robot's speed and acceleration along its path run ``scale`` times as fast as planned, by central
    differences of its position on :data:`PATH_GRID` times (exact for its pieces up to cubic; between pieces a
    mean of the two)."""
    t = np.linspace(0.0, robot.occupancy_s, PATH_GRID)
    x = robot.position_since_start(t)
    dt = t[1] - t[0]
    speed = scale * np.max(np.abs(np.diff(x))) / dt
    accel = scale**2 * np.max(np.abs(np.diff(x, 2))) / dt**2
    limits = robot.limits
    return [
        Check.of(
            "robots_path",
            f"{robot.name}: speed along its path",
            speed,
            limits.speed_mm_s,
            "mm/s",
            "max",
            LIMIT_REL_TOL * limits.speed_mm_s,
        ),
        Check.of(
            "robots_path",
            f"{robot.name}: acceleration along its path",
            accel,
            limits.accel_mm_s2,
            "mm/s^2",
            "max",
            LIMIT_REL_TOL * limits.accel_mm_s2,
        ),
    ]


def _order_checks(case: Any, plan: Any, dense: Dense) -> list[Check]:
    """Each robot at the die between the draws; the loader after the unloader (in the order the case says;
    in turns also back before the next unloader leaves). Times from theta3, within the period."""
    period = plan.period
    t3 = float(dense.key_times[2])
    free = float(np.mod(dense.key_times[1] - t3, period))  # theta3 -> theta2: the time outside the draw
    k = plan.robot_time_scale
    arrivals = {
        r.name: since(plan.robot_starts_s[r.name] / k + r.move.duration_s / k, t3, period) for r in case.robots_on_path
    }
    next_unloader = arrivals.get("unloader", 0.0) + period  # the next cycle's
    return window_order_checks(case, arrivals, free, k, ("", next_unloader))


def since(time_s: float, t3_s: float, period_s: float) -> float:
    """[s] from ``t3_s`` to ``time_s`` within the period (a time just before ``t3_s``, to round-off, negative)."""
    rel = float(np.mod(time_s - t3_s, period_s))
    return rel - period_s if rel > period_s - TIME_TOL_S else rel


def window_order_checks(
    case: Any, arrivals: dict[str, float], free_s: float, scale: float, where: tuple[str, float]
) -> list[Check]:
    """The order of the robots between one draw's end (theta3) and the next draw's start (theta2), ``free_s``
    [s] apart: ``arrivals`` each robot's arrival at the die centre [s from theta3, as run], its moves run
    ``scale`` times as fast as planned. Each robot's dwell there (gripping, dropping the blank) between theta3
    and theta2; the loader after the unloader (overlapping: it reaches the die centre once the unloader's tool
    is clear of the die; in turns: it leaves once the unloader is back, and is back before the next unloader
    leaves, which reaches the die centre at ``where[1]`` [s from this theta3]); ``where[0]`` names the window
    in the checks' names (a pendulum cycle's two)."""
    robots = robots_by_name(case)
    k, label = scale, where[0]
    out = []
    for name, robot in robots.items():
        arrives = arrivals[name]
        what = "grips" if name == "unloader" else "drops the blank"
        margin = min(arrives, free_s - (arrives + robot.dwell_s / k))
        name_at = f"{name}{label}: {what} at the die centre after theta3 and leaves it before theta2"
        out.append(Check.of("robots_order", name_at, margin, 0.0, "s", "min", TIME_TOL_S))
    if len(robots) < 2:
        return out
    u, ld = robots["unloader"], robots["loader"]
    grip, reaches = arrivals["unloader"], arrivals["loader"]
    if case.robots.order == "in-turns":
        back = grip + (u.dwell_s + u.move.duration_s) / k  # the unloader at its waiting point again
        leaves = reaches - ld.move.duration_s / k  # the loader leaves its own
        wrap = (where[1] - u.move.duration_s / k) - (reaches + (ld.dwell_s + ld.move.duration_s) / k)
        name = f"the loader{label} back before the next unloader leaves"
        out.append(Check.of("robots_order", name, wrap, 0.0, "s", "min", TIME_TOL_S))
        gap, name = leaves - back, f"the loader{label} leaves after the unloader is back"
    else:
        gap = reaches - (grip + (u.dwell_s + time_to_clear_s(u)) / k)
        name = f"the loader reaches the die{label} once the unloader is clear of it"
    out.append(Check.of("robots_order", name, gap, 0.0, "s", "min", TIME_TOL_S))
    return out
