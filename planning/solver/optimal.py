"""The optimal law: the fastest jerk-limited cycle, planned as a free profile (``planning.solver.free_nlp``).

Initial guess: a seven-segment plan of the case under the same jerk limit (the first start of its NLP
that converges, neither verified nor confirmed as the optimum: a start needs no more), sampled on the
phases' grids (the bound's profile has no jerk limit and is a poorer start); a neighbouring case's
optimal plan (a sweep, a looser limit) starts first and, when it holds here, is a candidate answer. The
minimum crank speed is held :data:`MIN_SPEED_BACKOFF` above its limit at the samples. The plans are
verified densely like every other. A draw at constant slide speed with a drive is seeded without the drive,
and its NLP is also solved without the motor's rows: that plan is a candidate where the motor can drive it,
and a second start of the drive NLP (the motor's limits only take plans away).

The layout of equal segments per phase (``planning.model.free_profile.PHASES``) cannot follow the arcs
where the slider acceleration sits at its limit when the jerk limit is high (there the optimum's
acceleration follows a curve and its jerk ramps are short): a plan whose peak jerk stays below
:data:`FINE_JERK_SHARE` of the limit is the layout's, not the jerk limit's, and is solved again on the
finer layout (``free_profile.finer``), started from it; the faster verified plan is the answer.
"""

from __future__ import annotations

import numpy as np

from planning.model.case import RPM, Case
from planning.model.cycle import HOLD_SEGMENT
from planning.model.free_profile import PHASES, STAND_SEGMENT, Layout, draws_freely, finer, first_layout, holds
from planning.model.laws.optimal import OptimalLaw
from planning.model.limits import Draw, draw_speed_bounds
from planning.model.plan import Plan
from planning.solver.free_nlp import free_nlp_for
from planning.solver.max_spm import converged_plan, solve_max_spm
from planning.solver.neighbour import can_answer, can_start, known_evaluation, plan_of
from planning.solver.outcomes import Infeasible
from planning.solver.parameters import brake_crossing, structure_values
from planning.solver.search import Search, prepare
from planning.solver.solution import Solution
from planning.solver.verify import evaluate
from planning.tolerances import MIN_SPEED_BACKOFF

SEED_LAW = "seven-segment"  # a jerk-limited law whose plan starts the NLP
FINE_JERK_SHARE = 0.5  # a plan using less than this share of the jerk limit is solved again on the finer layout


def seed_values(seed: Plan, phases: Layout = PHASES, case: Case | None = None) -> dict[str, float]:
    """A plan of another law (or an optimal plan on another layout) as the optimal NLP's values on the
    phases' ``layout``: its profile sampled on each phase's uniform grid between the key points, the jerk of
    each segment from the change of acceleration across it; the robots' starts as they were. With a hold
    (``case``'s, needed then) the brake, the standstill and the return from rest from the seed's own."""
    prof, period = seed.profile, seed.period
    t1, t2, t3, t4 = (float(t) for t in seed.key_times())
    spans = {"return": (t3, t4), "transfer": (t4, t1 + period), "feed": (t1 + period, t2 + period)}
    spans["draw"] = (t2 + period, t3 + period)  # a free draw's phase (a draw at constant slide speed)
    values = {"draw_speed": float(seed.parameters.draw_speed), "die_up_time": seed.nlp_values["die_up_time"]}
    if holds(phases):  # the brake, the standstill, the rise from rest (its die crossing counted from there), the return
        stands, stood = _standstill(seed)
        peak = _first_peak(seed, stood, t4)
        spans |= {"brake": (t3, stands), "stand": (stands, stood), "rise": (stood, peak), "return": (peak, t4)}
        values["die_up_time"] = _rising_through_die(seed, case, stood, t4)
    if draws_freely(phases):  # the speed at theta3 and the acceleration there
        values["draw_speed"], values["draw_accel"] = (float(x) for x in prof.at_time(t3)[1:3])
    braking = case is not None and brake_crossing(case)  # a descending crossing in a hold's brake: from theta3
    if seed.motion_law == OptimalLaw.name or braking:  # (else from theta1 in the free NLP, theta3 in a law's)
        values["die_down_time"] = seed.nlp_values["die_down_time"]
    else:
        values["die_down_time"] = max(seed.nlp_values["die_down_time"] - seed.nlp_values["closing_time"], 0.0)
    for phase, n in phases:
        a, b = spans[phase]
        h = (b - a) / n
        t = a + h * np.arange(n + 1)
        wrapped = t >= period
        th, om, al, _ = prof.at_time(np.where(wrapped, t - period, t))
        th = th + np.where(wrapped | (phase in ("feed", "draw")), 2 * np.pi, 0.0)
        values[f"{phase}_step"] = h
        for k in range(n):
            values[f"{phase}_jerk_{k}"] = float((al[k + 1] - al[k]) / h)
        for k in range(1, n + 1):
            values |= {f"{phase}_angle_{k}": float(th[k]), f"{phase}_speed_{k}": float(om[k])}
            values[f"{phase}_accel_{k}"] = float(al[k])
    for name in ("unloader_start", "loader_start"):  # the robots' starts count from theta3 in both NLPs
        if name in seed.nlp_values:
            values[name] = seed.nlp_values[name]
    return values


def _standstill(plan: Plan) -> tuple[float, float]:
    """``(start, end)`` [s] of a plan's hold standstill (a law's or the optimal law's segment)."""
    names = [seg.name for seg in plan.profile.segments]
    k = next(i for i, name in enumerate(names) if name in (HOLD_SEGMENT, STAND_SEGMENT))
    return float(plan.profile.knot_times[k]), float(plan.profile.knot_times[k + 1])


RISE_SHARE = 0.25  # a seed's rise from rest ends at its speed's peak, at most this share of the way to theta4 (a
# law's half rises monotonically to its peak; the optimum's rise may end early, where the die zone caps the speed)
PEAK_GRID = 400  # points on which a seed's speed peak after its standstill is looked for


def _first_peak(plan: Plan, start: float, end: float) -> float:
    """[s] where ``plan``'s crank speed peaks between ``start`` (rest after a hold) and ``end`` (theta4): a seed's
    rise from rest ends there, at most :data:`RISE_SHARE` of the way."""
    t = np.linspace(start, end, PEAK_GRID)
    speed = plan.profile.at_time(t)[1]
    return float(min(t[int(np.argmax(speed))], start + RISE_SHARE * (end - start)))


def _rising_through_die(plan: Plan, case: Case, start: float, end: float) -> float:
    """[s] from ``start`` to where ``plan``'s slide rises through ``case``'s die height before ``end`` (0: it does
    not, the crossing inactive)."""
    up = structure_values(case)["die_up_angle"]
    theta = plan.profile.at_time(np.array([start, end]))[0]
    if not theta[0] < up < theta[1]:
        return 0.0
    return float(plan.profile.time_at_angle(up)) - start


def seed_case(case: Case) -> Case:
    """The case the seed law plans the start of: ``case`` under :data:`SEED_LAW`; a draw at constant slide
    speed v drawn instead at the constant crank speed at which the slide reaches v where the draw's ``|h'|`` is
    largest (never faster than v; at least the least crank speed, at most the highest the limits allow), and
    without its drive (a start only: a motor that cannot draw at one crank speed may draw at the slide's)."""
    if not case.free_draw:
        return case.with_law(SEED_LAW)
    draw = Draw.of(case)
    speed = case.process.draw_slide_speed_mm_s / float(np.max(np.abs(draw.d1)))
    highest = min(draw_speed_bounds(case).values(), default=speed)
    speed = max(min(speed, highest), case.limits.min_crank_speed_rpm * RPM)
    process = case.process.model_copy(update={"draw_slide_speed_mm_s": None, "draw_speed_rpm": speed / RPM})
    planner = case.planner.model_copy(update={"motion_law": SEED_LAW, "law_parameter": None})
    return case.model_copy(update={"process": process, "planner": planner, "drive": None})


def from_neighbour_optimal(case: Case, neighbour: Plan | Solution) -> Solution | None:
    """The answer from ``neighbour`` alone (its plan when it holds here, one start from its values), or
    None: fast, not confirmed (``planning.solver.optimize.solve``)."""
    _require_jerk_limit(case)
    search = _search(case, _layout_of(plan_of(neighbour), case))
    return search.answer() if _from(search, neighbour) else None


def _layout_of(plan: Plan, case: Case) -> Layout:
    """The phases' layout of an optimal plan that draws as ``case`` does (freely or at a constant crank speed);
    else (a plan of another law, or of the other draw) ``case``'s first layout."""
    layout = getattr(plan.parameters, "layout", None) if plan.motion_law == OptimalLaw.name else None
    if layout is None or draws_freely(layout) != case.free_draw or holds(layout) != (case.hold_angle is not None):
        return _first(case)
    return layout


def _first(case: Case) -> Layout:
    """The first layout of ``case``: its draw free or not, with or without a hold."""
    return first_layout(case.free_draw, case.hold_angle is not None)


def _search(case: Case, phases: Layout | None = None, drive: bool = True) -> Search:
    """The optimal law's search on the phases' ``layout`` (the case's first by default): prechecks, parameters,
    bounds, scales; the minimum crank speed backed off. ``drive`` False: the NLP without the motor's rows (its
    plans verified against the whole case, motor included)."""
    search = prepare(case, "free", free_nlp_for(case, phases or _first(case), drive))
    search.parameters = search.parameters.copy()
    search.parameters[search.parameter("min_crank_speed")] *= 1 + MIN_SPEED_BACKOFF
    return search


def _from(search: Search, neighbour: Plan | Solution) -> bool:
    """A neighbouring case's optimal plan: a candidate when it answers this case and holds here, and a start
    (``planning.solver.neighbour``); whether either verified."""
    case, plan = search.case, plan_of(neighbour)
    layout = getattr(plan.parameters, "layout", PHASES)
    same_draw = draws_freely(layout) == case.free_draw and holds(layout) == (case.hold_angle is not None)
    if not can_start(plan, case, "free") or not same_draw:
        return False
    if can_answer(plan, case, "free", search.draw_speed_range):
        evaluation = known_evaluation(neighbour, case) or evaluate(plan, case)
        if evaluation.verification.passed:  # a neighbouring case's plan that holds here is an answer
            search.consider(Solution(plan, evaluation), plan.period)
    search.attempt(plan.nlp_values, "free")
    return search.best is not None


def _require_jerk_limit(case: Case) -> None:
    if case.limits.crank_jerk_rad_s3 is None:
        raise Infeasible(
            "the optimal law needs limits.crank_jerk_rad_s3 (the jerk it may use)", limit="limits.crank_jerk_rad_s3"
        )


def solve_optimal(case: Case, neighbour: Plan | Solution | None = None) -> Solution:
    """The fastest verified cycle of ``case`` under the optimal law (needs ``limits.crank_jerk_rad_s3``).

    ``neighbour``: an optimal plan of a neighbouring case (a sweep, an edit on the web page, a looser
    limit). When it holds here it is a candidate; its values start the NLP, and when that start verifies
    the seed law is not solved at all (a warm re-solve)."""
    _require_jerk_limit(case)
    spent = (0, 0)  # a neighbour's search that found nothing: its iterations and starts still count
    if neighbour is not None:
        search = _search(case, _layout_of(plan_of(neighbour), case))
        if _from(search, neighbour):
            return _on_the_finer_layout(case, search)
        spent = (search.iterations, search.starts)
    t_start = search.t_start if neighbour is not None else None
    search = _search(case)
    search.t_start = t_start or search.t_start
    search.iterations, search.starts = spent
    seeded = seed_case(case)
    seed = converged_plan(seeded) or solve_max_spm(seeded, "free").plan
    search.iterations += seed.solver.iterations
    search.starts += seed.solver.starts
    start = seed_values(seed, _first(case), case)
    starts = [start] + (_kinematic_candidate(search, start) if case.drive is not None and case.free_draw else [])
    for values in starts:  # each start runs (the better verified plan kept)
        search.multi_start([values], "free", confirm=False)
    return _on_the_finer_layout(case, search)


def _kinematic_candidate(search: Search, start: dict[str, float]) -> list[dict[str, float]]:
    """A draw at constant slide speed with a drive: the optimum of the NLP without the motor's rows from ``start``
    (whose seed law planned the case without its drive), refined and verified against the whole case, motor
    included: a candidate of ``search`` where it passes; returned as a start of the drive NLP (one item; none
    where that NLP found no optimum). The motor's limits only take plans away: where they do not bind, the
    kinematic optimum is the drive problem's too, which the drive NLP's own start may miss (another local
    optimum); where they bind, a start from it may reach a plan the seed's does not."""
    kinematic = _search(search.case, drive=False)
    res = kinematic.nlp.solve(start, kinematic.parameters, kinematic.lbx, kinematic.ubx, "free", kinematic.scale)
    search.iterations += res.iterations
    if not res.success:
        return []
    values = kinematic.nlp.values_of(res)
    kinematic.attempt(values, "free")
    search.iterations += kinematic.iterations
    search.starts += kinematic.starts
    if kinematic.best is not None:
        search.consider(kinematic.best, kinematic.best_score)
    return [values]


def _on_the_finer_layout(case: Case, search: Search) -> Solution:
    """The search's answer, or, where its plan on the first layout uses less than :data:`FINE_JERK_SHARE` of
    the jerk limit (the layout held it back, not the limit), the faster of it and the finer layout's plan
    started from it."""
    answer = search.answer()
    fine_layout = finer(_first(case))
    used = answer.plan.parameters.peak_jerks()[0]
    if _layout_of(answer.plan, case) == fine_layout or used >= FINE_JERK_SHARE * case.limits.crank_jerk_rad_s3:
        return answer
    return on_layout(case, answer, fine_layout, search)


def on_layout(case: Case, answer: Solution, layout: Layout, search: Search | None = None) -> Solution:
    """The faster of ``answer`` (an optimal plan of ``case``) and the plan on the phases' ``layout`` started
    from it (how the finer layout and the bracket, ``planning.solver.bracket``, refine a plan); ``search``:
    the one that found ``answer``, whose time and work count."""
    fine = _search(case, layout)
    fine.consider(answer, answer.plan.period)
    if search is not None:
        fine.iterations, fine.starts, fine.t_start = search.iterations, search.starts, search.t_start
    fine.multi_start([seed_values(answer.plan, layout, case)], "free", confirm=False)
    return fine.answer()
