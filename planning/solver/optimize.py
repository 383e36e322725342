"""The orchestrator: case -> NLP parameters -> multi-start IPOPT solves -> verified plan.

Initial guesses are built from the case alone (never from published numbers): a transfer speed,
peak speeds near the constant-speed acceleration bound, and half durations that sweep the angles
between the key points (the same for every motion law: each half of every law sweeps
``D (v_start + v_end) / 2``). The NLP is the one of the case's motion law (``planner.motion_law``).
``free`` placement starts also from the ``published`` placement's solution, so it is never worse
than that structure, and keeps the best plan that verifies. A case with a drive starts with one
probe of the drive NLP (the first published start): where the motor limits that plan, the drive NLP
answers; else the case is solved without the motor's rows, and that optimum is the answer when the
motor can drive it (the motor's limits only take plans away), else the drive NLP runs. Without a
verified plan the answer is a typed outcome (``planning.solver.outcomes``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np

from planning.model.case import RPM, Case, Placement, draw_speed_bounds
from planning.model.cycle import HALVES
from planning.model.laws import get_law
from planning.model.laws import improved_scurve as sc
from planning.model.plan import Plan, SolverInfo, params_from_numbers, profile_from_tdc
from planning.solver.ipopt import NLPResult, NLPStatus
from planning.solver.nlp import (
    BLOCK_FIELDS,
    DRIVE_INDEX,
    DRIVE_PARAMETERS,
    FORMING_SAMPLES,
    PARAMETER_INDEX,
    PARAMETERS,
    VARIABLE_INDEX,
    VARIABLES,
    CycleNLP,
    cycle_nlp,
    variable_scales,
)
from planning.solver.outcomes import Attempt, Infeasible, NoPlanFound, Unverified
from planning.solver.verify import BINDING_SHARE, CHECK_FIELDS, CheckId, Verification, verify
from press.dynamics import drive_state, envelope_torque, forming_force

ACCEL_BACKOFF = 5e-4  # the NLP keeps |slider acceleration| <= (1 - backoff) * limit at its samples
RMS_PROOF_MARGIN = 1e-3  # relative: the trapezoidal draw integral of the RMS precheck is far more accurate
DRIVE_BACKOFF = 5e-5  # likewise for the motor's peak and RMS torque (refined like the acceleration if it overshoots)
MIN_HALF_S = 4e-3  # [s] lower bound on the duration of a half (1 ms per improved-S-curve sub-segment)
MAX_TIME_S = 600.0  # [s] least upper bound on a time variable (see _bounds)
REFINEMENTS = 8  # re-solves with a lowered sampled acceleration limit
RMS_ROW_ACTIVE = 1e-6  # the NLP's RMS row (heat over the rating's, 1 at the limit) is active above 1 - this
REFINE_MARGIN = 1e-5  # relative: a refined sampled limit is tightened this much beyond the measured overshoot
HARDER_BACKOFF = 5e-3  # when no start verifies: once more with this back-off on the sampled limits
NO_LIMIT = 1e9  # stands for an absent motor limit in the NLP's parameters
AGREE_S = 1e-6  # [s] two starts whose best periods agree this closely have found the same optimum
POWER_SMOOTHING = 1e-3  # epsilon of the NLP's smooth max(P, 0), as a share of rated torque x base speed


MOTOR_CHECKS = frozenset({CheckId.MOTOR_PEAK, CheckId.MOTOR_SPEED, CheckId.MOTOR_RMS})  # the drive's limits
# the checks whose overshoot between the NLP's samples a re-solve with a lowered sampled limit removes
REFINED = {
    CheckId.SLIDER_ACCEL: PARAMETER_INDEX["accel_limit"],
    CheckId.DIE_SPEED: PARAMETER_INDEX["die_speed"],  # the drive NLP's die-zone rows (see CycleNLP.die_zone_rows)
    CheckId.MIN_CRANK_SPEED: PARAMETER_INDEX["min_crank_speed"],  # the optimal law's sampled speed limits
    CheckId.CRANK_SPEED: PARAMETER_INDEX["crank_speed_max"],
    CheckId.MOTOR_PEAK: DRIVE_INDEX["motor_peak"],
    CheckId.MOTOR_RMS: DRIVE_INDEX["motor_rms"],
}


class Ran(NamedTuple):
    """A start already solved: its ``start`` values and what it ``found`` (verified values and score), or None."""

    start: dict[str, float]
    found: tuple[dict[str, float], float] | None


@dataclass(frozen=True)
class Solution:
    """A verified plan and its verification; ``at_rate``: for an objective at the line's rate, the
    objective's figures and the baseline it beats (``planning.solver.objectives.AtRate``), else None."""

    plan: Plan
    verification: Verification
    at_rate: Any = None


def precheck(case: Case) -> tuple[float, float]:
    """Cheap necessary conditions before any NLP; returns the draw-speed bounds ``(lo, hi)`` [rad/s].

    Raises :class:`Infeasible` naming the limit that makes the case impossible.
    """
    bounds = draw_speed_bounds(case)
    w_min = case.limits.min_crank_speed_rpm * RPM
    th1, _, _, th4 = case.key_angles
    window = th1 + 2 * math.pi - th4
    if window / w_min < case.process.transfer_time_s:
        raise Infeasible(
            f"transfer_time_s = {case.process.transfer_time_s:g} cannot be met: at min_crank_speed_rpm = "
            f"{case.limits.min_crank_speed_rpm:g} the crank crosses the {math.degrees(window):.1f} deg from "
            f"theta4 to theta1 in at most {window / w_min:.3f} s",
            limit="process.transfer_time_s",
            value=case.process.transfer_time_s,
            needed=window / w_min,
        )
    if case.drive is not None:
        _drive_precheck(case, w_min)
    w_given = case.process.draw_speed_rpm
    if w_given is not None:
        w2 = w_given * RPM
        if w2 > bounds["slider_accel"] * (1 + 1e-12):
            a_draw = case.limits.slider_accel_mm_s2 * (w2 / bounds["slider_accel"]) ** 2
            raise Infeasible(
                f"at the draw speed {w_given:g} rpm the slider acceleration in the draw reaches "
                f"{a_draw:.0f} mm/s^2 > slider_accel_mm_s2 = {case.limits.slider_accel_mm_s2:g}",
                limit="limits.slider_accel_mm_s2",
                value=case.limits.slider_accel_mm_s2,
                needed=a_draw,
            )
        return w2, w2
    hi = min(bounds.values())
    if hi < w_min:
        name = min(bounds, key=bounds.get)
        raise Infeasible(
            f"the {name.replace('_', ' ')} limit allows a draw speed of at most {hi / RPM:.3f} rpm, "
            f"below min_crank_speed_rpm = {case.limits.min_crank_speed_rpm:g}",
            limit="limits.min_crank_speed_rpm",
            value=case.limits.min_crank_speed_rpm,
            needed=hi / RPM,
        )
    return w_min, hi


def _drive_precheck(case: Case, w_lowest: float) -> None:
    """Infeasible when the motor cannot make the draw even at the lowest draw speed the case allows (at
    constant speed the draw needs the most torque where the forming force acts on the longest lever)."""
    w2 = case.process.draw_speed_rpm * RPM if case.process.draw_speed_rpm is not None else w_lowest
    _, th2, th3, _ = case.key_angles
    theta = np.linspace(th2, th3, 2001)
    state = drive_state(
        theta,
        np.full_like(theta, w2),
        np.zeros_like(theta),
        case.press.crank_radius_mm,
        case.press.rod_length_mm,
        case.drive_model,
    )
    motor = case.drive.motor
    envelope = envelope_torque(state["motor_speed_rad_s"], motor.peak_torque_Nm, motor.base_speed_rpm * RPM)
    use = np.abs(state["motor_torque_Nm"]) / envelope
    k = int(np.argmax(use))
    if use[k] > 1.0:
        needed = float(abs(state["motor_torque_Nm"][k]))
        raise Infeasible(
            f"drive.motor.peak_torque_Nm = {motor.peak_torque_Nm:g} cannot make the draw: at "
            f"{math.degrees(theta[k]):.1f} deg and {w2 / RPM:.3g} rpm the motors must give {needed:.0f} N m"
            + (f" ({100 * use[k]:.0f} % of the envelope at that speed)" if envelope[k] < motor.peak_torque_Nm else ""),
            limit="drive.motor.peak_torque_Nm",
            value=motor.peak_torque_Nm,
            needed=needed,
            angle_deg=math.degrees(theta[k]),
        )
    if case.process.draw_speed_rpm is None:
        return
    # RMS: the draw alone gives integral T_m^2 dt = integral T_m^2 dtheta / w2, and no cycle is longer than
    # one turn at the minimum crank speed, so RMS^2 >= that integral / (2 pi / w_min)
    sq = state["motor_torque_Nm"] ** 2
    draw_heat = float(np.sum(np.diff(theta) * (sq[1:] + sq[:-1]) / 2)) / w2
    longest = 2 * math.pi / (case.limits.min_crank_speed_rpm * RPM)
    least_rms = math.sqrt(draw_heat / longest)
    if least_rms > motor.rated_torque_Nm * (1 + RMS_PROOF_MARGIN):
        raise Infeasible(
            f"drive.motor.rated_torque_Nm = {motor.rated_torque_Nm:g} cannot be met: the draw alone at "
            f"{w2 / RPM:.3g} rpm gives an RMS torque of at least {least_rms:.0f} N m over the longest cycle "
            f"limits.min_crank_speed_rpm = {case.limits.min_crank_speed_rpm:g} allows ({longest:.1f} s)",
            limit="drive.motor.rated_torque_Nm",
            value=motor.rated_torque_Nm,
            needed=least_rms,
        )


def nlp_parameters(case: Case) -> np.ndarray:
    """The parameter vector of the NLP for ``case`` (inside units)."""
    m = case.machine
    lim = case.limits
    th1, th2, th3, th4 = case.key_angles
    down, up = (float(a) for a in m.angles_at_height(lim.die_height_mm))
    values = {
        "R": case.press.crank_radius_mm,
        "L": case.press.rod_length_mm,
        "theta1": th1,
        "theta2": th2,
        "theta3": th3,
        "theta4": th4,
        "transfer_time": case.process.transfer_time_s,
        "accel_limit": case.limits.slider_accel_mm_s2 * (1 - ACCEL_BACKOFF),
        "die_speed": case.limits.die_speed_mm_s,
        # a crossing inside the draw is covered by the draw-speed bound: its rows are switched off
        "die_down_angle": down,
        "die_down_slope": abs(float(m.derivatives(down)[0])) if down < th2 else 0.0,
        "die_down_active": 1.0 if down < th2 else 0.0,
        "die_up_angle": up,
        "die_up_slope": abs(float(m.derivatives(up)[0])) if up > th3 else 0.0,
        "die_up_active": 1.0 if up > th3 else 0.0,
        "crank_speed_max": crank_speed_limit(case) or NO_LIMIT,
        "crank_accel_max": lim.crank_accel_rad_s2 or NO_LIMIT,
        "crank_jerk_max": lim.crank_jerk_rad_s3 or NO_LIMIT,
        "die_height": lim.die_height_mm,
        "min_crank_speed": lim.min_crank_speed_rpm * RPM,
    }
    out = np.array([values[k] for k in PARAMETERS], dtype=float)
    if case.drive is None:
        return out
    return np.concatenate([out, drive_parameters(case)])


def crank_speed_limit(case: Case) -> float | None:
    """The crank's top speed [rad/s]: the drive's crank-speed limit and the motor's top speed through
    the gear, whichever is lower; None without either."""
    tops = [case.limits.crank_speed_rpm * RPM] if case.limits.crank_speed_rpm is not None else []
    if case.drive is not None:
        tops.append(case.drive.motor.max_speed_rpm * RPM / case.drive.gear_ratio)
    return min(tops) if tops else None


def drive_parameters(case: Case) -> np.ndarray:
    """The drive's NLP parameters (:data:`DRIVE_PARAMETERS`, then the forming force at the draw's samples)."""
    d = case.drive_model
    motor = case.drive.motor
    values = {
        "drive_M": d.M,
        "drive_J0": d.J0,
        "drive_F_cb": d.F_cb,
        "drive_i": d.i,
        "drive_eta": d.eta,
        "drive_J_m": d.J_m,
        "motor_peak": motor.peak_torque_Nm * (1 - DRIVE_BACKOFF),
        "motor_base_speed": motor.base_speed_rpm * RPM,
        "motor_rms": motor.rated_torque_Nm * (1 - DRIVE_BACKOFF),
        # the objective: the period alone (max-SPM); planning.solver.objectives sets the others per solve
        "weight_period": 1.0,
        "weight_heat": 0.0,
        "weight_energy": 0.0,
        "weight_dwell": 0.0,
        "regen": case.drive.regen_efficiency,
        "power_smoothing": POWER_SMOOTHING * motor.rated_torque_Nm * motor.base_speed_rpm * RPM,
        "target_period": 0.0,
    }
    _, th2, th3, _ = case.key_angles
    theta = th2 + np.linspace(0.0, 1.0, FORMING_SAMPLES) * (th3 - th2)
    forming = forming_force(theta, case.machine.height(theta), d)
    return np.concatenate([[values[k] for k in DRIVE_PARAMETERS], forming])


def _guess(case: Case, w2: float, w1: float, peak_share: float, inside: float) -> dict[str, float]:
    """A rough start: S-curves that sweep the key-point angles, peak speeds ``peak_share`` of the
    constant-speed acceleration bound, key points ``inside`` quarters into the halves."""
    law = get_law(case.planner.motion_law)
    R, L = case.press.crank_radius_mm, case.press.rod_length_mm
    th1, th2, th3, th4 = case.key_angles
    w_acc = math.sqrt(case.limits.slider_accel_mm_s2 / (R + R**2 / L))  # |d2h/dtheta2| peaks at BDC
    top = crank_speed_limit(case) or math.inf
    w1 = min(w1, 0.8 * top)
    wm = min(max(peak_share * w_acc, 1.2 * max(w1, w2)), max(0.98 * top, 1.01 * max(w1, w2)))

    def halves(angle: float, w_from: float, w_to: float) -> tuple[float, float]:
        ratio = math.sqrt((wm - w_to) / (wm - w_from))  # one jerk for both halves (Eq. 14)
        D_a = angle / ((w_from + wm) / 2 + ratio * (wm + w_to) / 2)  # a symmetric half sweeps D (v0 + v1) / 2
        return D_a, ratio * D_a

    D_fa, D_fd = halves(th2 - th1, w1, w2)
    D_ra, D_rd = halves(th4 - th3, w2, w1)
    T_c = (th1 + 2 * math.pi - th4) / w1
    share = inside / sc.SUBSEGMENTS
    t4 = D_ra + (1 - share) * D_rd
    t1 = D_ra + D_rd + T_c + share * D_fa
    t_feed_end = t1 - share * D_fa + D_fa + D_fd
    return {
        "transfer_speed": w1,
        "draw_speed": w2,
        "feed_peak_speed": wm,
        "return_peak_speed": wm,
        "feed_accel_duration": D_fa,
        "feed_decel_duration": D_fd,
        "return_accel_duration": D_ra,
        "return_decel_duration": D_rd,
        "transfer_dwell": T_c,
        "law_parameter": law.parameter.start if law.parameter else 0.0,
        "closing_time": t1,
        "opening_time": t4,
        "die_down_time": 0.5 * (t1 + t_feed_end),
        "die_up_time": 0.5 * t4,
    }


def _bounds(case: Case, w2_lo: float, w2_hi: float, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    w_min = case.limits.min_crank_speed_rpm * RPM
    # every time of a cycle lies within one period, and the crank never turns slower than w_min: the
    # period is at most 2 pi / w_min. The bound scales with the case; 600 s keeps the usual cases' numerics.
    lo = np.zeros(len(VARIABLES))
    hi = np.full(len(VARIABLES), max(MAX_TIME_S, 1.01 * 2 * math.pi / w_min))
    i = VARIABLE_INDEX
    lo[i["transfer_speed"]], hi[i["transfer_speed"]] = w_min, 1e3
    lo[i["draw_speed"]], hi[i["draw_speed"]] = w2_lo, w2_hi
    for k in ("feed_peak_speed", "return_peak_speed"):
        lo[i[k]], hi[i[k]] = w_min, 1e3
    for k in HALVES:
        lo[i[f"{k}_duration"]] = MIN_HALF_S
    law = get_law(case.planner.motion_law)
    fixed = case.planner.law_parameter
    if law.parameter is None:
        lo[i["law_parameter"]] = hi[i["law_parameter"]] = 0.0
    elif fixed is not None:
        lo[i["law_parameter"]] = hi[i["law_parameter"]] = fixed
    else:
        lo[i["law_parameter"]], hi[i["law_parameter"]] = law.parameter.low, law.parameter.high
    for k in ("die_down", "die_up"):
        if p[PARAMETER_INDEX[f"{k}_active"]] == 0.0:
            lo[i[f"{k}_time"]] = hi[i[f"{k}_time"]] = 0.0
    return lo, hi


def _plan(case: Case, values: dict[str, float], placement: Placement, info: SolverInfo) -> Plan:
    th = case.key_angles
    law = case.planner.motion_law
    params = params_from_numbers(values, float(th[1]), float(th[2]), law)
    profile = profile_from_tdc(params)
    plan = Plan(params, profile, tuple(float(a) for a in th), placement, info, motion_law=law)
    t = plan.key_times()
    structure = {"closing": plan.segment_at(float(t[0])), "opening": plan.segment_at(float(t[3]))}
    return replace(plan, structure=structure, nlp_values=dict(values))


def _fits(plan: Plan, case: Case, placement: Placement, w2_lo: float, w2_hi: float) -> bool:
    """Whether ``plan`` is a candidate answer for ``case``: same placement rule (a published-structure
    plan is also a free one), same key angles, a draw speed within this case's bounds."""
    same_angles = np.allclose(plan.key_angles, case.key_angles, rtol=0, atol=1e-12)
    w2 = float(plan.parameters.draw_speed)
    fits_placement = placement == "free" or plan.placement == "published"
    same_law = plan.motion_law == case.planner.motion_law
    return bool(same_angles and same_law and fits_placement and w2_lo - 1e-12 <= w2 <= w2_hi + 1e-12)


@dataclass
class _Search:
    """The state of one :func:`solve`: the case and its compiled NLP, the variable bounds and scales,
    the best verified plan so far, and the totals the answer reports."""

    case: Case
    placement: Placement
    nlp: CycleNLP
    parameters: np.ndarray  # of the case, :data:`PARAMETERS` order
    lbx: np.ndarray
    ubx: np.ndarray
    scale: np.ndarray
    draw_speed_range: tuple[float, float]  # [rad/s]
    t_start: float
    best: Solution | None = None
    attempts: list[Attempt] = field(default_factory=list)
    iterations: int = 0
    starts: int = 0
    fixed_period: bool = False  # the cycle time held at the parameter target_period (a target rate)
    score: Callable[[Plan], float] | None = None  # what "better" means, lower is better; None: the period
    make_plan: Callable[..., Plan] | None = None  # values -> Plan (None: a plan of the case's law's cycle)
    best_score: float = math.inf
    stop_on: frozenset[CheckId] = frozenset()  # a converged plan failing one of these checks ends the search
    stopped: bool = False  # it did

    def score_of(self, plan: Plan) -> float:
        """The plan's score: :attr:`score`, or its period [s]."""
        return plan.period if self.score is None else self.score(plan)

    def attempt(self, x0: dict[str, float], placement: Placement) -> tuple[dict[str, float], float] | None:
        """Solve from ``x0``; where only sampled limits fail the dense check (the slider acceleration, the
        motor's peak and RMS torque, ...: :data:`REFINED`), lower the NLP's sampled limit by the measured
        overshoot and re-solve warm (at most ``REFINEMENTS`` times). Where the NLP's RMS row is active but
        the exact RMS torque stays more than :data:`BINDING_SHARE` below the rating (its trapezoid over the
        samples overestimates the heat), raise that row's limit by the measured gap once and re-solve warm
        (:meth:`_rms_gap`). Returns the best verified values and score, or None."""
        q = self.parameters.copy()
        values = x0
        multipliers = None
        found: tuple[dict[str, float], float] | None = None
        loosened = False
        self.starts += 1
        for _ in range(REFINEMENTS + 2):
            res = self.nlp.solve(values, q, self.lbx, self.ubx, placement, self.scale, multipliers, self.fixed_period)
            self.iterations += res.iterations
            if self.fixed_period and res.status == NLPStatus.STOPPED_AT_LIMIT:
                # at a target rate the optimum may sit where a half of the law degenerates (a monotone speed
                # change: peak = end speed); IPOPT then crawls, and a fresh start from its last iterate ends it
                res = self.nlp.solve(self.nlp.values_of(res), q, self.lbx, self.ubx, placement, self.scale, None, True)
                self.iterations += res.iterations
            values, multipliers = self.nlp.values_of(res), res.multipliers
            if not res.success:
                block, amount = self.nlp.worst_violation(placement, res.g, self.fixed_period)
                field = BLOCK_FIELDS[block]
                self.attempts.append(Attempt(res.return_status, block, amount, case_field=field))
                return found
            info = SolverInfo(self.iterations, time.perf_counter() - self.t_start, self.starts, res.return_status)
            plan = (self.make_plan or _plan)(self.case, values, placement, info)
            check = verify(plan, self.case)
            if check.passed:
                score = self.score_of(plan)
                self.consider(Solution(plan, check), score)
                if found is None or score < found[1]:
                    found = (values, score)
                gap = None if loosened else self._rms_gap(res, check)
                if gap is None:
                    return found
                q[DRIVE_INDEX["motor_rms"]] *= gap * (1 - REFINE_MARGIN)
                loosened = True
                continue
            bad = check.failures()
            self.attempts.append(Attempt(check=bad[0], case_field=CHECK_FIELDS.get(bad[0].id, "")))
            if any(c.id in self.stop_on for c in bad):
                self.stopped = True
                return found
            refinable = {cid: k for cid, k in REFINED.items() if k < q.size}  # the NLP's own limits
            if self.nlp.die_zone_rows is None:  # the kinematic NLP holds the die speed at the crossings only
                refinable.pop(CheckId.DIE_SPEED)
            if not self.nlp.sampled_speed_limits:  # the laws' halves are monotone: their end and peak speeds hold them
                refinable.pop(CheckId.MIN_CRANK_SPEED)
                refinable.pop(CheckId.CRANK_SPEED)
            if any(c.id not in refinable for c in bad):
                return found
            for c in bad:  # tighten the NLP's sampled limit by the measured overshoot
                if c.kind == "min":  # a lower limit (the optimal law's minimum crank speed) goes up
                    q[refinable[c.id]] *= (c.limit / max(c.value, 0.5 * c.limit)) * (1 + REFINE_MARGIN)
                else:
                    q[refinable[c.id]] *= (c.limit / c.value) * (1 - REFINE_MARGIN)
        return found

    def _rms_gap(self, res: NLPResult, check: Verification) -> float | None:
        """``rated / exact RMS torque`` when the NLP's RMS row is active at ``res`` and the exact RMS torque of
        the verified plan is more than :data:`BINDING_SHARE` below the rating; else None."""
        block = next((b for b in self.nlp.blocks if b.name == "motor RMS torque"), None)
        if block is None or res.g[block.start] < 1 - RMS_ROW_ACTIVE:
            return None
        rms = next(c for c in check.checks if c.id == CheckId.MOTOR_RMS)
        return rms.limit / rms.value if rms.margin > BINDING_SHARE * rms.limit else None

    def key(self, values: dict[str, float]) -> np.ndarray:
        """``values`` as the NLP's variable vector (to compare starts)."""
        return np.array([values[k] for k, _ in self.nlp.variables])

    def consider(self, solution: Solution, score: float) -> None:
        """Keep ``solution`` (verified) when its ``score`` beats the best so far."""
        if self.best is None or score < self.best_score - 1e-9:
            self.best, self.best_score = solution, score

    def multi_start(
        self, x0s: list[dict[str, float]], placement: Placement, confirm: bool = True, ran: tuple[Ran, ...] = ()
    ) -> dict[str, float] | None:
        """Run the starts in order until the two best verified ones agree on the score (the optimum
        is confirmed; ``confirm`` False: until one verifies) or the starts run out; the values of the
        best verified start. ``ran``: starts of this placement already solved (the drive's probe): they
        are not run again, and what they found counts."""
        found = sorted((r.found for r in ran if r.found is not None), key=lambda item: item[1])
        tried = [self.key(r.start) for r in ran]
        for x0 in x0s:
            if self.stopped:
                break
            key = self.key(x0)
            if any(np.allclose(key, other, rtol=1e-9, atol=1e-12) for other in tried):
                continue  # the same start again would only repeat its answer
            tried.append(key)
            out = self.attempt(x0, placement)
            if out is None:
                continue
            found.append(out)
            found.sort(key=lambda item: item[1])
            if not confirm or (len(found) >= 2 and found[1][1] - found[0][1] <= AGREE_S):
                break
        return found[0][0] if found else None

    def answer(self) -> Solution:
        """The best verified plan with the solver's totals; else the typed error: a converged plan
        that failed the dense check is the finding (:class:`Unverified`), otherwise :class:`NoPlanFound`."""
        if self.best is None:
            found = [a for a in self.attempts if a.check is not None]
            if found:
                raise Unverified("no plan meets the limits: " + found[0].describe(), found[0].check)
            last = self.attempts[-1].describe() if self.attempts else "no start"
            raise NoPlanFound(
                f"the solver found none from {self.starts} starts, which does not prove the limits "
                f"cannot be met; last: {last}",
                tuple(self.attempts),
            )
        plan = self.best.plan
        if self.placement == "free" and plan.placement == "published":
            # the published structure is one of the free structures: report it as the free answer
            plan = replace(plan, placement="free")
        info = SolverInfo(self.iterations, time.perf_counter() - self.t_start, self.starts, plan.solver.status)
        return Solution(replace(plan, solver=info), self.best.verification)


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
        from planning.solver.objectives import solve_at_rate

        return solve_at_rate(case, placement, neighbour)
    if get_law(case.planner.motion_law).free_profile:
        from planning.solver.optimal import solve_optimal

        return solve_optimal(case, neighbour)
    search = _prepare(case, placement or case.planner.placement)
    neighbour = _adopt(search, neighbour)
    if follow and _follow(search, neighbour):
        return search.answer()
    ran: tuple[Ran, ...] = ()
    if case.drive is not None and search.best is None:
        ran = _probe(search, neighbour)
        if _kinematic_first(search, neighbour, ran):
            return search.answer()
    _multi_start(search, neighbour, ran)
    if search.best is None:
        _try_harder(search, neighbour)
    return search.answer()


def _probe(search: _Search, neighbour: Plan | None) -> tuple[Ran, ...]:
    """A case with a drive: the drive NLP from the first published start, to learn whether the motor
    limits the plan (:func:`_kinematic_first`)."""
    start = _published_starts(search, neighbour)[0]
    return (Ran(start, search.attempt(start, "published")),)


def _kinematic_first(search: _Search, neighbour: Plan | None, ran: tuple[Ran, ...]) -> bool:
    """A case with a drive whose motor did not bind at the ``ran`` probe (or the probe found no plan):
    solve it without the motor's rows (the kinematic NLP, smaller and faster), counting the probe's
    plan. Its optimum is the drive problem's too when the motor can drive it, because the motor's
    limits only take plans away; the dense verification (motor checks included) decides. The first
    converged plan the motor cannot drive ends this search: the drive NLP must answer then (a verified
    kinematic plan found before stays a candidate). Whether this answered the case."""
    if search.best is not None and any(c.id in MOTOR_CHECKS for c in search.best.verification.binding()):
        return False  # the motor limits the probe's plan: the drive NLP answers
    ran = tuple(r for r in ran if r.found is not None)  # a probe that found no plan: its start runs again here
    law = search.case.planner.motion_law
    kinematic = replace(
        search,
        nlp=cycle_nlp(law, False),
        parameters=search.parameters[: len(PARAMETERS)],
        attempts=[],
        stop_on=MOTOR_CHECKS,
    )
    _multi_start(kinematic, neighbour, ran)
    search.iterations, search.starts = kinematic.iterations, kinematic.starts
    search.best, search.best_score = kinematic.best, kinematic.best_score
    return search.best is not None and not kinematic.stopped


def converged_plan(case: Case) -> Plan | None:
    """The plan of the first free-placement start of ``case``'s law (max-SPM) that converges, not verified
    and not refined: a start for another NLP (the optimal law's), far quicker than :func:`solve`. None
    when no start converges."""
    search = _prepare(case, "free")
    for x0 in _free_starts(search, None, None):
        res = search.nlp.solve(x0, search.parameters, search.lbx, search.ubx, "free", search.scale)
        search.iterations += res.iterations
        search.starts += 1
        if res.success:
            info = SolverInfo(search.iterations, time.perf_counter() - search.t_start, search.starts, res.return_status)
            return _plan(case, search.nlp.values_of(res), "free", info)
    return None


def _multi_start(search: _Search, neighbour: Plan | None, ran: tuple[Ran, ...] = ()) -> None:
    """The published placement's starts (but those ``ran`` before), then (free placement) the free starts
    from its best plan."""
    published = search.multi_start(_published_starts(search, neighbour), "published", ran=ran)
    if search.placement == "free":
        search.multi_start(_free_starts(search, neighbour, published), "free")


def _try_harder(search: _Search, neighbour: Plan | None) -> None:
    """No start verified: run them all once more with a wider back-off on the sampled slider
    acceleration (a plan of that slightly tighter problem meets this one's limits)."""
    index = PARAMETER_INDEX["accel_limit"]
    search.parameters = search.parameters.copy()
    search.parameters[index] *= (1 - HARDER_BACKOFF) / (1 - ACCEL_BACKOFF)
    _multi_start(search, neighbour)


def _prepare(case: Case, placement: Placement, nlp: CycleNLP | None = None) -> _Search:
    """Prechecks, the case's parameters, the variable bounds and scales, the compiled NLP: ``nlp``, or by
    default the case's law's (with the motor's rows when it has a drive)."""
    t_start = time.perf_counter()
    w2_lo, w2_hi = precheck(case)
    p = nlp_parameters(case)
    lbx, ubx = _bounds(case, w2_lo, w2_hi, p)
    lim = case.limits
    scale = variable_scales(case.press.crank_radius_mm, case.press.rod_length_mm, lim.slider_accel_mm_s2)
    nlp = nlp or cycle_nlp(case.planner.motion_law, case.drive is not None)
    return _Search(case, placement, nlp, p, lbx, ubx, scale, (w2_lo, w2_hi), t_start)


def _adopt(search: _Search, neighbour: Plan | None) -> Plan | None:
    """A neighbour plan that fits and verifies here is the first answer; the neighbour when its NLP
    values can start this case's NLP (same law), else None."""
    if neighbour is None:
        return None
    if _fits(neighbour, search.case, search.placement, *search.draw_speed_range):
        check = verify(neighbour, search.case)
        if check.passed:
            search.consider(Solution(neighbour, check), search.score_of(neighbour))
    if neighbour.motion_law != search.case.planner.motion_law or not neighbour.nlp_values:
        return None  # another law's plan neither answers this case nor starts its NLP
    return neighbour


def _follow(search: _Search, neighbour: Plan | None) -> bool:
    """Solve from the neighbour's values alone (same placement rule); whether that verified."""
    if neighbour is None or not (neighbour.placement == search.placement or search.placement == "free"):
        return False
    return search.attempt(neighbour.nlp_values, neighbour.placement) is not None


def _transfer_speeds(case: Case) -> tuple[float, float]:
    """``(w_transfer, w_min)`` [rad/s]: the speed that just meets the transfer time (at least 1.5 times
    the minimum) and the minimum crank speed."""
    th1, _, _, th4 = case.key_angles
    w_min = case.limits.min_crank_speed_rpm * RPM
    return max((th1 + 2 * math.pi - th4) / case.process.transfer_time_s, 1.5 * w_min), w_min


def _published_starts(search: _Search, neighbour: Plan | None) -> list[dict[str, float]]:
    """Starts of the published placement: the neighbour's values when it has that placement, then
    guesses from the case."""
    case, w2 = search.case, search.draw_speed_range[1]
    w_transfer, w_min = _transfer_speeds(case)
    starts = [_guess(case, w2, w_transfer, share, 1.0) for share in (0.9, 0.6)]
    starts.append(_guess(case, w2, 0.5 * (w_transfer + w_min), 0.75, 1.0))
    if neighbour is not None and neighbour.placement == "published":
        starts = [neighbour.nlp_values] + starts
    return starts


def _free_starts(search: _Search, neighbour: Plan | None, published: dict[str, float] | None) -> list[dict[str, float]]:
    """Starts of the free placement: the neighbour's values when it has that placement, the best
    published-placement plan (a feasible start of the free problem), then guesses from the case."""
    case, w2 = search.case, search.draw_speed_range[1]
    w_transfer, w_min = _transfer_speeds(case)
    starts = [neighbour.nlp_values] if neighbour is not None and neighbour.placement == "free" else []
    starts += [published] if published is not None else []
    starts.append(_guess(case, w2, w_transfer, 0.9, 1.5))
    starts.append(_guess(case, w2, 2 * w_min, 0.95, 2.0))
    return starts
