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
from planning.solver.parameters import brake_crossing


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

    lead, th_return, w_return = hold_lead(case, w2)
    D_fa, D_fd = halves(th2 - th1, w1, w2)
    D_ra, D_rd = halves(th4 - th_return, w_return, w1)
    T_c = (th1 + 2 * math.pi - th4) / w1
    share = inside / sc.SUBSEGMENTS
    t4 = lead + D_ra + (1 - share) * D_rd
    t1 = lead + D_ra + D_rd + T_c + share * D_fa
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
        "die_down_time": braking_time(case, w2) if brake_crossing(case) else 0.5 * (t1 + t_feed_end),
        "die_up_time": 0.5 * (lead + t4),
    }


def braking_time(case: Case, w2: float) -> float:
    """[s from theta3] when the braking crank passes the descending die-height crossing (before a hold), as a
    constant deceleration from ``w2`` to rest over the brake's angle would: a start for its time variable."""
    th3 = float(case.key_angles[2])
    down = float(case.machine.angles_at_height(case.limits.die_height_mm)[0])
    share = (down - th3) / (case.hold_angle - th3)  # of the angle; the time's share is 1 - sqrt(1 - share)
    return (1 - math.sqrt(1 - share)) * 2 * (case.hold_angle - th3) / w2


def hold_lead(case: Case, w2: float) -> tuple[float, float, float]:
    """``(time [s] from theta3 to the return's start, the angle [rad] and speed [rad/s] it starts at)``: 0,
    theta3, ``w2``; after a hold the brake's time (``2 (theta_h - theta3) / w2``) and the hold's, theta_h, 0."""
    th3 = float(case.key_angles[2])
    if case.hold_angle is None:
        return 0.0, th3, w2
    return 2 * (case.hold_angle - th3) / w2 + case.process.hold_time_s, case.hold_angle, 0.0


def transfer_speeds(case: Case) -> tuple[float, float]:
    """``(w_transfer, w_min)`` [rad/s]: the speed that just meets the transfer time (at least 1.5 times
    the minimum) and the minimum crank speed."""
    th1, _, _, th4 = case.key_angles
    w_min = case.limits.min_crank_speed_rpm * RPM
    return max((th1 + 2 * math.pi - th4) / case.transfer_time_s, 1.5 * w_min), w_min


def published_starts(case: Case, w2: float, neighbour: Plan | None) -> list[dict[str, float]]:
    """Starts of the published placement at draw speed ``w2`` [rad/s]: the neighbour's values when it has
    that placement, then guesses from the case, the constant-speed motion last (:func:`constant_speed`)."""
    w_transfer, w_min = transfer_speeds(case)
    starts = [guess(case, w2, w_transfer, share, 1.0) for share in (0.9, 0.6)]
    starts.append(guess(case, w2, 0.5 * (w_transfer + w_min), 0.75, 1.0))
    if case.hold_angle is None:  # a hold stops the crank: never one constant speed
        starts.append(constant_speed(case, w2, 1.0))
    if neighbour is not None and neighbour.placement == "published":
        starts = [neighbour.nlp_values] + starts
    return starts


def constant_speed(case: Case, w2: float, inside: float) -> dict[str, float]:
    """The crank at one constant speed all round (every half a speed change of zero: a motion of every law
    with halves, whatever its jerk limit), the speed the draw's, the transfer time's and the slide's
    acceleration at constant speed allow, the lowest of them (at least the minimum crank speed): a start that
    holds where the others cannot reach a plan (a crank-jerk limit near zero). Key points ``inside`` quarters
    into the halves, as :func:`guess` places them."""
    th1, th2, th3, th4 = case.key_angles
    w_transfer, w_min = transfer_speeds(case)
    w_window = (th1 + 2 * math.pi - th4) / case.transfer_time_s
    w_accel = math.sqrt(case.limits.slider_accel_mm_s2 / case.machine.peak_curvature)
    w = max(min(w2, w_window, w_accel, top_crank_speed(case) or math.inf), w_min)
    share = inside / sc.SUBSEGMENTS  # theta4 this share before the return's end, theta1 after the feed's start
    D_r = (th4 - th3) / ((2 - share) * w)  # the return's halves sweep theta3 .. theta4 and the share past it
    D_f = (th2 - th1) / ((2 - share) * w)
    T_c = max((th1 + 2 * math.pi - th4) / w - share * (D_r + D_f), 0.0)
    t4 = D_r + (1 - share) * D_r
    t1 = 2 * D_r + T_c + share * D_f
    law = get_law(case.planner.motion_law)
    return {
        "transfer_speed": w,
        "draw_speed": w,
        "feed_peak_speed": w,
        "return_peak_speed": w,
        "feed_accel_duration": D_f,
        "feed_decel_duration": D_f,
        "return_accel_duration": D_r,
        "return_decel_duration": D_r,
        "transfer_dwell": T_c,
        "law_parameter": law.parameter.start if law.parameter else 0.0,
        "closing_time": t1,
        "opening_time": t4,
        "die_down_time": 0.5 * (t1 + t1 - share * D_f + 2 * D_f),
        "die_up_time": 0.5 * t4,
    }


def free_starts(
    case: Case, w2: float, neighbour: Plan | None, published: dict[str, float] | None
) -> list[dict[str, float]]:
    """Starts of the free placement: the neighbour's values when it has that placement, the published
    placement's plan (a free solve's first verified one), the die exit's start where the draw ends in the die
    zone (:func:`die_exit`), then guesses from the case."""
    w_transfer, w_min = transfer_speeds(case)
    starts = [neighbour.nlp_values] if neighbour is not None and neighbour.placement == "free" else []
    starts += [published] if published is not None else []
    exit_start = die_exit(case, w2)
    starts += [exit_start] if exit_start is not None else []
    starts.append(guess(case, w2, w_transfer, 0.9, 1.5))
    starts.append(guess(case, w2, 2 * w_min, 0.95, 2.0))
    if case.hold_angle is None:
        starts.append(constant_speed(case, w2, 1.5))
    return starts


def die_exit(case: Case, w2: float) -> dict[str, float] | None:
    """Where the draw ends with the slide still below the die height (the check warns of it), the die speed
    caps the crank at the crossing the slide rises through after theta3: ``v_die / |h'|`` there. A start of
    that structure: the return's halves sweep theta3 to that crossing only, and the transfer runs at the cap
    (or the speed the transfer time needs, the lower) from the crossing through the robot's window, theta4
    in the transfer. None where the draw ends above the die height, or with a hold (its return starts at rest)."""
    m = case.machine
    th1, _, th3, th4 = case.key_angles
    die = case.limits.die_height_mm
    if float(m.height(th3)) >= die or case.hold_angle is not None:
        return None
    up = float(m.angles_at_height(min(die, m.stroke))[1])
    if not th3 < up < th4:
        return None
    cap = case.limits.die_speed_mm_s / abs(float(m.derivatives(up)[0]))
    w_transfer, w_min = transfer_speeds(case)
    w1 = max(min(w_transfer, cap), w_min)
    x0 = guess(case, w2, w1, 0.9, 1.0)
    wm2 = 1.1 * max(w1, w2)
    ratio = math.sqrt((wm2 - w1) / (wm2 - w2))  # one jerk for both halves (Eq. 14)
    D_ra = (up - th3) / ((w2 + wm2) / 2 + ratio * (wm2 + w1) / 2)
    D_rd = ratio * D_ra
    D_fa, wm1 = x0["feed_accel_duration"], x0["feed_peak_speed"]
    share = 1.0 / sc.SUBSEGMENTS  # theta1 a sub-segment into the feed's acceleration, as in guess()
    feed_start = th1 + 2 * math.pi - share * D_fa * (w1 + wm1) / 2
    dwell = max((feed_start - up) / w1, 0.0)
    closing = D_ra + D_rd + dwell + share * D_fa
    return {
        **x0,
        "transfer_speed": w1,
        "return_peak_speed": wm2,
        "return_accel_duration": D_ra,
        "return_decel_duration": D_rd,
        "transfer_dwell": dwell,
        "opening_time": D_ra + D_rd + (th4 - up) / w1,
        "closing_time": closing,
        "die_up_time": D_ra + D_rd,
        "die_down_time": 0.5 * (closing + D_ra + D_rd + dwell + D_fa + x0["feed_decel_duration"]),
    }


PERIOD_BISECTIONS = 60  # halvings of the transfer speed's range: below round-off
PERIOD_SPEED_RANGE = (1e-3, 10.0)  # the transfer speed searched: this share of the draw's ... times a turn a period
PERIOD_PEAK_SHARES = (0.9, 0.6)  # the guesses' peak speeds, shares of the constant-speed acceleration bound
PERIOD_INSIDE = 1.5  # the key points this many quarters into the halves (as the free placement's guesses)


def guesses_at_period(case: Case, w2: float, period_s: float) -> list[dict[str, float]]:
    """Starts at cycle time ``period_s`` [s] and draw speed ``w2`` [rad/s] (a press run slower than its
    fastest, in a line): :func:`guess`'s S-curves with the transfer speed whose rough cycle (the halves, the
    transfer dwell and the draw at ``w2``) takes ``period_s``, found by bisection, peak speeds at two shares."""
    _, th2, th3, _ = case.key_angles
    draw_s = (th3 - th2) / w2

    def cycle_s(values: dict[str, float]) -> float:
        halves = ("feed_accel_duration", "feed_decel_duration", "return_accel_duration", "return_decel_duration")
        return sum(values[k] for k in halves) + values["transfer_dwell"] + draw_s

    starts = []
    for share in PERIOD_PEAK_SHARES:
        lo, hi = PERIOD_SPEED_RANGE[0] * w2, PERIOD_SPEED_RANGE[1] * 2 * math.pi / period_s
        for _ in range(PERIOD_BISECTIONS):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if cycle_s(guess(case, w2, mid, share, PERIOD_INSIDE)) > period_s else (lo, mid)
        starts.append(guess(case, w2, 0.5 * (lo + hi), share, PERIOD_INSIDE))
    return starts
