"""A plan's cams (``planning.model.cam``): where the points go and what they hold.

The master runs ``m = 360 t / P`` [deg] (``t`` [s] from TDC, ``P`` the plan's period; a pendulum plan's ``t``
from its forward swing's start, one master turn its two swings), the slave is the crank angle in degrees; at a
point the plan gives ``Y = theta``, ``V = dY/dX = omega / w_m`` and ``A = d2Y/dX2 = alpha / w_m^2 * pi / 180``
with the master's speed ``w_m = 2 pi / P`` [rad/s] (the form of ``cam_table.csv``). Three placements:

- :func:`law_cam`: XYVA points where the law's segments end. Between two of them a law whose crank angle is
  a polynomial of degree five or less in time (the improved S-curve, the seven-segment law, the optimal
  law: linear jerk, degree four) is a polynomial of the same degree in the master, which the quintic
  reproduces: the cam is the plan, to round-off (:func:`exact_in_poly5`).
- :func:`fewest_xyva`: the fewest XYVA points whose quintics keep the slide within a tolerance of the plan
  (the quintic law's speed is of degree five, its angle six; the logistic and cycloidal laws are no
  polynomials): from each point the farthest next one that holds, over the plan's dense samples; a hold's
  standstill and a swing's turn start and end at a point.
- :func:`table_cam`: ``n`` points equidistant in the master (a table for a controller that interpolates
  linearly or by a spline).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from planning.model.cam import DEG, TURN_DEG, Cam, Interpolation, quintic_coefficients
from planning.model.cycle import HOLD_SEGMENT
from planning.model.free_profile import STAND_SEGMENT
from planning.model.pendulum import TURN_SEGMENT, PendulumPlan
from planning.model.plan import Plan
from planning.model.profile import sample_times
from planning.tolerances import CAM_POINT_GAP_DEG

CamPlan = Plan | PendulumPlan  # a rotary plan, or a pendulum plan (its slave back where it started after a cycle)

Height = Callable[[np.ndarray], np.ndarray]  # crank angle [rad] -> the slide's height [mm]


def xyva(plan: CamPlan, master_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Y [deg], V [deg/deg], A [deg/deg^2])`` of the plan at master angles in ``[0, 360]``; at 360 deg the
    state at 0 a turn on (the plan closes within the verification's tolerances; a cam repeats exactly)."""
    period = plan.period
    master = np.asarray(master_deg, dtype=float)
    end = master >= TURN_DEG
    th, om, al, _ = plan.profile.at_time(np.where(end, 0.0, master) / TURN_DEG * period)
    w_m = 2 * math.pi / period
    return np.degrees(th) + np.where(end, plan.slave_turn_deg, 0.0), om / w_m, al / w_m**2 * DEG


def poly5_cam(plan: CamPlan, master_deg: np.ndarray) -> Cam:
    """The XYVA cam of the plan at the master angles (0 and 360 among them)."""
    y, v, a = xyva(plan, master_deg)
    return Cam(Interpolation.POLY5, np.asarray(master_deg, dtype=float), y, v, a, plan.slave_turn_deg)


def segment_ends(plan: CamPlan) -> np.ndarray:
    """The master angles [deg] where the law's segments end, 0 and 360 included; an end closer than
    :data:`~planning.tolerances.CAM_POINT_GAP_DEG` to the point before it (or to 360) is left out."""
    master = np.unique(np.clip(plan.profile.knot_times / plan.period * TURN_DEG, 0.0, TURN_DEG))
    kept = [0.0]
    for m in master:
        if m - kept[-1] > CAM_POINT_GAP_DEG and TURN_DEG - m > CAM_POINT_GAP_DEG:
            kept.append(float(m))
    return np.array([*kept, TURN_DEG])


def exact_in_poly5(plan: CamPlan) -> bool:
    """Whether each of the plan's segments is a polynomial of degree five or less in time (linear jerk and
    no shape): then :func:`law_cam` is the plan to round-off (two segment ends closer than
    :data:`~planning.tolerances.CAM_POINT_GAP_DEG` apart are one point: a short piece's error instead)."""
    return all(seg.shape is None for seg in plan.profile.segments)


def law_cam(plan: CamPlan) -> Cam:
    """XYVA points where the law's segments end."""
    return poly5_cam(plan, segment_ends(plan))


def table_cam(plan: CamPlan, points: int, interpolation: Interpolation) -> Cam:
    """``points`` points equidistant in the master (a table; the end, 360 deg, is the start a turn on)."""
    if interpolation is Interpolation.POLY5:
        return poly5_cam(plan, np.linspace(0.0, TURN_DEG, points + 1))
    master = np.linspace(0.0, TURN_DEG, points + 1)
    return Cam(interpolation, master, xyva(plan, master)[0], slave_turn_deg=plan.slave_turn_deg)


def slide_deviation_mm(cam: Cam, plan: CamPlan, height: Height, master_deg: np.ndarray) -> float:
    """The largest ``|h(cam) - h(plan)|`` [mm] at the master angles."""
    y_cam = cam.at(master_deg)[0]
    y_plan = xyva(plan, master_deg)[0]
    return float(np.max(np.abs(height(y_cam * DEG) - height(y_plan * DEG))))


def fewest_xyva(plan: CamPlan, height: Height, tolerance_mm: float) -> Cam:
    """The fewest XYVA points (from the plan's dense samples: every millisecond and every knot) whose
    quintics keep the slide within ``tolerance_mm`` of the plan at every sample: from each point, the
    farthest sample whose quintic back to it holds (found by doubling the reach, then halving it)."""
    times = sample_times(plan.period, plan.profile.knot_times)[0]
    master = times / plan.period * TURN_DEG
    y, v, a = xyva(plan, master)
    h = height(y * DEG)
    chosen = [0]
    must = standstill_samples(plan, times)
    while chosen[-1] < master.size - 1:
        i = chosen[-1]
        last = next((k for k in must if k > i), master.size - 1)  # never past a standstill's end
        reach = 1
        while i + reach < last and _holds(i, i + 2 * reach, master, y, v, a, h, height, tolerance_mm):
            reach *= 2
        lo, hi = i + reach, min(i + 2 * reach, last)
        if hi > lo and _holds(i, hi, master, y, v, a, h, height, tolerance_mm):
            lo = hi
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if _holds(i, mid, master, y, v, a, h, height, tolerance_mm) else (lo, mid)
        chosen.append(min(lo, last))
    picked = np.array(chosen)
    x = master[picked]
    x[0], x[-1] = 0.0, TURN_DEG
    return Cam(Interpolation.POLY5, x, y[picked], v[picked], a[picked], plan.slave_turn_deg)


def standstill_samples(plan: CamPlan, times: np.ndarray) -> list[int]:
    """The indices in ``times`` (the plan's samples, its knots among them) of where a hold's standstill starts
    and ends: points of every cam, so that the crank stands still between them (a quintic from a point
    before the standstill to one after it would move)."""
    knots = plan.profile.knot_times
    ends = [
        t
        for k, seg in enumerate(plan.profile.segments)
        if seg.name in (HOLD_SEGMENT, TURN_SEGMENT, STAND_SEGMENT)
        for t in (knots[k], knots[k + 1])
    ]
    return sorted(int(np.argmin(np.abs(times - t))) for t in ends)


def _holds(
    i: int,
    j: int,
    master: np.ndarray,
    y: np.ndarray,
    v: np.ndarray,
    a: np.ndarray,
    h: np.ndarray,
    height: Height,
    tolerance_mm: float,
) -> bool:
    """Whether the quintic from sample ``i`` to ``j`` keeps the slide within the tolerance at the samples
    between them."""
    if j > master.size - 1:
        return False
    if j - i < 2:
        return True
    w = np.array([master[j] - master[i]])
    b = quintic_coefficients(w, y[[i, j]], v[[i, j]], a[[i, j]])[0]
    x = master[i + 1 : j] - master[i]
    y_fit = y[i] + x * (b[0] + x * (b[1] + x * (b[2] + x * (b[3] + x * b[4]))))
    return bool(np.max(np.abs(height(y_fit * DEG) - h[i + 1 : j])) <= tolerance_mm)
