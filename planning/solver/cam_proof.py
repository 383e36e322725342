"""A cam proved as its controller runs it.

A cam (``planning.model.cam``) is run as its controller interpolates it, the master turning at a share
``speed`` of the plan's master speed (1: the plan's, ``360 / P`` deg/s; an operator's override turns it up
or down), and passed through the dense verification the plan passed (``planning.solver.verify.evaluate``
with ``cam``; a pendulum plan's, ``planning.solver.pendulum_check.evaluate_pendulum``): the cycle closes
and every limit of the press and the process holds. At a master speed ``s`` times the plan's, the crank's
speed scales with ``s``, its acceleration with ``s^2``, its jerk with ``s^3`` and the robot's window with
``1 / s``; the proof does not scale figures, it runs the cam at that
speed. What a proof states (:class:`CamProof`): whether every limit holds, each limit's margin, the
largest slide deviation from the plan [mm] at the same master angle, the steps across the cam's end, and
the highest master speed at which every limit still holds (to :data:`SPEED_RESOLUTION`), with the first
failure :data:`OVERRIDE_STEP` above it.

:func:`cam_for` places the points as a :class:`CamSpec` asks (``planning.model.cam_points``): XYVA at the
law's segment ends, the fewest XYVA points within a slide tolerance or of a number at most, a table of
``n`` points, or (``auto``) the fewest for which every limit holds.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from planning.model.cam import DEG, Cam, Interpolation, realised_profile
from planning.model.cam_points import CamPlan, exact_in_poly5, fewest_xyva, law_cam, table_cam
from planning.model.case import Case
from planning.model.limits.base import Check
from planning.model.pendulum import PendulumPlan
from planning.solver.pendulum_check import evaluate_pendulum
from planning.solver.verify import Evaluation, Verification, evaluate
from planning.tolerances import CAM_END_TOL, CAM_TIGHTEST_MM, SPEED_RESOLUTION

CONTROLLER_CYCLE_S = 1e-3  # [s] the controller's cycle a linear table is driven at (a common EtherCAT cycle)
OVERRIDE_STEP = 0.01  # the proof shows the cam failing this share above its highest master speed
FASTEST_SEARCHED = 8.0  # the highest master speed searched, as a share of the plan's
MOST_TABLE_POINTS = 10_000  # the largest table ``auto`` tries (Siemens TO_Cam_10k's)
TOLERANCE_SHRINK = 10.0  # ``auto`` tightens an XYVA cam's tolerance by this factor until every limit holds


@dataclass(frozen=True)
class CamSpec:
    """What cam to make: its ``interpolation``; ``points`` (at most this many: a table's count; XYVA points
    as close to the plan as that many can be) or ``tolerance_mm`` (XYVA: the fewest points within it of the
    plan's slide); neither: XYVA at the law's segment ends where the law is a polynomial in time, else the
    fewest points for which every limit holds (a table's too); ``speed``: the master speed it is proved at,
    a share of the plan's; ``cycle_s`` [s]: the controller's cycle (a linear table as the drive follows
    it)."""

    interpolation: Interpolation = Interpolation.POLY5
    points: int | None = None
    tolerance_mm: float | None = None
    speed: float = 1.0
    cycle_s: float = CONTROLLER_CYCLE_S


@dataclass(frozen=True)
class CamProof:
    """A cam run as its controller runs it (module docstring): the ``cam``, its ``plan``, the master
    ``speed`` it was proved at (a share of the plan's), its ``evaluation`` there (every check with its
    margin), ``deviation_mm`` and ``deviation_deg`` (the largest slide and crank deviation from the plan at
    the same master angle), ``end_steps`` (across the cam's end: deg, deg/deg, deg/deg^2), the
    ``highest_speed`` share at which every limit holds (0 when none searched does; :data:`FASTEST_SEARCHED`
    when it holds up to there) and ``above``: the verification :data:`OVERRIDE_STEP` above it (None when
    the search's ceiling holds)."""

    cam: Cam
    plan: CamPlan
    speed: float
    evaluation: Evaluation
    deviation_mm: float
    deviation_deg: float
    end_steps: tuple[float, float, float]
    highest_speed: float
    above: Verification | None

    @property
    def ends_join(self) -> bool:
        """Whether position, speed and acceleration continue across the cam's end (a smooth cam)."""
        return all(abs(step) <= CAM_END_TOL for step in self.end_steps)

    @property
    def passed(self) -> bool:
        """Every limit holds at the proof's master speed."""
        return self.evaluation.verification.passed

    def failure(self) -> Check | None:
        """The first check that fails at the proof's master speed (None when all hold)."""
        failures = self.evaluation.verification.failures()
        return failures[0] if failures else None


def run(cam: Cam, plan: CamPlan, case: Case, speed: float = 1.0, cycle_s: float = CONTROLLER_CYCLE_S) -> Evaluation:
    """The dense verification of ``cam`` run at ``speed`` times the plan's master speed."""
    profile = realised_profile(cam, plan.period / speed, cycle_s)
    if isinstance(plan, PendulumPlan):  # the swings' own verification, their times divided by the speed
        return evaluate_pendulum(replace(plan, profile=profile, time_scale=speed), case, cam=True)
    # the robots follow their cams on the same master: at ``speed`` they run that many times as fast
    return evaluate(replace(plan, profile=profile, robot_time_scale=speed), case, cam=True)


def prove(cam: Cam, plan: CamPlan, case: Case, speed: float = 1.0, cycle_s: float = CONTROLLER_CYCLE_S) -> CamProof:
    """The :class:`CamProof` of ``cam`` at ``speed``."""
    evaluation = run(cam, plan, case, speed, cycle_s)
    deviation_mm, deviation_deg = _deviation(evaluation, plan, case, speed)
    highest, above = _highest_speed(cam, plan, case, speed, evaluation.verification.passed, cycle_s)
    return CamProof(cam, plan, speed, evaluation, deviation_mm, deviation_deg, cam.end_steps(), highest, above)


def _deviation(evaluation: Evaluation, plan: CamPlan, case: Case, speed: float) -> tuple[float, float]:
    """The largest slide [mm] and crank [deg] deviation of the run cam from the plan at the same master
    angle, over the run's dense samples."""
    samples = evaluation.samples
    t_plan = samples.t * speed  # the plan's time at the same master angle
    th_plan = plan.profile.at_time(t_plan)[0]
    h_plan = case.machine.jets(th_plan)[0]
    return float(np.max(np.abs(samples.h - h_plan))), float(np.degrees(np.max(np.abs(samples.theta - th_plan))))


def _highest_speed(
    cam: Cam, plan: CamPlan, case: Case, speed: float, holds: bool, cycle_s: float
) -> tuple[float, Verification | None]:
    """The highest master speed share at which every limit holds, to :data:`SPEED_RESOLUTION`, and the
    verification :data:`OVERRIDE_STEP` above it: up from ``speed`` where the cam holds there, down from it
    where it does not (0 when nothing down to a tenth of it holds)."""

    def passes(share: float) -> bool:
        return run(cam, plan, case, share, cycle_s).verification.passed

    if holds:
        lo, hi = speed, None
        while hi is None and lo < FASTEST_SEARCHED:
            trial = min(2 * lo, FASTEST_SEARCHED)
            if passes(trial):
                lo = trial
            else:
                hi = trial
        if hi is None:
            return lo, None
    else:
        lo, hi = None, speed
        while lo is None and hi > speed / 10:
            trial = hi * 0.9
            if passes(trial):
                lo = trial
            else:
                hi = trial
        if lo is None:
            return 0.0, None
    while hi - lo > SPEED_RESOLUTION * lo:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if passes(mid) else (lo, mid)
    above = run(cam, plan, case, lo * (1 + OVERRIDE_STEP), cycle_s).verification
    return lo, above


def cam_for(plan: CamPlan, case: Case, spec: CamSpec) -> CamProof:
    """The cam ``spec`` asks of ``plan``, proved (module docstring)."""
    poly5 = spec.interpolation is Interpolation.POLY5
    if spec.points is not None:
        cam = _within_points(plan, case, spec.points) if poly5 else table_cam(plan, spec.points, spec.interpolation)
    elif spec.tolerance_mm is not None and poly5:
        cam = fewest_xyva(plan, case.machine.height, spec.tolerance_mm)
    elif poly5 and exact_in_poly5(plan):
        cam = law_cam(plan)
    else:
        cam = _fewest_that_hold(plan, case, spec)
    return prove(cam, plan, case, spec.speed, spec.cycle_s)


def _within_points(plan: CamPlan, case: Case, most: int) -> Cam:
    """The XYVA cam of at most ``most`` points that keeps the slide closest to the plan: the law's segment
    ends where they are exact and few enough; else the fewest points within a tolerance, the tolerance
    halved while they stay at most ``most`` (from the stroke down; equidistant points where even that needs
    more)."""
    if exact_in_poly5(plan) and law_cam(plan).points <= most:
        return law_cam(plan)
    tolerance = case.machine.stroke
    best = fewest_xyva(plan, case.machine.height, tolerance)
    if best.points > most:
        return table_cam(plan, most, Interpolation.POLY5)
    while tolerance > CAM_TIGHTEST_MM:
        tolerance /= 2
        trial = fewest_xyva(plan, case.machine.height, tolerance)
        if trial.points > most:
            break
        best = trial
    return best


def _fewest_that_hold(plan: CamPlan, case: Case, spec: CamSpec) -> Cam:
    """The fewest points for which every limit holds at ``spec.speed``: an XYVA cam's tolerance tightened by
    :data:`TOLERANCE_SHRINK` from a hundredth of the stroke; a table's count by doubling, then halving
    the step. The last cam tried when none holds (its proof then says what it breaks)."""

    def holds(cam: Cam) -> bool:
        return run(cam, plan, case, spec.speed, spec.cycle_s).verification.passed

    if spec.interpolation is Interpolation.POLY5:
        tolerance = case.machine.stroke / 100
        cam = fewest_xyva(plan, case.machine.height, tolerance)
        while not holds(cam) and tolerance > CAM_TIGHTEST_MM:
            tolerance /= TOLERANCE_SHRINK
            cam = fewest_xyva(plan, case.machine.height, tolerance)
        return cam
    lo, hi = 3, 8
    while not holds(table_cam(plan, hi, spec.interpolation)):
        if hi >= MOST_TABLE_POINTS:
            return table_cam(plan, hi, spec.interpolation)
        lo, hi = hi, min(2 * hi, MOST_TABLE_POINTS)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if holds(table_cam(plan, mid, spec.interpolation)) else (mid, hi)
    return table_cam(plan, hi, spec.interpolation)


def motor_cam(cam: Cam, gear_ratio: float) -> Cam:
    """The same cam with the motor as its slave: every slave value times the gear ratio (motor turns per
    crank turn)."""
    scale = float(gear_ratio)
    return replace(
        cam,
        slave_deg=cam.slave_deg * scale,
        slope=None if cam.slope is None else cam.slope * scale,
        curvature=None if cam.curvature is None else cam.curvature * scale,
    )


def slide_at(cam: Cam, case: Case) -> np.ndarray:
    """The slide's height [mm] at the cam's points (for a controller's HMI)."""
    return case.machine.height(cam.slave_deg * DEG)
