"""The bracket: what is possible, between a verified motion and a certified upper bound.

Below: a motion that passes the dense verification against every limit of the case (the optimal law,
``planning.solver.optimal``: no motion law's shape in the way). Above: the certified upper bound
(``planning.solver.upper_bound``), which no motion within the limits can exceed. The fastest possible
cycle lies between them; the gap ``upper / verified - 1`` says how well it is known. Each round refines
the two sides in turn: the verified motion on a layout of more segments (:data:`LAYOUT_FACTORS` times the
first layout's), the upper bound on a grid of more intervals (:data:`UPPER_MESHES`), until the gap is under
the tolerance or the refinements run out, or stall (a side that closed less than :data:`STALL_SHARE` of the
gap is refined no further: the gap is then the relaxation's, e.g. limits it leaves out, or the motion's).
The gap reached is reported, not hidden. With robots the verified side is not refined (their rows tie every
segment of the free profile together: a finer layout's NLP grows with the square of its segments).

A case without a crank-jerk limit allows any jerk: the verified motion is planned under an allowance of
:data:`JERK_ALLOWANCE` times the press's characteristic jerk (speed scale over time scale squared), which
its own verification checks; the case's own limits are verified again on the same plan. A case with an
objective at the line's rate is bracketed for the most strokes. A refinement that finds no plan, or none
that passes, stalls its side (the motion found before stays). A verified motion above the upper bound
(beyond :data:`CROSSED_PCT`) would be a fault, and is raised as one.
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass

from planning.model.case import Case
from planning.model.free_profile import finer, first_layout
from planning.model.laws.optimal import OptimalLaw
from planning.model.profile import max_abs_jerk
from planning.solver.ahead import Ahead
from planning.solver.optimal import on_layout, solve_optimal
from planning.solver.outcomes import NoPlanFound, PlanningError
from planning.solver.solution import Solution
from planning.solver.upper_bound import UpperBound, upper_bound
from planning.solver.verify import evaluate
from planning.tolerances import CROSSED_PCT

BRACKET_TOL_PCT = 0.05  # [%] the gap the bracket refines down to by default
UPPER_MESHES = (1440, 2880, 5760)  # intervals of the upper bound's mesh, coarse to fine (one piece each)
LAYOUT_FACTORS = (6.0, 15.0)  # the verified motion's refinements: this many times the first layout's segments
STALL_SHARE = 0.1  # a refinement that closes less than this share of the gap ends that side's refinements
JERK_ALLOWANCE = 2000.0  # x the press's characteristic jerk: the verified motion's jerk without a case limit


@dataclass(frozen=True)
class BracketRound:
    """One round: the ``verified_spm`` and ``upper_spm`` it reached and their ``gap_pct`` [%]."""

    verified_spm: float
    upper_spm: float
    gap_pct: float


@dataclass(frozen=True)
class Bracket:
    """The fastest possible cycle lies in ``[verified.plan.spm, upper.spm]``: ``verified`` (a plan that passed
    the dense verification against the case's limits), ``upper`` (the certified upper bound), ``gap_pct``
    [%] between them, ``tolerance_pct`` [%] asked, ``met`` whether the gap is within it, ``rounds`` (the
    first computation's result, then each refinement's), ``jerk_allowance_rad_s3`` (the jerk the verified
    motion was allowed when the case sets none, else None), ``wall_time_s`` [s]."""

    verified: Solution
    upper: UpperBound
    gap_pct: float
    tolerance_pct: float
    met: bool
    rounds: tuple[BracketRound, ...]
    jerk_allowance_rad_s3: float | None
    wall_time_s: float

    def as_dict(self) -> dict:
        plan = self.verified.plan
        return {
            "verified_spm": plan.spm,
            "verified_law": plan.motion_law,
            "verified_segments": [[phase, n] for phase, n in plan.parameters.layout],
            "verified_peak_crank_jerk_rad_s3": max_abs_jerk(plan.profile),
            "jerk_allowance_rad_s3": self.jerk_allowance_rad_s3,
            "upper_spm": self.upper.spm,
            "upper_points": self.upper.points,
            "gap_pct": self.gap_pct,
            "tolerance_pct": self.tolerance_pct,
            "met": self.met,
            "rounds": [vars(r) for r in self.rounds],
            "wall_time_s": self.wall_time_s,
        }


def gap_pct(verified_spm: float, upper_spm: float) -> float:
    """The bracket's gap [%]: how much the upper bound lies above the verified motion."""
    return 100.0 * (upper_spm / verified_spm - 1.0)


def jerk_allowance(case: Case) -> float:
    """The crank jerk [rad/s^3] the verified motion may use when the case sets no limit on it:
    :data:`JERK_ALLOWANCE` x w* / t*^2 (w* = sqrt(A / peak |h''|), t* = sqrt(length scale / A))."""
    m, A = case.machine, case.limits.slider_accel_mm_s2
    return JERK_ALLOWANCE * math.sqrt(A / m.peak_curvature) / (m.length_scale / A)


def bracket(case: Case, tolerance_pct: float = BRACKET_TOL_PCT, ahead: Ahead | None = None) -> Bracket:
    """The bracket of ``case`` (module docstring); raises a :class:`PlanningError` when no verified motion
    or no upper bound is found. ``ahead``: the worker that makes the upper bounds (the caller's, which may have
    other calls of its own there, and closes it), else one of the bracket's own."""
    t_start = time.perf_counter()
    allowance = None if case.limits.crank_jerk_rad_s3 is not None else jerk_allowance(case)
    planned = case.with_objective("max-spm")
    if allowance is not None:
        limits = planned.limits.model_copy(update={"crank_jerk_rad_s3": allowance})
        planned = planned.model_copy(update={"limits": limits})
    planned = planned.with_law(OptimalLaw.name)
    fastest = case.with_objective("max-spm")  # the bracket is about the most strokes, whatever the objective
    # each upper bound computed in a worker while the motion is planned (``planning.solver.ahead``): the caller's, or
    # one of the bracket's own, closed here
    with contextlib.nullcontext(ahead) if ahead is not None else Ahead() as worker:
        verified, upper, rounds = _refined(case, planned, fastest, tolerance_pct, worker)
    gap = rounds[-1].gap_pct
    if gap < -CROSSED_PCT:
        raise NoPlanFound(
            f"the verified motion ({verified.plan.spm:.6f} SPM) is above the certified upper bound ({upper.spm:.6f}): "
            "a fault of pressplan's, please report it with the case"
        )
    return Bracket(
        verified,
        upper,
        gap,
        tolerance_pct,
        gap <= tolerance_pct,
        tuple(rounds),
        allowance,
        time.perf_counter() - t_start,
    )


def _refined(
    case: Case, planned: Case, fastest: Case, tolerance_pct: float, ahead: Ahead
) -> tuple[Solution, UpperBound, list[BracketRound]]:
    """The first verified motion and upper bound, then the rounds that refine them (module docstring): the verified
    motion of ``planned`` checked against ``fastest``, the upper bound of ``fastest``. Each upper bound is started
    ``ahead`` as soon as the rounds may need it, and taken when its turn comes: the same numbers, in the time of
    the longer side on two cores."""
    following = ahead.start(upper_bound, fastest, UPPER_MESHES[0], 1)
    verified = _checked(fastest, solve_optimal(planned))
    upper = following.take()
    rounds = [BracketRound(verified.plan.spm, upper.spm, gap_pct(verified.plan.spm, upper.spm))]
    # with robots the verified motion stays on the first layout: their rows tie every segment of the profile
    # (the slide's height at a robot's time sums them all), so a finer layout's NLP grows with its square
    first = first_layout(case.free_draw, case.hold_angle is not None)
    layouts = [finer(first, f) for f in LAYOUT_FACTORS] if case.robots is None else []
    meshes = list(UPPER_MESHES[1:])
    following, turn = None, 0  # following: the bound of meshes[0], once started
    while rounds[-1].gap_pct > tolerance_pct and (layouts or meshes):
        if following is None and meshes:
            following = ahead.start(upper_bound, fastest, meshes[0], 1)
        before = rounds[-1]
        room = STALL_SHARE * (before.upper_spm - before.verified_spm)
        if layouts and (turn % 2 == 0 or not meshes):  # the two sides in turn, the verified motion first
            try:
                verified = _checked(fastest, on_layout(planned, verified, layouts.pop(0)), verified)
            except PlanningError:  # no plan on the finer layout: the side stalls, the motion found stays
                pass
            if verified.plan.spm - before.verified_spm < room:
                layouts.clear()  # the layout does not hold the motion back (or failed): finer ones will not help
        else:
            meshes.pop(0)
            try:  # the meshes are not nested: the lowest upper bound is kept
                upper = min(upper, following.take(), key=lambda u: u.spm)
            except PlanningError:
                pass
            following = None
            if before.upper_spm - upper.spm < room:
                meshes.clear()  # the relaxation, not its mesh, leaves the gap
        turn += 1
        rounds.append(BracketRound(verified.plan.spm, upper.spm, gap_pct(verified.plan.spm, upper.spm)))
    return verified, upper, rounds


def _checked(case: Case, solution: Solution, previous: Solution | None = None) -> Solution:
    """``solution`` verified against ``case``'s own limits (it was planned under the jerk allowance too),
    or ``previous`` when it does not pass."""
    evaluation = evaluate(solution.plan, case)
    verification = evaluation.verification
    if verification.passed:
        return Solution(solution.plan, evaluation)
    if previous is not None:
        return previous
    raise NoPlanFound(
        "the bracket's motion did not pass the verification: " + ", ".join(c.name for c in verification.failures())
    )


__all__ = ["BRACKET_TOL_PCT", "Bracket", "BracketRound", "PlanningError", "bracket", "gap_pct", "jerk_allowance"]
