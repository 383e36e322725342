"""Initial guesses of the halves NLP (``planning.solver.halves_nlp``), built from the case alone.

Never from published numbers: a transfer speed, peak speeds near the constant-speed acceleration bound,
and half durations that sweep the angles between the key points (the same for every motion law: each
half of every law sweeps ``D (v_start + v_end) / 2``). The published placement's starts come first; the
free placement's start also from the published placement's best plan (a feasible start of the free
problem), so it is never worse than that structure. A neighbouring case's plan starts first where it
fits.
"""

from __future__ import annotations

import math

from planning.model.case import RPM, Case
from planning.model.laws import get_law
from planning.model.laws import improved_scurve as sc
from planning.model.limits import limits_of
from planning.model.plan import Plan


def top_crank_speed(case: Case) -> float | None:
    """The lowest top crank speed [rad/s] a limit of ``case`` sets (the drive's, the motor's through the
    gear); None without one."""
    tops = [t for limit in limits_of(case) if (t := limit.top_crank_speed(case)) is not None]
    return min(tops) if tops else None


def guess(case: Case, w2: float, w1: float, peak_share: float, inside: float) -> dict[str, float]:
    """A rough start: S-curves that sweep the key-point angles, peak speeds ``peak_share`` of the
    constant-speed acceleration bound, key points ``inside`` quarters into the halves."""
    law = get_law(case.planner.motion_law)
    th1, th2, th3, th4 = case.key_angles
    w_acc = math.sqrt(case.limits.slider_accel_mm_s2 / case.machine.peak_curvature)
    top = top_crank_speed(case) or math.inf
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


def transfer_speeds(case: Case) -> tuple[float, float]:
    """``(w_transfer, w_min)`` [rad/s]: the speed that just meets the transfer time (at least 1.5 times
    the minimum) and the minimum crank speed."""
    th1, _, _, th4 = case.key_angles
    w_min = case.limits.min_crank_speed_rpm * RPM
    return max((th1 + 2 * math.pi - th4) / case.process.transfer_time_s, 1.5 * w_min), w_min


def published_starts(case: Case, w2: float, neighbour: Plan | None) -> list[dict[str, float]]:
    """Starts of the published placement at draw speed ``w2`` [rad/s]: the neighbour's values when it has
    that placement, then guesses from the case."""
    w_transfer, w_min = transfer_speeds(case)
    starts = [guess(case, w2, w_transfer, share, 1.0) for share in (0.9, 0.6)]
    starts.append(guess(case, w2, 0.5 * (w_transfer + w_min), 0.75, 1.0))
    if neighbour is not None and neighbour.placement == "published":
        starts = [neighbour.nlp_values] + starts
    return starts


def free_starts(
    case: Case, w2: float, neighbour: Plan | None, published: dict[str, float] | None
) -> list[dict[str, float]]:
    """Starts of the free placement: the neighbour's values when it has that placement, the best
    published-placement plan, then guesses from the case."""
    w_transfer, w_min = transfer_speeds(case)
    starts = [neighbour.nlp_values] if neighbour is not None and neighbour.placement == "free" else []
    starts += [published] if published is not None else []
    starts.append(guess(case, w2, w_transfer, 0.9, 1.5))
    starts.append(guess(case, w2, 2 * w_min, 0.95, 2.0))
    return starts
