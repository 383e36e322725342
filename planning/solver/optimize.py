"""``solve``: the one entry point of planning, which dispatches a case to the solve its planner asks for.

- ``max-spm`` under a law with halves: ``planning.solver.max_spm`` (the halves NLP, multi-start,
  placements, the drive's probe);
- ``max-spm`` under the optimal law: ``planning.solver.optimal`` (the free profile's NLP);
- an objective at the line's rate: ``planning.solver.objectives``.

Each returns a verified :class:`~planning.solver.solution.Solution` or raises a typed outcome
(``planning.solver.outcomes``).
"""

from __future__ import annotations

from planning.model.case import Case, Placement
from planning.model.laws import get_law
from planning.model.plan import Plan
from planning.solver.max_spm import solve_max_spm
from planning.solver.objectives import solve_at_rate
from planning.solver.optimal import solve_optimal
from planning.solver.solution import Solution

__all__ = ["Solution", "solve"]


def solve(
    case: Case, placement: Placement | None = None, neighbour: Plan | None = None, follow: bool = False
) -> Solution:
    """The fastest verified cycle for ``case``; raises a :class:`PlanningError` when there is none.

    ``neighbour``: a plan of a neighbouring case (a sweep, a relaxed limit). It is verified against
    this case as it stands (when its placement fits and its key angles and draw speed are this
    case's) and its NLP values start the multi-start, so the answer is never worse than ``neighbour``
    where ``neighbour`` is feasible here. ``follow``: with a fitting ``neighbour``, solve from it alone
    and return what that start finds when it verifies (a sweep following its neighbours); otherwise
    the full multi-start runs. A case whose ``planner.objective`` is not ``max-spm`` is solved at its
    target rate (``planning.solver.objectives.solve_at_rate``).
    """
    if case.planner.objective != "max-spm":
        return solve_at_rate(case, placement, neighbour)
    if get_law(case.planner.motion_law).free_profile:
        return solve_optimal(case, neighbour)
    return solve_max_spm(case, placement, neighbour, follow)
