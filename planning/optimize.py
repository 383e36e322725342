"""The orchestrator: case -> NLP parameters -> multi-start IPOPT solves -> verified plan.

Initial guesses are built from the case alone (never from published numbers): a transfer speed,
peak speeds near the constant-speed acceleration bound, and half durations that sweep the angles
between the key points (the same for every motion law: each half of every law sweeps
``D (v_start + v_end) / 2``). The NLP is the one of the case's motion law (``planner.motion_law``).
``free`` placement starts also from the ``published`` placement's solution, so it is never worse
than that structure, and keeps the best plan that verifies.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from planning.case import RPM, Case, draw_speed_bounds
from planning.cycle import HALVES
from planning.laws import get_law
from planning.laws import improved_scurve as sc
from planning.nlp import PARAMETER_INDEX, PARAMETERS, VARIABLE_INDEX, VARIABLES, CycleNLP, cycle_nlp
from planning.plan import Plan, SolverInfo, params_from_numbers, profile_from_tdc
from planning.verify import ACCEL_CHECK, Verification, verify

Placement = Literal["free", "published"]
ACCEL_BACKOFF = 5e-4  # the NLP keeps |slider acceleration| <= (1 - backoff) * limit at its samples
MIN_HALF_S = 4e-3  # [s] lower bound on the duration of a half (1 ms per improved-S-curve sub-segment)
MAX_TIME_S = 600.0  # [s] upper bound on any time variable
REFINEMENTS = 3  # re-solves with a lowered sampled acceleration limit
NO_LIMIT = 1e9  # stands for an absent motor limit in the NLP's parameters
AGREE_S = 1e-6  # [s] two starts whose best periods agree this closely have found the same optimum


class PlanningError(Exception):
    """No verified plan. ``kind`` is ``infeasible`` (limits cannot be met) or ``unverified``."""

    def __init__(self, kind: str, reason: str):
        self.kind = kind
        self.reason = reason
        super().__init__(f"{kind}: {reason}")


@dataclass(frozen=True)
class Solution:
    """A verified plan and its verification."""

    plan: Plan
    verification: Verification


def precheck(case: Case) -> tuple[float, float]:
    """Cheap necessary conditions before any NLP; returns the draw-speed bounds ``(lo, hi)`` [rad/s].

    Raises :class:`PlanningError` (infeasible) naming the limit that makes the case impossible.
    """
    bounds = draw_speed_bounds(case)
    w_min = case.limits.min_crank_speed_rpm * RPM
    th1, _, _, th4 = case.key_angles
    window = th1 + 2 * math.pi - th4
    if window / w_min < case.process.transfer_time_s:
        raise PlanningError(
            "infeasible",
            f"transfer_time_s = {case.process.transfer_time_s:g} cannot be met: at min_crank_speed_rpm = "
            f"{case.limits.min_crank_speed_rpm:g} the crank crosses the {math.degrees(window):.1f} deg from "
            f"theta4 to theta1 in at most {window / w_min:.3f} s",
        )
    w_given = case.process.draw_speed_rpm
    if w_given is not None:
        w2 = w_given * RPM
        if w2 > bounds["slider_accel"] * (1 + 1e-12):
            a_draw = case.limits.slider_accel_mm_s2 * (w2 / bounds["slider_accel"]) ** 2
            raise PlanningError(
                "infeasible",
                f"at the draw speed {w_given:g} rpm the slider acceleration in the draw reaches "
                f"{a_draw:.0f} mm/s^2 > slider_accel_mm_s2 = {case.limits.slider_accel_mm_s2:g}",
            )
        return w2, w2
    hi = min(bounds.values())
    if hi < w_min:
        name = min(bounds, key=bounds.get)
        raise PlanningError(
            "infeasible",
            f"the {name.replace('_', ' ')} limit allows a draw speed of at most {hi / RPM:.3f} rpm, "
            f"below min_crank_speed_rpm = {case.limits.min_crank_speed_rpm:g}",
        )
    return w_min, hi


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
        "crank_speed_max": (lim.crank_speed_rpm or NO_LIMIT) * RPM,
        "crank_accel_max": lim.crank_accel_rad_s2 or NO_LIMIT,
        "crank_jerk_max": lim.crank_jerk_rad_s3 or NO_LIMIT,
    }
    return np.array([values[k] for k in PARAMETERS], dtype=float)


def _guess(case: Case, w2: float, w1: float, peak_share: float, inside: float) -> dict[str, float]:
    """A rough start: S-curves that sweep the key-point angles, peak speeds ``peak_share`` of the
    constant-speed acceleration bound, key points ``inside`` quarters into the halves."""
    law = get_law(case.planner.motion_law)
    R, L = case.press.crank_radius_mm, case.press.rod_length_mm
    th1, th2, th3, th4 = case.key_angles
    w_acc = math.sqrt(case.limits.slider_accel_mm_s2 / (R + R**2 / L))  # |d2h/dtheta2| peaks at BDC
    top = case.limits.crank_speed_rpm * RPM if case.limits.crank_speed_rpm else math.inf
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
        "law_parameter": law.parameter[3] if law.parameter else 0.0,
        "closing_time": t1,
        "opening_time": t4,
        "die_down_time": 0.5 * (t1 + t_feed_end),
        "die_up_time": 0.5 * t4,
    }


def _bounds(case: Case, w2_lo: float, w2_hi: float, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    lo = np.zeros(len(VARIABLES))
    hi = np.full(len(VARIABLES), MAX_TIME_S)
    w_min = case.limits.min_crank_speed_rpm * RPM
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
        lo[i["law_parameter"]], hi[i["law_parameter"]] = law.parameter[1:3]
    for k in ("die_down", "die_up"):
        if p[PARAMETER_INDEX[f"{k}_active"]] == 0.0:
            lo[i[f"{k}_time"]] = hi[i[f"{k}_time"]] = 0.0
    return lo, hi


def scales_for(case: Case) -> np.ndarray:
    """Variable scales from the press's own characteristic time ``T* = sqrt(R / A)`` [s] and speed
    ``W* = sqrt(A / (R + R^2/L))`` [rad/s] (A the slider-acceleration limit): speeds ~ W*,
    durations of the halves ~ T*, stage times ~ 10 T*. The factors make the variables O(1) for a
    press cycle of the usual proportions; they span orders of magnitude from a small fast press to a
    heavy slow one."""
    R, L, A = case.press.crank_radius_mm, case.press.rod_length_mm, case.limits.slider_accel_mm_s2
    t_star = math.sqrt(R / A)
    w_star = math.sqrt(A / (R + R**2 / L))
    unit = {"speed": 0.42 * w_star, "half": 1.12 * t_star, "time": 2.8 * t_star, "shape": 1.0}
    kinds = {f"{k}_duration": "half" for k in HALVES}
    kinds.update({f"{k}_speed": "speed" for k in ("transfer", "draw", "feed_peak", "return_peak")})
    kinds["law_parameter"] = "shape"
    return np.array([unit[kinds.get(k, "time")] for k, _ in VARIABLES])


def _run(
    nlp: CycleNLP,
    placement: Placement,
    x0: dict[str, float],
    p: np.ndarray,
    lbx: np.ndarray,
    ubx: np.ndarray,
    multipliers: tuple[np.ndarray, np.ndarray] | None = None,
):
    """One IPOPT solve; ``p`` = case parameters + variable scales, ``lbx``/``ubx`` physical bounds.
    With ``multipliers`` (of a nearby solve) the warm-start solver is used. Returns the values, the
    constraint values, IPOPT's statistics and the multipliers."""
    scales = p[len(PARAMETERS) :]
    x0v = np.clip(np.array([x0[k] for k, _ in VARIABLES]), lbx, ubx) / scales
    lbg, ubg = nlp.bounds(placement)
    args = {"x0": x0v, "p": p, "lbx": lbx / scales, "ubx": ubx / scales, "lbg": lbg, "ubg": ubg}
    solver = nlp.solver
    if multipliers is not None:
        solver = nlp.warm_solver()
        args.update(lam_x0=multipliers[0], lam_g0=multipliers[1])
    res = solver(**args)
    stats = solver.stats()
    x = np.clip(np.array(res["x"]).ravel() * scales, lbx, ubx)  # IPOPT relaxes bounds by ~1e-8
    g = np.array(res["g"]).ravel()
    lam = (np.array(res["lam_x"]).ravel(), np.array(res["lam_g"]).ravel())
    return {k: float(x[j]) for j, (k, _) in enumerate(VARIABLES)}, g, stats, lam


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


def _violation(nlp: CycleNLP, placement: Placement, g: np.ndarray) -> tuple[str, float]:
    """The constraint block with the largest violation at the last iterate."""
    lbg, ubg = nlp.bounds(placement)
    viol = np.maximum(lbg - g, 0) + np.maximum(g - ubg, 0)
    worst = max(nlp.blocks, key=lambda b: float(np.max(viol[b.start : b.stop], initial=0.0)))
    return worst.name, float(np.max(viol[worst.start : worst.stop], initial=0.0))


def solve(case: Case, placement: Placement | None = None, warm: Plan | None = None, follow: bool = False) -> Solution:
    """The fastest verified cycle for ``case``; raises :class:`PlanningError` when there is none.

    ``warm``: a plan of a neighbouring case (a sweep, a relaxed limit). It is verified against this
    case as it stands (when its placement fits and its key angles and draw speed are this case's) and
    its NLP values start the multi-start, so the answer is never worse than ``warm`` where ``warm``
    is feasible here. ``follow``: with a fitting ``warm`` plan, solve from it alone and return what
    that start finds when it verifies (a sweep following its neighbours); otherwise the full
    multi-start runs.
    """
    placement = placement or case.planner.placement
    t_start = time.perf_counter()
    w2_lo, w2_hi = precheck(case)
    p = nlp_parameters(case)
    w2 = w2_hi
    th1, _, _, th4 = case.key_angles
    w_min = case.limits.min_crank_speed_rpm * RPM
    w_transfer = max((th1 + 2 * math.pi - th4) / case.process.transfer_time_s, 1.5 * w_min)

    best: Solution | None = None
    failures: list[str] = []
    iterations = 0
    starts = 0

    def attempt(x0: dict[str, float], as_placement: Placement) -> tuple[dict[str, float], float] | None:
        """Solve from ``x0``; if only the dense slider-acceleration check fails, lower the NLP's
        sampled limit by the measured overshoot and re-solve warm (at most ``REFINEMENTS`` times).
        Returns the verified values and period, or None."""
        nonlocal best, iterations, starts
        q = p.copy()
        values = x0
        lam = None
        starts += 1
        for _ in range(REFINEMENTS + 1):
            values, g, stats, lam = _run(nlp, as_placement, values, q, lbx, ubx, lam)
            iterations += int(stats["iter_count"])
            status = str(stats["return_status"])
            if status not in ("Solve_Succeeded", "Solved_To_Acceptable_Level"):
                name, amount = _violation(nlp, as_placement, g)
                failures.append(f"solver stopped ({status}); worst constraint: {name} (violated by {amount:.3g})")
                return None
            info = SolverInfo(iterations, time.perf_counter() - t_start, starts, status)
            plan = _plan(case, values, as_placement, info)
            check = verify(plan, case)
            if check.passed:
                if best is None or plan.period < best.plan.period - 1e-9:
                    best = Solution(plan, check)
                return values, plan.period
            bad = check.failures()
            failures.append(
                f"verification failed: {bad[0].name} = {bad[0].value:.6g} {bad[0].unit} (limit {bad[0].limit:.6g})"
            )
            if [c.name for c in bad] != [ACCEL_CHECK]:
                return None
            q[PARAMETER_INDEX["accel_limit"]] *= (bad[0].limit / bad[0].value) * (1 - 1e-5)
        return None

    def multi_start(x0s: list[dict[str, float]], as_placement: Placement) -> dict[str, float] | None:
        """Run the starts in order until the two best verified ones agree on the period (the optimum
        is confirmed) or the starts run out; the values of the best verified start."""
        found: list[tuple[float, dict[str, float]]] = []
        tried: list[np.ndarray] = []
        for x0 in x0s:
            key = np.array([x0[k] for k, _ in VARIABLES])
            if any(np.allclose(key, other, rtol=1e-9, atol=1e-12) for other in tried):
                continue  # the same start again would only repeat its answer
            tried.append(key)
            out = attempt(x0, as_placement)
            if out is None:
                continue
            found.append((out[1], out[0]))
            found.sort(key=lambda item: item[0])
            if len(found) >= 2 and found[1][0] - found[0][0] <= AGREE_S:
                break
        return found[0][1] if found else None

    nlp = cycle_nlp(case.planner.motion_law)
    lbx, ubx = _bounds(case, w2_lo, w2_hi, p)
    p = np.concatenate([p, scales_for(case)])
    if warm is not None and _fits(warm, case, placement, w2_lo, w2_hi):
        check = verify(warm, case)
        if check.passed:
            best = Solution(warm, check)
    if warm is not None and warm.motion_law != case.planner.motion_law:
        warm = None  # another law's plan neither answers this case nor starts its NLP
    warm_values = [warm.nlp_values] if warm is not None and warm.nlp_values else []
    same_rule = warm is not None and (warm.placement == placement or placement == "free")
    if follow and warm_values and same_rule and attempt(warm_values[0], warm.placement) is not None:
        return _finished(best, iterations, starts, t_start, placement)
    published_starts = [_guess(case, w2, w_transfer, share, 1.0) for share in (0.9, 0.6)]
    published_starts.append(_guess(case, w2, 0.5 * (w_transfer + w_min), 0.75, 1.0))
    if warm is not None and warm.placement == "published":
        published_starts = warm_values + published_starts
    pub_values = multi_start(published_starts, "published")
    if placement == "free":
        free_starts = list(warm_values) if warm is not None and warm.placement == "free" else []
        free_starts += [pub_values] if pub_values is not None else []  # a feasible start of the free problem
        free_starts.append(_guess(case, w2, w_transfer, 0.9, 1.5))
        free_starts.append(_guess(case, w2, 2 * w_min, 0.95, 2.0))
        multi_start(free_starts, "free")
    return _finished(best, iterations, starts, t_start, placement, failures)


def _finished(
    best: Solution | None,
    iterations: int,
    starts: int,
    t_start: float,
    placement: Placement,
    failures: list[str] | None = None,
) -> Solution:
    """The answer of :func:`solve`: the best verified plan with the solver's totals, or the error."""
    if best is None:
        failures = failures or []
        found = [f for f in failures if f.startswith("verification")]
        if found:  # a converged plan failed the dense check: that finding is the answer
            raise PlanningError("unverified", "no plan meets the limits: " + found[0])
        raise PlanningError("infeasible", "no plan meets the limits: " + (failures[-1] if failures else "no start"))
    plan = best.plan
    if placement == "free" and plan.placement == "published":
        # the published structure is one of the free structures: report it as the free answer
        plan = replace(plan, placement="free")
    info = SolverInfo(iterations, time.perf_counter() - t_start, starts, plan.solver.status)
    return Solution(replace(plan, solver=info), best.verification)
