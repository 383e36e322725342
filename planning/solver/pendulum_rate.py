"""A pendulum stroke at the line's rate: the swings with the least RMS motor torque or supply energy at
``planner.target_spm`` (``planner.objective`` ``min-rms-torque`` or ``min-energy``), beside the baseline it beats.

The fastest swing (``planning.solver.pendulum.solve_pendulum``) is solved first; a target above its strokes is
refused (``Infeasible``, naming the limits that bind there, as for a rotary stroke); at its rate it is the
answer. The **baseline** is what a press does at a lower rate without planning for it: the fastest swings
unchanged, then the crank standing at theta_s, where the cycle starts, for the spare time; checked like any plan
(the answer only where its check passes).
The rate NLP (``planning.solver.pendulum_nlp``, its cycle held at ``120 / target_spm`` s: two strokes a cycle)
weighs the heat (``integral T_m^2 dt``) or the supply energy, normalised by the baseline's figure (the energy
with the heat's :data:`HEAT_TIE_BREAK` share breaking ties, as the rotary rate NLP does). Its starts: the
baseline's values and the NLP's own starts with their standstills lengthened to the rate. Every converged plan
is verified densely; the answer is the verified plan with the least figure
(``planning.solver.solution.objective_value``: the verification's exact RMS or supply energy), the baseline
when none beats it. Where no start verifies, the sampled limits are lowered by their overshoot as in the
max-SPM solve.
"""

from __future__ import annotations

import time
from dataclasses import replace

from planning.model.case import Case
from planning.model.pendulum import STROKES_PER_CYCLE
from planning.solver.objectives import HEAT_TIE_BREAK, PEAK_START_HEADROOM, check_reachable
from planning.solver.outcomes import Unverified
from planning.solver.pendulum import PendulumSolution, solve_pendulum, solved_starts
from planning.solver.pendulum_check import evaluate_pendulum
from planning.solver.pendulum_nlp import (
    PEAK_VARIABLE,
    PendulumNLP,
    build,
    elapsed_info,
    plan_of_values,
    refined,
    sampled_limit_values,
    starts,
)
from planning.solver.solution import AtRate, objective_value
from planning.solver.verify import Evaluation
from planning.tolerances import SAME_PERIOD_S

REFINE_ROUNDS = 4  # the rate NLP solved again with the sampled limits lowered, at most this often


def solve_swings(case: Case, compare: bool = True) -> PendulumSolution:
    """The answer of a pendulum case: at its target rate where ``planner.objective`` weighs the motor
    (:func:`solve_pendulum_at_rate`), else the most strokes (``solve_pendulum``; ``compare``: with the rotary
    stroke beside it)."""
    if case.planner.objective == "max-spm":
        return solve_pendulum(case, compare)
    return solve_pendulum_at_rate(case)


def rate_nlp(case: Case) -> PendulumNLP:
    """The rate NLP of ``case``, built once for every rate and either objective of it (the rate and the weights
    its parameters): kept by the fields the NLP reads (not the case's name, title or source, the target rate or
    which objective), the last :data:`KEPT_RATE_NLPS` only (each holds tens of MB)."""
    peak = case.planner.objective == "min-grid-peak"  # (its NLP has the bus peak's variable and rows)
    kind = "min-grid-peak" if peak else "min-rms-torque"  # any other at a rate
    planner = case.planner.model_copy(update={"objective": kind, "target_spm": None})
    key = case.model_copy(update={"planner": planner}).model_dump_json(exclude={"name", "title", "source"})
    if key not in _RATE_NLPS:
        while len(_RATE_NLPS) >= KEPT_RATE_NLPS:
            _RATE_NLPS.pop(next(iter(_RATE_NLPS)))
        _RATE_NLPS[key] = build(case)
    return _RATE_NLPS[key]


KEPT_RATE_NLPS = 2  # the rate NLPs a process keeps (a trade-off's one case; a page's last edits)
_RATE_NLPS: dict[str, PendulumNLP] = {}


def solve_pendulum_at_rate(case: Case, fastest: PendulumSolution | None = None) -> PendulumSolution:
    """The verified pendulum plan of ``case`` at its target rate with the least objective, with how it compares
    (``at_rate``; module docstring); ``fastest``: the case's fastest swings when the caller has them (a
    trade-off's). Raises a :class:`~planning.solver.outcomes.PlanningError` without one."""
    t0 = time.perf_counter()
    objective, target = case.planner.objective, case.planner.target_spm
    if fastest is None:
        fastest = solve_pendulum(case.with_objective("max-spm"), compare=False)
    check_reachable(target, fastest, case)
    period = STROKES_PER_CYCLE * 60.0 / target
    if abs(fastest.plan.period - period) <= SAME_PERIOD_S:  # at the fastest rate the fastest swings: that one plan
        return replace(fastest, at_rate=AtRate(objective, target, fastest.plan.spm, fastest, False))
    baseline = _baseline(case, fastest, period)
    compiled = rate_nlp(case)
    rate = _weights(baseline.evaluation, objective, period)
    # the baseline answers where no plan beats it, when its own check passes (it may not: see :func:`_baseline`)
    best = baseline if baseline.evaluation.verification.passed else None
    tried, iterations = 0, fastest.plan.solver.iterations
    limits = sampled_limit_values(case)
    for _ in range(REFINE_ROUNDS + 1):
        nlp = compiled.at(limits, rate)
        x0s = _starts(case, nlp, baseline, period)
        found, failed, tried, iterations = _run(case, nlp, x0s, (t0, tried, iterations))
        if found is not None and (best is None or objective_value(found, objective) < objective_value(best, objective)):
            best = found
        if found is not None or failed is None:
            break
        limits = refined(limits, failed.verification.failures())
        if limits is None:
            break
    if best is None:  # neither a plan of the rate NLP nor the baseline verified
        check = baseline.evaluation.verification.failures()[0]
        raise Unverified(f"no plan at the rate meets the limits: {check.name} = {check.value:.6g} {check.unit}", check)
    at_rate = AtRate(objective, target, fastest.plan.spm, baseline, best is not baseline)
    plan = replace(best.plan, solver=elapsed_info(t0, iterations, tried, best.plan.solver.status))
    evaluation = replace(best.evaluation, samples=replace(best.evaluation.samples, plan=plan))
    return replace(best, plan=plan, evaluation=evaluation, at_rate=at_rate)


def _baseline(case: Case, fastest: PendulumSolution, period: float) -> PendulumSolution:
    """The fastest swings, then the crank standing at theta_s (where the cycle starts) for the spare time, as a
    press waits for its next start; checked densely like any plan. Its swings are the fastest plan's, but the
    check's 1 ms grid spans another period, so it samples them elsewhere: where the fastest plan's slide
    acceleration sits at its limit, the baseline can read a few 1e-6 above it (the knuckle joint's read 10000.1
    against 10000). Such a baseline stays the comparison (its failed check said beside it) but is never the
    answer."""
    values = dict(fastest.plan.nlp_values)
    values["turn_start_s"] += max(period - fastest.plan.period, 0.0)
    plan = plan_of_values(case, values, replace(fastest.plan.solver, status="baseline"))
    return PendulumSolution(plan, evaluate_pendulum(plan, case))


def _weights(baseline: Evaluation, objective: str, period: float) -> dict[str, float]:
    """The rate NLP's parameters: the cycle's time and the weights that make the baseline's objective 1."""
    heat_weight = 1.0 / (baseline.drive.rms_motor_torque_Nm**2 * period)
    weights = {"target_period": period, "weight_heat": heat_weight, "weight_energy": 0.0, "weight_peak": 0.0}
    if objective == "min-rms-torque":
        return weights
    if objective == "min-grid-peak":  # the bus's peak [W], the heat breaking ties (as the rotary rate NLP's)
        peak_W = baseline.drive.power.bus_peak_kW * 1e3
        return weights | {"weight_heat": HEAT_TIE_BREAK * heat_weight, "weight_peak": 1.0 / peak_W}
    energy = max(abs(baseline.drive.supply_energy_kJ), baseline.drive.crank_work_abs_kJ) * 1e3
    return weights | {"weight_heat": HEAT_TIE_BREAK * heat_weight, "weight_energy": 1.0 / energy}


def _starts(case: Case, nlp: PendulumNLP, baseline: PendulumSolution, period: float) -> list[dict[str, float]]:
    """The baseline's values, then the NLP's own starts with both standstills lengthened to the rate (with the
    least grid peak the bus peak's variable above the baseline's peak)."""
    out = [dict(baseline.plan.nlp_values)]
    for start in starts(case, nlp):
        extra = 0.5 * max(period - plan_of_values(case, start, baseline.plan.solver).period, 0.0)
        out.append({**start, "turn_end_s": start["turn_end_s"] + extra, "turn_start_s": start["turn_start_s"] + extra})
    if PEAK_VARIABLE in nlp.names:
        top = PEAK_START_HEADROOM * 1e3 * baseline.drive.power.bus_peak_kW
        out = [{**values, PEAK_VARIABLE: top} for values in out]
    return out


def _run(
    case: Case, nlp: PendulumNLP, x0s: list[dict[str, float]], counts: tuple[float, int, int]
) -> tuple[PendulumSolution | None, PendulumSolution | None, int, int]:
    """Each start solved and verified (``planning.solver.pendulum.solved_starts``): the verified plan with the
    least figure, the first plan that failed its check (or None), and the counts of starts and iterations."""
    solved, tried, iterations = solved_starts(case, nlp, x0s, counts)
    verified = [s for s in solved if s.evaluation.verification.passed]
    found = min(verified, key=lambda s: objective_value(s, case.planner.objective), default=None)
    failed = next((s for s in solved if not s.evaluation.verification.passed), None)
    return found, failed, tried, iterations
