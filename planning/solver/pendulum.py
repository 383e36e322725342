"""Solve a pendulum stroke: the NLP from several starts, the dense verification, the sampled limits refined.

Before solving, a given draw speed above a swing's draw-speed bound, and a draw the motors cannot make on a swing
at the least draw speed, are refused (``Infeasible``). Each start of :func:`~planning.solver.pendulum_nlp.starts`
is solved; every converged plan is verified densely (``planning.solver.pendulum_check``); the answer is the
verified plan with the most strokes. When none verifies and the failures are of limits the NLP holds at samples
only (the slide's acceleration and speed, the die zone, the motor's torques, the grid's peak, the robots'
clearances), those limits are lowered by their overshoot (the robots' needs raised by their shortfall) and the NLP
(built once, the limits its parameters) solved again, at most :data:`REFINE_ROUNDS` times, each round also starting
from the last round's best plan. Under the optimal law (``planning.solver.pendulum_free``) the one start is the
case's plan under the seven-segment law (the cycloidal where that finds none), and on a press whose two sides of
BDC are one the NLP with the swings tied as mirror images is solved too: the faster verified plan of the two is the
answer. For comparison the same case is solved as a rotary stroke: the gain of the swing is stated beside its plan.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from planning.model.case import Case
from planning.model.limits.capacity import torque_capacity_kNm
from planning.model.limits.grid import drive_chain
from planning.model.pendulum import STROKES_PER_CYCLE, TWO_PI, PendulumPlan, mirror_symmetric, swing_setups
from planning.model.units import RPM, rounded_down
from planning.solver.outcomes import Infeasible, NoPlanFound, PlanningError, Unverified
from planning.solver.pendulum_check import evaluate_pendulum
from planning.solver.pendulum_drive import draw_torque
from planning.solver.pendulum_free import SEED_LAWS, seed_start
from planning.solver.pendulum_nlp import (
    PendulumNLP,
    build,
    elapsed_info,
    free,
    plan_of_values,
    refined,
    sampled_limit_values,
    solve_once,
    starts,
)
from planning.solver.solution import Solution
from planning.tolerances import SAME_RELATIVE
from press.dynamics import envelope_torque

REFINE_ROUNDS = 4  # the NLP solved again with the sampled limits lowered, at most this often


@dataclass(frozen=True)
class PendulumSolution(Solution):
    """A verified pendulum plan: the ``plan``, its ``evaluation``; ``rotary_spm``: the same case as a rotary
    stroke (None when that has no verified plan, ``rotary_reason`` says why); ``at_rate``: a plan at the line's
    rate (``planning.solver.pendulum_rate``), its baseline a pendulum solution too. The drive's figures are a
    cycle's (two strokes); :attr:`energy_kJ` is a stroke's, as a rotary solution's."""

    plan: PendulumPlan
    rotary_spm: float | None = None
    rotary_reason: str = ""

    @property
    def energy_kJ(self) -> float:
        """The supply energy a stroke [kJ]: a cycle's over its two strokes, at the bus with the drive's electrical
        side (its copper and converter losses counted), else at the motors' shaft (as a rotary solution's)."""
        power = self.drive.power
        cycle = power.bus_supply_energy_kJ if power is not None else self.drive.supply_energy_kJ
        return cycle / STROKES_PER_CYCLE

    @property
    def gain(self) -> float | None:
        """Strokes per minute over the rotary stroke's, as a share (0.25: a quarter more)."""
        return None if self.rotary_spm is None else self.plan.spm / self.rotary_spm - 1


def solve_pendulum(case: Case, compare: bool = True) -> PendulumSolution:
    """The verified pendulum plan of ``case`` with the most strokes (module docstring); ``compare``: solve the
    rotary stroke too. Raises :class:`~planning.solver.outcomes.PlanningError` without one."""
    t0 = time.perf_counter()
    _precheck_draw_speed(case)
    if case.drive is not None:
        _precheck_draw_torque(case)
    compiled = build(case)  # once: the sampled limits are its parameters
    seeded, counts = _seeded(case, compiled.names)
    mirrored = free(case) and mirror_symmetric(case.machine)  # the optimal swings tied as mirror images too
    best, errors = None, []
    for nlp in ([build(case, mirror=True)] if mirrored else []) + [compiled]:
        found, error, counts = _refined(case, nlp, seeded, (t0, *counts))
        errors += [error] if error is not None else []
        if found is not None and (best is None or found[0].spm > best[0].spm):
            best = found
    if best is None:  # the untied NLP's reason (the more general problem)
        raise errors[-1]
    return _with_rotary(case, best, t0, counts[1], counts[0], compare)


def _refined(
    case: Case, compiled: PendulumNLP, seeded: list[dict[str, float]], counts: tuple[float, int, int]
) -> tuple[tuple | None, PlanningError | None, tuple[int, int]]:
    """The most strokes among the verified plans of ``compiled`` from its starts (and ``seeded``), the sampled
    limits refined while none verifies (module docstring): ``(plan, evaluation)`` or None with the error that says
    why, and the counts ``(starts tried, iterations)`` carried on from ``counts`` ``(t0, tried, iterations)``."""
    t0, tried, iterations = counts
    limits, previous, failure = sampled_limit_values(case), None, None
    for _ in range(REFINE_ROUNDS + 1):
        nlp = compiled.at(limits)
        x0s = starts(case, nlp) + seeded + ([previous] if previous else [])
        solved, tried, iterations = solved_starts(case, nlp, x0s, (t0, tried, iterations))
        best, best_failed = None, None
        for passed in (True, False):  # the most strokes among the verified plans, and among the failed
            group = [(s.plan, s.evaluation) for s in solved if s.evaluation.verification.passed == passed]
            top = max(group, key=lambda item: item[0].spm, default=None)
            best, best_failed = (top, best_failed) if passed else (best, top)
        if best is not None:
            best, more = _loosened(case, compiled, limits, best)
            return best, None, (tried + int(more > 0), iterations + more)
        if best_failed is None:
            if failure:  # an earlier round's plan failed its check; this round's found none
                break
            return None, NoPlanFound(f"no start of the pendulum NLP converged ({tried} tried)"), (tried, iterations)
        failure = best_failed[1].verification.failures()
        limits = refined(limits, failure)
        previous = best_failed[0].nlp_values
        if limits is None:
            break
    check = failure[0]
    reason = f"{check.name} = {check.value:.6g} {check.unit} (limit {check.limit:.6g})"
    return None, Unverified(reason, check), (tried, iterations)


def _seeded(case: Case, names: tuple[str, ...]) -> tuple[list[dict[str, float]], tuple[int, int]]:
    """The optimal law's start (``planning.solver.pendulum_free``): the case's pendulum plan under the first law of
    :data:`~planning.solver.pendulum_free.SEED_LAWS` that finds one, as the free swings' values, and the starts and
    iterations the seed took; none for a law with halves (its NLP's own starts). :class:`NoPlanFound` naming the
    optimal law when no seed law finds swings."""
    if not free(case):
        return [], (0, 0)
    reasons = []
    for law in SEED_LAWS:
        try:
            seed = solve_pendulum(case.with_law(law), compare=False).plan
        except PlanningError as exc:  # (its starts and iterations are not carried by the error)
            reasons.append(f"{law}: {exc.reason}")
            continue
        return [seed_start(seed, names)], (seed.solver.starts, seed.solver.iterations)
    reason = "; ".join(reasons)
    raise NoPlanFound(f"the optimal law's swings start from a law with halves' swings, and none was found ({reason})")


def solved_starts(
    case: Case, nlp: PendulumNLP, x0s: list[dict[str, float]], counts: tuple[float, int, int]
) -> tuple[list[PendulumSolution], int, int]:
    """Each start of ``nlp`` solved; every converged plan with its dense evaluation (verified or not), in the
    starts' order, and the counts ``(t0, starts tried, iterations)`` carried on (the latter two returned)."""
    t0, tried, iterations = counts
    out = []
    for x0 in x0s:
        values, res = solve_once(case, nlp, x0)
        tried, iterations = tried + 1, iterations + res.iterations
        if values is None:
            continue
        plan = plan_of_values(case, values, elapsed_info(t0, iterations, tried, res.return_status))
        out.append(PendulumSolution(plan, evaluate_pendulum(plan, case)))
    return out, tried, iterations


def _loosened(case: Case, compiled, limits: dict[str, float], best: tuple) -> tuple[tuple, int]:  # noqa: ANN001
    """With a drive: the RMS row (a trapezoid over the samples, which can overstate the exact RMS) loosened once by
    the room the exact one leaves, and the NLP solved again from the best plan; the better verified plan of the
    two, and the iterations spent (``planning.solver.search`` does the same for a rotary plan)."""
    check = best[1].verification.check("motor_rms_torque") if case.drive is not None else None
    if check is None or not 0 < check.value < check.limit:
        return best, 0
    looser = {**limits, "motor_rms_torque": limits["motor_rms_torque"] * check.limit / check.value}
    values, res = solve_once(case, compiled.at(looser), best[0].nlp_values)
    if values is None:
        return best, res.iterations
    plan = plan_of_values(case, values, best[0].solver)
    evaluation = evaluate_pendulum(plan, case)
    better = evaluation.verification.passed and plan.spm > best[0].spm
    return ((plan, evaluation) if better else best), res.iterations


def _precheck_draw_speed(case: Case) -> None:
    """A draw speed the case gives that one swing's draw cannot take, or a swing whose draw allows less than the
    least crank speed (on an asymmetric press the backward swing's draw meets its heights on the other side of
    BDC): refused before solving."""
    given = case.process.draw_speed_rpm
    least = case.limits.min_crank_speed_rpm
    for setup in swing_setups(case, {}):
        bound = setup.draw_speed_bound / RPM
        allows = f"the {rounded_down(bound)} rpm the limits allow in the {setup.name} swing's draw"
        if given is not None and given > bound * (1 + SAME_RELATIVE):
            reason = f"process.draw_speed_rpm = {given:g} is above {allows} (pressplan check prints each swing's)"
            raise Infeasible(reason, "process.draw_speed_rpm", given, bound)
        if least > bound * (1 + SAME_RELATIVE):
            reason = f"limits.min_crank_speed_rpm = {least:g} is above {allows}"
            raise Infeasible(reason, "limits.min_crank_speed_rpm", least, bound)


def _precheck_draw_torque(case: Case) -> None:
    """A draw the motors, the crank or the grid cannot make on one swing even at the least draw speed (the
    forming force's torque on the crank does not fall with the speed; on a link drive the backward swing draws
    where the slide moves fast for the crank, its lever longer; the bus's power at the least speed): refused
    before solving."""
    motor = case.drive.motor
    lowest = max(case.limits.min_crank_speed_rpm, case.process.draw_speed_rpm or 0.0) * RPM
    capacity = torque_capacity_kNm(case)
    for setup in swing_setups(case, {}):
        u, torque, speed, crank = draw_torque(case, setup, lowest)
        envelope = envelope_torque(speed, motor.peak_torque_Nm, motor.base_speed_rpm * RPM)
        uses = [("drive.motor.peak_torque_Nm", np.abs(torque) / envelope, torque, motor.peak_torque_Nm, "N m")]
        if capacity is not None:
            uses.append(
                ("press.capacity.crank_torque_kNm", np.abs(crank) / (1e3 * capacity), crank / 1e3, capacity, "kN m")
            )
        grid = case.drive.grid.peak_power_kW if case.drive.grid is not None else None
        if grid is not None:  # the bus's power is the grid's, but what a storage carries
            bus = drive_chain(torque, torque * speed, case.drive)["bus_power_W"] / 1e3
            if not _storage_carries(case, setup.name, u, bus, lowest):
                uses.append(("drive.grid.peak_power_kW", bus / grid, bus, grid, "kW"))
        for field, use, needed, value, unit in uses:
            k = int(np.argmax(use))
            if use[k] > 1.0:
                angle = math.degrees(u[k] if setup.name == "forward" else TWO_PI - u[k])
                reason = (
                    f"{field} = {value:g} cannot make the {setup.name} swing's draw: at {angle:.1f} deg and "
                    f"{lowest / RPM:.3g} rpm it must give {abs(needed[k]):.0f} {unit}"
                )
                raise Infeasible(reason, field, value, float(abs(needed[k])), angle)


def _storage_carries(case: Case, swing: str, u: np.ndarray, bus_kW: np.ndarray, speed: float) -> bool:
    """Whether the case's storage can carry a swing's draw above the grid limit (its bus power ``bus_kW`` at
    angles ``u`` [rad] at the constant ``speed`` [rad/s]): within the storage's power, and the energy above the
    limit, ``integral (P - L)+ du / w``, within ``eta_s U`` (it cannot start fuller); :class:`Infeasible` naming the
    storage where the draw's excess is more than it holds; False without a storage."""
    d = case.drive
    s = d.storage
    if s is None:
        return False
    excess = np.maximum(bus_kW - d.grid.peak_power_kW, 0.0)
    if s.max_power_kW is not None and float(np.max(excess)) > s.max_power_kW:
        return False
    energy_kJ = float(np.sum(np.diff(u) * (excess[1:] + excess[:-1]) / 2)) / speed
    if energy_kJ <= s.efficiency * s.usable_energy_kJ:
        return True
    reason = (
        f"drive.storage.usable_energy_kJ = {s.usable_energy_kJ:g} cannot carry the {swing} swing's draw above "
        f"drive.grid.peak_power_kW = {d.grid.peak_power_kW:g}: at {speed / RPM:.3g} rpm it draws {energy_kJ:.1f} kJ "
        "above the limit"
    )
    raise Infeasible(reason, "drive.storage.usable_energy_kJ", s.usable_energy_kJ, energy_kJ / s.efficiency)


def _with_rotary(case: Case, best: tuple, t0: float, iterations: int, tried: int, compare: bool) -> PendulumSolution:
    plan, evaluation = best
    plan = replace(plan, solver=elapsed_info(t0, iterations, tried, plan.solver.status))  # the whole solve's
    evaluation = replace(evaluation, samples=replace(evaluation.samples, plan=plan))
    if not compare:
        return PendulumSolution(plan, evaluation)
    from planning.solver.optimize import solve

    rotary = case.model_copy(update={"planner": case.planner.model_copy(update={"mode": "rotary"})})
    try:
        return PendulumSolution(plan, evaluation, rotary_spm=solve(rotary).plan.spm)
    except PlanningError as exc:
        return PendulumSolution(plan, evaluation, rotary_reason=exc.reason)
