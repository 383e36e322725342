"""A pendulum press in a line (``pressplan line`` with a station in ``planner.mode: pendulum``): one swing a
master cycle, its robots on the line's master as a rotary press's.

The line's robots repeat every master cycle ``T`` (a part a cycle): each serves the press once a cycle. A
pendulum press makes one stroke a swing, so at the line it makes one swing a master cycle, its two-swing cycle
``2 T``; its robots' starts in the window at theta_s must then lie exactly ``T`` after their starts in the window
at theta_e (``S_s = S_e + T``), so that every robot sees the press open at the same master time each cycle.

The plan at the line's period keeps the fastest swings (their motion, ``planning.solver.pendulum``) and spends
the spare time ``D = 2 T - P0`` (``P0`` the fastest cycle) standing at the turns: ``da`` more at theta_e, ``D -
da`` more at theta_s. A robot whose window is lengthened so may start later in it: started ``d`` later in a window
whose turn stands ``d' >= d`` longer, its tool meets the slide where it is at least as high as before (the slide
rises to the turn and falls after it, so the later tool sees the rise later, the standstill, or the fall later
by ``d' >= d``). With ``Delta_r`` robot ``r``'s shift ``S_s - S_e`` in the fastest plan, its shift at the line is
``Delta_r + da + d_s - d_e = T`` with ``0 <= d_e <= da``, ``0 <= d_s <= D - da``: possible for any ``da``
exactly when ``0 <= T - Delta_r <= D``, i.e. ``T >= max(Delta_r, P0 - Delta_r)``. So the press's own least line
period (its "alone" for the line's bottleneck) is

    T_k = max(P0 / 2, max_r max(Delta_r, P0 - Delta_r)),

``P0 / 2`` on a symmetric press (the swings mirror images, ``Delta_r = P0 / 2``). The standstills are split so
that the robots' mean ``T - Delta_r`` falls on the turn at theta_e (``da`` = that mean, within ``0 .. D``), each
robot centred in what is left of its range. The plan is then verified like any pendulum plan
(``planning.solver.pendulum_check``), and the line checks the shift (``planning.solver.line``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from planning.model.case import MAX_HOLD_S, Case
from planning.model.pendulum import PendulumPlan
from planning.solver.outcomes import Infeasible, Unverified
from planning.solver.pendulum import PendulumSolution, solve_pendulum
from planning.solver.pendulum_check import evaluate_pendulum
from planning.solver.pendulum_nlp import plan_of_values
from planning.solver.pendulum_robots import WINDOWS, start_variable
from planning.tolerances import SAME_PERIOD_S

FIRST, SECOND = WINDOWS  # the window at theta_e (the line's reference) and the one at theta_s


def fastest_swings(case: Case) -> PendulumSolution:
    """The pendulum press's fastest verified swings (its robots on their curves), as a line's station alone."""
    return solve_pendulum(case.with_objective("max-spm"), compare=False)


def shifts_s(plan: PendulumPlan) -> dict[str, float]:
    """Each robot's start in the window at theta_s minus its start in the window at theta_e [s], within the
    plan's cycle."""
    return {name: float(np.mod(by[SECOND] - by[FIRST], plan.period)) for name, by in plan.robot_starts_s.items()}


def line_period_s(plan: PendulumPlan) -> float:
    """``T_k``: the shortest master cycle at which ``plan``'s swings serve the line's robots once a cycle each
    (module docstring)."""
    cycle = plan.period
    return max([cycle / 2] + [max(shift, cycle - shift) for shift in shifts_s(plan).values()])


def line_starts_s(plan: PendulumPlan) -> dict[str, float]:
    """Each robot's start on the press's own time [s from the forward swing's start] in the window at theta_e:
    the line's robot starts (the other window's lie a master cycle later)."""
    return {name: float(by[FIRST]) for name, by in plan.robot_starts_s.items()}


def swings_at_period(case: Case, period_s: float, fastest: PendulumSolution) -> PendulumSolution:
    """``fastest``'s swings at one swing a master cycle of ``period_s`` [s], standing at the turns for the spare
    time and each robot's starts ``period_s`` apart (module docstring); the plan verified densely.
    :class:`Infeasible` for a master cycle shorter than the swings' own (:func:`line_period_s`) or standing
    longer than ``MAX_HOLD_S`` at a turn; :class:`Unverified` when the plan fails its check (the case's limits at
    the most strokes: a line's station plans for the line's rate, its own objective not read)."""
    case = case.with_objective("max-spm")
    plan = fastest.plan
    least = line_period_s(plan)
    spare = 2 * period_s - plan.period
    if period_s < least - SAME_PERIOD_S:
        raise Infeasible(
            f"a master cycle of {period_s:.4g} s is shorter than the swings serve their robots once a cycle in "
            f"({least:.4g} s)",
            limit=None,
            value=period_s,
        )
    if abs(spare) <= SAME_PERIOD_S:
        return fastest
    spare = max(spare, 0.0)
    gaps = {name: period_s - shift for name, shift in shifts_s(plan).items()}
    at_end = float(np.clip(np.mean(list(gaps.values())), 0.0, spare)) if gaps else spare / 2
    if max(at_end, spare - at_end) > MAX_HOLD_S:
        raise Infeasible(
            f"a master cycle of {period_s:.4g} s stands more than {MAX_HOLD_S:g} s at a turn",
            limit=None,
            value=period_s,
        )
    values = dict(plan.nlp_values)
    values["turn_end_s"] += at_end
    values["turn_start_s"] += spare - at_end
    for name, gap in gaps.items():  # d_s - d_e = gap - da, d_e in [0, da], d_s in [0, D - da]
        change = gap - at_end
        lo, hi = max(0.0, -change), min(at_end, spare - at_end - change)
        later = 0.5 * (lo + hi)
        values[start_variable(name, FIRST)] += later
        values[start_variable(name, SECOND)] += later + change
    at_line = plan_of_values(case, values, replace(plan.solver, status="at the line's period"))
    solution = PendulumSolution(at_line, evaluate_pendulum(at_line, case))
    failed = solution.evaluation.verification.failures()
    if failed:
        check = failed[0]
        raise Unverified(f"{check.name} = {check.value:.6g} {check.unit} (limit {check.limit:.6g})", check)
    return solution
