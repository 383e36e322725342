"""``solve``: the one entry point of planning, which dispatches a case to the solve its planner asks for.

- ``max-spm`` under a law with halves: ``planning.solver.max_spm`` (the halves NLP, multi-start,
  placements, the drive's probe);
- ``max-spm`` under the optimal law: ``planning.solver.optimal`` (the free profile's NLP);
- an objective at the line's rate: ``planning.solver.objectives``.

Each returns a verified :class:`~planning.solver.solution.Solution` or raises a typed outcome
(``planning.solver.outcomes``).
"""

from __future__ import annotations

from dataclasses import replace

from planning.model.case import Case, Placement
from planning.model.laws import FREE, HALVES, get_law
from planning.model.plan import Plan
from planning.solver.max_spm import from_neighbour, solve_max_spm
from planning.solver.neighbour import plan_of
from planning.solver.objectives import solve_at_rate
from planning.solver.optimal import from_neighbour_optimal, solve_optimal
from planning.solver.outcomes import PlanningError
from planning.solver.solution import Solution
from planning.tolerances import BETTER_SHARE

__all__ = ["Solution", "better", "solve", "solve_from"]


def solve(
    case: Case, placement: Placement | None = None, neighbour: Plan | Solution | None = None, follow: bool = False
) -> Solution:
    """The fastest verified cycle for ``case``; raises a :class:`PlanningError` when there is none.

    One answer per case: the cold solve (its starts and stopping rule as if there were no neighbour),
    or better. ``neighbour``: a plan of a neighbouring case (a sweep's point before, a relaxed limit, the
    page's plan before an edit), or a solution (its evaluation, when made against this case, is not made
    again; ``planning.solver.neighbour``). Its plan, when it holds here, and a start from its values compete with
    the cold solve; the shorter verified cycle wins, so the answer is never worse than the cold solve's
    nor than the neighbour's where the neighbour holds. ``follow``: the neighbour's answer alone when it
    verifies, unconfirmed (fast, but it may be another local optimum than the cold solve's: the web
    page shows it while the confirmed answer is computed). A case whose ``planner.objective`` is not
    ``max-spm`` is solved at its target rate (``planning.solver.objectives.solve_at_rate``; a neighbour
    there starts the search and is not compared with a cold solve).
    """
    if case.planner.objective != "max-spm":
        return solve_at_rate(case, placement, plan_of(neighbour))
    if neighbour is None:
        return _cold(case, placement)
    if follow:  # the neighbour's answer alone, else the cold solve's
        warm = _from_neighbour(case, placement, neighbour)
        return warm if warm is not None else _cold(case, placement)
    # the cold solve first, as if there were no neighbour (its plan the one it finds alone, to round-off); the
    # neighbour's start then takes over what a cold start already refined from the same first optimum
    optima: list = []
    try:
        cold = _cold(case, placement, optima)
    except PlanningError:
        warm = _from_neighbour(case, placement, neighbour, optima)
        if warm is None:
            raise
        return warm
    return better(cold, _from_neighbour(case, placement, neighbour, optima))


def solve_from(case: Case, neighbour: Plan | Solution, placement: Placement | None = None) -> Solution | None:
    """The fast, unconfirmed answer of ``case`` from ``neighbour`` alone (its plan when it holds here, one
    start from its values), or None when neither verifies; raises a :class:`PlanningError` when a
    precheck refuses the case. ``solve(case, neighbour=...)`` confirms it against the cold solve. For
    ``max-spm`` only (an objective at a rate: None)."""
    if case.planner.objective != "max-spm":
        return None
    return _from_neighbour(case, placement, neighbour)


def _cold(case: Case, placement: Placement | None, optima: list | None = None) -> Solution:
    """The cold solve of the case's law's transcription (``optima``: shared with the neighbour's search)."""
    return TRANSCRIPTIONS[get_law(case.planner.motion_law).transcription][0](case, placement, None, optima)


def _from_neighbour(
    case: Case, placement: Placement | None, neighbour: Plan | Solution, optima: list | None = None
) -> Solution | None:
    """The answer from a neighbour alone, by the case's law's transcription."""
    return TRANSCRIPTIONS[get_law(case.planner.motion_law).transcription][1](case, placement, neighbour, optima)


# each transcription's cold solve and its answer from a neighbour, both ``(case, placement, neighbour, optima)``
# (the optimal law's free profile is planned whole, in free placement: it takes no placement, and its searches
# share no optima)
TRANSCRIPTIONS = {
    HALVES: (solve_max_spm, from_neighbour),
    FREE: (
        lambda case, _placement, _neighbour, _optima: solve_optimal(case),
        lambda case, _placement, neighbour, _optima: from_neighbour_optimal(case, neighbour),
    ),
}


def better(cold: Solution, warm: Solution | None) -> Solution:
    """The cold solve's answer unless the neighbour's is shorter; either way with both searches' totals."""
    if warm is None:
        return cold
    best = warm if warm.plan.period < cold.plan.period * (1 - BETTER_SHARE) else cold
    a, b = cold.plan.solver, warm.plan.solver
    totals = replace(
        best.plan.solver,
        iterations=a.iterations + b.iterations,
        starts=a.starts + b.starts,
        wall_time_s=a.wall_time_s + b.wall_time_s,
    )
    return replace(best, plan=replace(best.plan, solver=totals))
