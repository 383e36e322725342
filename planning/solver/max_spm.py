"""The most strokes under a motion law with halves: prepare, adopt a neighbour, follow it, probe the drive,
multi-start the published placement then the free one, try harder, answer.

``free`` placement starts also from the ``published`` placement's solution, so it is never worse than
that structure, and keeps the best plan that verifies. A case with a drive starts with one probe of the
drive NLP (the first published start): where the motor limits that plan, the drive NLP answers; else
the case is solved without the motor's rows, and that optimum is the answer when the motor can drive it
(the motor's limits only take plans away), else the drive NLP runs.
"""

from __future__ import annotations

from dataclasses import replace

from planning.model.case import Case, Placement
from planning.model.limits import BY_ID
from planning.model.plan import Plan
from planning.solver.halves_nlp import halves_nlp_for
from planning.solver.neighbour import can_answer, can_start, known_evaluation, plan_of
from planning.solver.search import Optimum, Ran, Search, prepare
from planning.solver.solution import Solution
from planning.solver.starts import constant_speed, free_starts, published_starts
from planning.solver.verify import evaluate

MOTOR_LIMITS = frozenset(limit.id for limit in BY_ID.values() if limit.motor)  # the motor's limits


def solve_max_spm(
    case: Case,
    placement: Placement | None = None,
    neighbour: Plan | Solution | None = None,
    optima: list[Optimum] | None = None,
) -> Solution:
    """The fastest verified cycle of ``case`` under its law with halves; ``neighbour``: a plan whose values
    start the multi-start (and which answers when it verifies here and beats the starts). Without a
    neighbour: the cold solve (``planning.solver.optimize.solve`` compares the two). ``optima``: the first
    optima another search of this case reached (``planning.solver.search.Optimum``; shared, added to)."""
    search = prepare(case, placement or case.planner.placement, optima=optima)
    neighbour = adopt(search, neighbour)
    ran: tuple[Ran, ...] = ()
    if case.drive is not None and search.best is None:
        ran = _probe(search, neighbour)
        if _kinematic_first(search, neighbour, ran):
            return search.answer()
    _multi_start(search, neighbour, ran)
    if search.best is None:
        _try_harder(search, neighbour)
    if search.best is None and case.hold_angle is None:  # a hold stops the crank: never one constant speed
        _constant_speed(search)
    return search.answer()


def _probe(search: Search, neighbour: Plan | None) -> tuple[Ran, ...]:
    """A case with a drive: the drive NLP from the first published start, to learn whether the motor
    limits the plan (:func:`_kinematic_first`)."""
    start = published_starts(search.case, search.draw_speed_range[1], neighbour)[0]
    return (Ran(start, search.attempt(start, "published")),)


def _kinematic_first(search: Search, neighbour: Plan | None, ran: tuple[Ran, ...]) -> bool:
    """A case with a drive whose motor did not bind at the ``ran`` probe (or the probe found no plan):
    solve it without the motor's rows (the kinematic NLP, smaller and faster), counting the probe's
    plan. Its optimum is the drive problem's too when the motor can drive it, because the motor's
    limits only take plans away; the dense verification (motor checks included) decides. The first
    converged plan the motor cannot drive ends this search: the drive NLP must answer then (a verified
    kinematic plan found before stays a candidate). Whether this answered the case."""
    if search.best is not None and any(c.id in MOTOR_LIMITS for c in search.best.verification.binding()):
        return False  # the motor limits the probe's plan: the drive NLP answers
    ran = tuple(r for r in ran if r.found is not None)  # a probe that found no plan: its start runs again here
    nlp = halves_nlp_for(search.case, drive=False)
    # its own bounds and scales (the probe's NLP may be the denser variant by now); the probe's work and plan kept
    carried = {k: getattr(search, k) for k in ("t_start", "iterations", "starts", "best", "best_score", "optima")}
    kinematic = replace(prepare(search.case, search.placement, nlp), **carried, stop_on=MOTOR_LIMITS)
    _multi_start(kinematic, neighbour, ran)
    search.iterations, search.starts = kinematic.iterations, kinematic.starts
    search.best, search.best_score = kinematic.best, kinematic.best_score
    return search.best is not None and not kinematic.stopped


def converged_plan(case: Case) -> Plan | None:
    """The plan of the first free-placement start of ``case``'s law (max-SPM) that converges, not verified
    and not refined: a start for another NLP (the optimal law's), far quicker than :func:`solve_max_spm`.
    None when no start converges."""
    search = prepare(case, "free")
    for x0 in free_starts(case, search.draw_speed_range[1], None, None):
        res = search.nlp.solve(x0, search.parameters, search.lbx, search.ubx, "free", search.scale)
        search.iterations += res.iterations
        search.starts += 1
        if res.success:
            return search.plan_of(search.nlp.values_of(res), "free", res.return_status)
    return None


def _multi_start(search: Search, neighbour: Plan | None, ran: tuple[Ran, ...] = ()) -> None:
    """The published placement's starts (but those ``ran`` before; in free placement until one verifies), then
    (free placement) the free starts from that plan."""
    w2 = search.draw_speed_range[1]
    if search.placement != "free":
        search.multi_start(published_starts(search.case, w2, neighbour), "published", ran=ran)
        return
    try:  # the free starts' second (after the published plan) is solved ahead while the published starts run
        if neighbour is None:
            search.begin_ahead(free_starts(search.case, w2, None, None)[0], "free")
        # the free starts confirm their own optimum: one published plan seeds them
        published = search.multi_start(published_starts(search.case, w2, neighbour), "published", False, ran=ran)
        search.multi_start(free_starts(search.case, w2, neighbour, published), "free")
    finally:
        search.stop_ahead()


def _try_harder(search: Search, neighbour: Plan | None) -> None:
    """No start verified: run them all once more with a wider back-off on the limits that have one
    (``Limit.harder_backoff``; the slider acceleration): a plan of that slightly tighter problem meets this
    one's limits."""
    search.parameters = search.parameters.copy()
    for limit in search.nlp.layout.limits:
        if limit.harder_backoff is not None:
            search.parameters[search.parameter(limit.refined)] *= (1 - limit.harder_backoff) / (1 - limit.backoff)
    _multi_start(search, neighbour)


def _constant_speed(search: Search) -> None:
    """No start reached a plan: the crank at one constant speed all round (``planning.solver.starts.
    constant_speed``: a motion of every law with halves, with no jerk at all) is a candidate as it is, where
    it holds (a crank-jerk limit near zero leaves the NLP no room to move from it)."""
    x0 = constant_speed(search.case, search.draw_speed_range[1], 1.0)
    plan = search.plan_of(x0, "published", "constant speed")
    evaluation = evaluate(plan, search.case)
    if evaluation.verification.passed:
        solution = Solution(plan, evaluation)
        search.consider(solution, search.score_of(solution))


def adopt(search: Search, neighbour: Plan | Solution | None) -> Plan | None:
    """A neighbour plan that answers this case (``planning.solver.neighbour``) and verifies here is the
    first answer (its evaluation against this case reused when it was handed over with one); the
    neighbour's plan when its NLP values can start this case's NLP, else None."""
    plan = plan_of(neighbour)
    if plan is None:
        return None
    if can_answer(plan, search.case, search.placement, search.draw_speed_range):
        evaluation = known_evaluation(neighbour, search.case) or evaluate(plan, search.case)
        if evaluation.verification.passed:
            solution = Solution(plan, evaluation)
            search.consider(solution, search.score_of(solution))
    return plan if can_start(plan, search.case, search.placement) else None


def from_neighbour(
    case: Case, placement: Placement | None, neighbour: Plan | Solution, optima: list[Optimum] | None = None
) -> Solution | None:
    """The answer from ``neighbour`` alone: its plan when it holds here, and one start from its values
    (same placement rule); None when neither verifies. Fast, but not confirmed: the cold multi-start may
    find a better optimum (``planning.solver.optimize.solve``). ``optima``: as :func:`solve_max_spm`'s."""
    search = prepare(case, placement or case.planner.placement, optima=optima)
    _follow(search, adopt(search, neighbour))
    return search.answer() if search.best is not None else None


def _follow(search: Search, neighbour: Plan | None) -> bool:
    """Solve from the neighbour's values alone (``neighbour``: a plan :func:`adopt` found able to start this
    case's NLP), in its own placement; whether that verified."""
    if neighbour is None:
        return False
    return search.attempt(neighbour.nlp_values, neighbour.placement) is not None
