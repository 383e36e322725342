"""Independent verification of a plan: dense closed-form re-simulation against every constraint.

The plan's profile is evaluated in closed form on a uniform grid of at most 1 ms (not at the
optimizer's sample points), plus every knot, and each constraint of the case is checked with the
tolerances below (the README's numerical contract). Only a plan whose checks all pass is a success.
"""

from __future__ import annotations

import enum
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from planning.model.case import RPM, Case
from planning.model.plan import Plan

MAX_STEP_S = 1e-3  # [s] dense grid step (at most), for cycles up to MAX_SAMPLES * MAX_STEP_S = 1000 s
MAX_SAMPLES = 1_000_000  # grid points at most: a longer cycle gets a uniform step of period / MAX_SAMPLES
REL_TOL = 1e-6  # relative tolerance on every limit
ANGLE_TOL = 1e-6  # [rad] key angles and cycle closure
TIME_TOL = 1e-6  # [s] transfer time
SPEED_TOL = 1e-9  # [rad/s] continuity and constant-speed draw
ENERGY_REL_TOL = 1e-6  # energy balance, relative to the larger of the forming work and integral |T_c omega| dt
CONTINUITY_TOL = 1e-9  # [rad/s, rad/s^2] jump allowed at a knot (beyond the O(eps^2) remainder)
BINDING_SHARE = 1e-4  # relative: a check within this share of its limit binds (the reports' binding list)


class CheckId(str, enum.Enum):
    """Stable identifiers of the verification checks (the display names may change; these do not)."""

    FINITE = "finite"
    CYCLE_ANGLE = "cycle_angle"
    SPEED_CLOSES = "speed_closes"
    ACCEL_CLOSES = "accel_closes"
    SPEED_CONTINUOUS = "speed_continuous"
    ACCEL_CONTINUOUS = "accel_continuous"
    KEY_ANGLES = "key_angles"
    TRANSFER_TIME = "transfer_time"
    SAFETY_HEIGHT = "safety_height"
    DRAW_CONSTANT = "draw_constant_speed"
    DRAW_START_SPEED = "draw_start_speed"
    DIE_SPEED = "die_speed"
    SLIDER_ACCEL = "slider_accel"
    CRANK_SPEED = "crank_speed_limit"
    CRANK_ACCEL = "crank_accel_limit"
    CRANK_JERK = "crank_jerk_limit"
    MIN_CRANK_SPEED = "min_crank_speed"
    MOTOR_PEAK = "motor_peak_torque"
    MOTOR_SPEED = "motor_speed"
    MOTOR_RMS = "motor_rms_torque"
    ENERGY_BALANCE = "energy_balance"


# the case field behind each check: a failure message names what the user can change
CHECK_FIELDS = {
    CheckId.TRANSFER_TIME: "process.transfer_time_s",
    CheckId.SAFETY_HEIGHT: "process.safety_height_mm",
    CheckId.DRAW_START_SPEED: "limits.draw_start_speed_mm_s",
    CheckId.DIE_SPEED: "limits.die_speed_mm_s",
    CheckId.SLIDER_ACCEL: "limits.slider_accel_mm_s2",
    CheckId.CRANK_SPEED: "limits.crank_speed_rpm",
    CheckId.CRANK_ACCEL: "limits.crank_accel_rad_s2",
    CheckId.CRANK_JERK: "limits.crank_jerk_rad_s3",
    CheckId.MIN_CRANK_SPEED: "limits.min_crank_speed_rpm",
    CheckId.KEY_ANGLES: "key_points",
    CheckId.MOTOR_PEAK: "drive.motor.peak_torque_Nm",
    CheckId.MOTOR_SPEED: "drive.motor.max_speed_rpm",
    CheckId.MOTOR_RMS: "drive.motor.rated_torque_Nm",
}


@dataclass(frozen=True)
class Check:
    """One verified constraint ``id`` (display ``name``): measured ``value`` against ``limit`` (``kind``
    max|min|equal) in ``unit``."""

    name: str
    value: float
    limit: float
    unit: str
    kind: str
    passed: bool
    id: CheckId = field(compare=False)

    @property
    def margin(self) -> float:
        """Distance to the limit, positive when satisfied (for ``equal``: minus the error)."""
        if self.kind == "max":
            return self.limit - self.value
        if self.kind == "min":
            return self.value - self.limit
        return -abs(self.value - self.limit)

    @property
    def binds(self) -> bool:
        """An inequality that sits at its limit, within :data:`BINDING_SHARE` of it."""
        return self.kind in ("max", "min") and abs(self.margin) <= BINDING_SHARE * max(abs(self.limit), 1e-12)

    def as_dict(self) -> dict:
        """The check as ``result.json`` writes it (display name, value, limit, unit, kind, passed, margin)."""
        out = asdict(self)
        del out["id"]
        return {**out, "margin": self.margin}


@dataclass(frozen=True)
class Verification:
    """All checks of a plan; ``passed`` when every one holds. ``step_s`` [s] is the grid step used."""

    checks: tuple[Check, ...]
    step_s: float
    samples: int

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def failures(self) -> list[Check]:
        return [c for c in self.checks if not c.passed]

    def binding(self) -> list[Check]:
        """The checks at their limits (:attr:`Check.binds`)."""
        return [c for c in self.checks if c.binds]


def dense_times(period: float, knot_times: np.ndarray, max_step: float = MAX_STEP_S) -> np.ndarray:
    """A uniform grid over ``[0, period]`` [s] with step <= ``max_step`` (at most :data:`MAX_SAMPLES`
    points: a coarser uniform step for a cycle longer than 1000 s), merged with the knots."""
    n = min(int(math.ceil(period / max_step)), MAX_SAMPLES)
    grid = np.linspace(0.0, period, n + 1)
    return np.unique(np.concatenate([grid, knot_times]))


def verify(plan: Plan, case: Case) -> Verification:
    """Re-simulate ``plan`` densely and check it against the limits of ``case``."""
    prof = plan.profile
    P = plan.period
    machine = case.machine
    lim = case.limits
    t = dense_times(P, prof.knot_times)
    th, om, al, je = prof.at_time(t)
    h, v, a, _ = machine.slider(th, om, al, je)
    checks: list[Check] = []

    def add(check_id: CheckId, name: str, value: float, limit: float, unit: str, kind: str, tol: float) -> None:
        value, limit = float(value), float(limit)
        if not math.isfinite(value):
            ok = False
        elif kind == "max":
            ok = value <= limit + tol
        elif kind == "min":
            ok = value >= limit - tol
        else:
            ok = abs(value - limit) <= tol
        checks.append(Check(name, value, limit, unit, kind, ok, check_id))

    finite = bool(np.all(np.isfinite(np.concatenate([th, om, al, h, v, a]))))
    add(CheckId.FINITE, "trajectory finite", 1.0 if finite else math.nan, 1.0, "", "equal", 0.0)
    # the cycle closes: 360 deg, same speed and acceleration at both ends
    end = prof.at_time(np.array([0.0, P]))
    add(
        CheckId.CYCLE_ANGLE,
        "cycle angle",
        math.degrees(end[0][1] - end[0][0]),
        360.0,
        "deg",
        "equal",
        math.degrees(ANGLE_TOL),
    )
    add(CheckId.SPEED_CLOSES, "speed closes", (end[1][1] - end[1][0]) / RPM, 0.0, "rpm", "equal", SPEED_TOL / RPM)
    add(CheckId.ACCEL_CLOSES, "acceleration closes", end[2][1] - end[2][0], 0.0, "rad/s^2", "equal", 1e-6)
    # continuity at the knots: across a knot t_k, omega(t_k + e) - omega(t_k - e) = 2 e alpha + O(e^2 |jerk|)
    # and alpha(t_k + e) - alpha(t_k - e) = e (j_left + j_right) + O(e^2 |dj/dt|); a jump would add its
    # full size. e stays within both neighbouring segments; the remainders are bounded from their jerks.
    knots = prof.knot_times[1:-1]
    if knots.size:
        T = prof.durations
        eps = np.minimum(1e-7, 0.25 * np.minimum(T[:-1], T[1:]))
        left, right = prof.at_time(knots - eps), prof.at_time(knots + eps)
        j_max = max_abs_jerk(prof)
        j1_max = max(_max_jerk_rate(s) for s in prof.segments)
        jump_w = float(np.max(np.abs(right[1] - left[1] - 2 * eps * prof.at_time(knots)[2])))
        jump_a = float(np.max(np.abs(right[2] - left[2] - eps * (left[3] + right[3]))))
        add(
            CheckId.SPEED_CONTINUOUS,
            "crank speed continuous at knots",
            jump_w,
            0.0,
            "rad/s",
            "equal",
            CONTINUITY_TOL + 1e-14 * j_max,
        )
        add(
            CheckId.ACCEL_CONTINUOUS,
            "crank acceleration continuous at knots",
            jump_a,
            0.0,
            "rad/s^2",
            "equal",
            CONTINUITY_TOL + 1e-14 * j1_max,
        )
    # key angles and the transfer window
    key_t = plan.key_times()
    th_key = prof.at_time(key_t)[0]
    err = float(np.max(np.abs(th_key - np.array(plan.key_angles))))
    add(CheckId.KEY_ANGLES, "key angles reached", math.degrees(err), 0.0, "deg", "equal", math.degrees(ANGLE_TOL))
    t1, t2, t3, t4 = key_t
    add(
        CheckId.TRANSFER_TIME,
        "transfer time theta4 -> theta1",
        t1 + P - t4,
        case.process.transfer_time_s,
        "s",
        "min",
        TIME_TOL,
    )
    window = (t >= t4) | (t <= t1)
    add(
        CheckId.SAFETY_HEIGHT,
        "slider at or above the safety height from theta4 to theta1",
        float(np.min(h[window])),
        case.process.safety_height_mm,
        "mm",
        "min",
        REL_TOL * case.process.safety_height_mm,
    )
    # the draw at constant speed
    draw = (t >= t2) & (t <= t3)
    w2 = float(plan.parameters.draw_speed)
    add(
        CheckId.DRAW_CONSTANT,
        "draw at constant crank speed",
        float(np.max(np.abs(om[draw] - w2))) / RPM,
        0.0,
        "rpm",
        "equal",
        SPEED_TOL / RPM,
    )
    v2 = abs(float(machine.slider(plan.key_angles[1], w2)[1]))
    add(
        CheckId.DRAW_START_SPEED,
        "slider speed at the draw start",
        v2,
        lim.draw_start_speed_mm_s,
        "mm/s",
        "max",
        REL_TOL * lim.draw_start_speed_mm_s,
    )
    low = h <= lim.die_height_mm
    crossings = [float(x) for x in machine.angles_at_height(min(lim.die_height_mm, machine.stroke))]
    v_cross = [abs(s) for s in _slider_speed_at_angles(plan, case, crossings)]
    v_die = max(([float(np.max(np.abs(v[low])))] if low.any() else [0.0]) + v_cross)
    add(
        CheckId.DIE_SPEED,
        "slider speed at or below the die height",
        v_die,
        lim.die_speed_mm_s,
        "mm/s",
        "max",
        REL_TOL * lim.die_speed_mm_s,
    )
    add(
        CheckId.SLIDER_ACCEL,
        "|slider acceleration|",
        float(np.max(np.abs(a))),
        lim.slider_accel_mm_s2,
        "mm/s^2",
        "max",
        REL_TOL * lim.slider_accel_mm_s2,
    )
    motor = (
        (CheckId.CRANK_SPEED, "crank speed <= crank_speed_rpm", lim.crank_speed_rpm, float(np.max(om)) / RPM, "rpm"),
        (
            CheckId.CRANK_ACCEL,
            "|crank acceleration| <= crank_accel_rad_s2",
            lim.crank_accel_rad_s2,
            float(np.max(np.abs(al))),
            "rad/s^2",
        ),
        (CheckId.CRANK_JERK, "|crank jerk| <= crank_jerk_rad_s3", lim.crank_jerk_rad_s3, max_abs_jerk(prof), "rad/s^3"),
    )
    for check_id, name, limit, value, unit in motor:
        if limit is not None:
            add(check_id, name, value, limit, unit, "max", REL_TOL * limit)
    add(
        CheckId.MIN_CRANK_SPEED,
        "crank speed (forward, never stops)",
        float(np.min(om)) / RPM,
        lim.min_crank_speed_rpm,
        "rpm",
        "min",
        REL_TOL * lim.min_crank_speed_rpm,
    )
    if case.drive is not None:
        _drive_checks(add, plan, case, th, om, al)
    return Verification(tuple(checks), float(np.max(np.diff(t))), int(t.size))


def _drive_checks(add, plan: Plan, case: Case, th, om, al) -> None:  # noqa: ANN001 - the add() of verify
    """The motor's limits on the dense grid, its RMS torque and the energy balance by quadrature
    (``planning.model.drive``)."""
    from planning.model.drive import cycle_integrals
    from press.dynamics import drive_state, envelope_torque

    motor = case.drive.motor
    s = drive_state(th, om, al, case.press.crank_radius_mm, case.press.rod_length_mm, case.drive_model)
    envelope = envelope_torque(s["motor_speed_rad_s"], motor.peak_torque_Nm, motor.base_speed_rpm * RPM)
    use = float(np.max(np.abs(s["motor_torque_Nm"]) / envelope))
    add(CheckId.MOTOR_PEAK, "motor peak torque", use, 1.0, "of the envelope", "max", REL_TOL)
    top = float(np.max(s["motor_speed_rad_s"])) / RPM
    add(CheckId.MOTOR_SPEED, "motor speed", top, motor.max_speed_rpm, "rpm", "max", REL_TOL * motor.max_speed_rpm)
    fig = cycle_integrals(plan.profile, case)
    rated = motor.rated_torque_Nm
    add(CheckId.MOTOR_RMS, "motor RMS torque", fig["rms_motor_torque_Nm"], rated, "N m", "max", REL_TOL * rated)
    scale = max(abs(fig["forming_work_kJ"]), fig["crank_work_abs_kJ"])
    add(
        CheckId.ENERGY_BALANCE,
        "energy balance: crank work = forming work",
        fig["crank_work_kJ"],
        fig["forming_work_kJ"],
        "kJ",
        "equal",
        ENERGY_REL_TOL * scale,
    )


def max_abs_jerk(prof) -> float:
    """Largest |crank jerk| [rad/s^3]: at a segment's ends where the jerk is linear; for a shaped
    segment the closed-form peak of its whole half (``|dv| / D^2`` times the shape's peak), which a
    piece cut off at TDC may not reach, so the check errs on the safe side."""
    out = 0.0
    for s in prof.segments:
        j = max(abs(float(s.j0)), abs(float(s.j0) + float(s.j1) * float(s.duration)))
        if s.shape is not None:
            j += abs(float(s.dv)) / float(s.span) ** 2 * float(s.shape.peak_jerk())
        out = max(out, j)
    return out


def _max_jerk_rate(seg) -> float:
    """A bound on |d jerk / dt| [rad/s^4] inside ``seg`` (for the continuity remainder): ``j1`` of the
    linear part plus, for a shape, twice the largest finite-difference slope of its jerk on 400 steps."""
    rate = abs(float(seg.j1))
    if seg.shape is not None:
        u = np.linspace(0.0, 1.0, 401)
        s2 = np.asarray(seg.shape.terms(u)[3], dtype=float)
        rate += 2 * abs(float(seg.dv)) / float(seg.span) ** 3 * float(np.max(np.abs(np.diff(s2)) / np.diff(u)))
    return rate


def _slider_speed_at_angles(plan: Plan, case: Case, angles: list[float]) -> list[float]:
    """Slider speed [mm/s] where the crank passes each of ``angles`` [rad]."""
    out = []
    for ang in angles:
        tt = plan.profile.time_at_angle(ang)
        th, om, al, je = plan.profile.at_time(np.array([tt]))
        out.append(float(case.machine.slider(th, om, al, je)[1][0]))
    return out
