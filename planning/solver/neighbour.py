"""The one rule for a plan before (a neighbouring case's: a sweep's point before, the page's plan before an
edit, a looser limit): whether it can answer this case, and whether its values can start this case's NLP.

- It **answers** (:func:`can_answer`: a candidate, once its verification against this case passes) when it
  has this case's key angles (to ``SAME_ANGLE_RAD``), its motion law, a placement this case allows (a
  published-structure plan is also a free one) and a draw speed within this case's range (a case that
  gives the draw speed takes no plan at another), and the case's hold at the bottom or none (``Plan.holds_as``).
- It **starts** this case's NLP (:func:`can_start`) when it has the case's law (the NLP's variables are its
  law's), its NLP values, and a placement the case allows; its values start the NLP of its own placement.

Every solve (the laws with halves, the optimal law, the objectives at a rate) asks these two questions
here. A neighbour handed over as a :class:`~planning.solver.solution.Solution` whose evaluation was made
against this very case is not evaluated again (:func:`known_evaluation`).
"""

from __future__ import annotations

import numpy as np

from planning.model.case import Case, Placement
from planning.model.plan import Plan
from planning.solver.solution import Solution
from planning.solver.verify import Evaluation
from planning.tolerances import SAME_ANGLE_RAD, SAME_SPEED_RAD_S


def placement_allows(plan: Plan, placement: Placement) -> bool:
    """Whether a plan of ``plan.placement`` is one of ``placement``'s (free takes both)."""
    return placement == "free" or plan.placement == placement


def can_answer(plan: Plan, case: Case, placement: Placement, draw_speed_range: tuple[float, float]) -> bool:
    """Whether ``plan`` is a candidate answer of ``case`` (module docstring); ``draw_speed_range`` [rad/s]:
    the case's (``planning.solver.precheck``)."""
    lo, hi = draw_speed_range
    w2 = float(plan.parameters.draw_speed)
    same_angles = np.allclose(plan.key_angles, case.key_angles, rtol=0, atol=SAME_ANGLE_RAD)
    in_range = lo - SAME_SPEED_RAD_S <= w2 <= hi + SAME_SPEED_RAD_S
    same_law = plan.motion_law == case.planner.motion_law
    return bool(same_angles and same_law and placement_allows(plan, placement) and in_range and plan.holds_as(case))


def can_start(plan: Plan | None, case: Case, placement: Placement) -> bool:
    """Whether ``plan``'s NLP values can start ``case``'s NLP (module docstring)."""
    if plan is None or not plan.nlp_values:
        return False
    return plan.motion_law == case.planner.motion_law and placement_allows(plan, placement)


def plan_of(neighbour: Plan | Solution | None) -> Plan | None:
    """The plan of a neighbour handed over as a plan or as a solution."""
    return neighbour.plan if isinstance(neighbour, Solution) else neighbour


def known_evaluation(neighbour: Plan | Solution | None, case: Case) -> Evaluation | None:
    """The neighbour's evaluation when it was made against ``case`` itself (a sweep's second pass hands its
    neighbours over verified), else None."""
    if isinstance(neighbour, Solution) and neighbour.evaluation.samples.case == case:
        return neighbour.evaluation
    return None
