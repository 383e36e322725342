"""The motor's limits (all motors together, a case with a ``drive:`` section): its top speed, its peak-torque
envelope and its rated (RMS) torque. The drive model and its signs: ``press.dynamics``."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.errors import CaseError
from planning.model.limits.base import (
    BoundMesh,
    Check,
    Dense,
    Impossible,
    Limit,
    RelaxedMesh,
    Row,
    Transcription,
    trapezoid,
)
from planning.model.limits.canonical import SpeedCap
from planning.model.units import RPM
from planning.tolerances import DRIVE_BACKOFF, LIMIT_REL_TOL, RMS_PROOF_MARGIN, SAME_ANGLE_RAD
from press.backend import math_module
from press.dynamics import GRAVITY, drive_state, envelope_torque, forming_force, link_terms


class MotorSpeedLimit(SpeedCap):
    """motor speed = gear ratio x crank speed <= ``drive.motor.max_speed_rpm`` (a speed cap, ``k`` = the gear
    ratio): a top crank speed, held like ``limits.crank_speed_rpm`` (in every NLP of a drive case, the
    kinematic one too; a given draw speed above it is an error in the case)."""

    id = "motor_speed"
    name = "motor speed"
    unit = "rpm"
    field = "drive.motor.max_speed_rpm"
    order = 52
    parameters = ("motor_top_crank_speed",)
    refined = "motor_top_crank_speed"
    motor = True
    unit_divisor = RPM

    def applies(self, case: Any) -> bool:
        return case.drive is not None

    def validate(self, case: Any) -> None:
        d = case.drive
        if d is None:
            return
        through_gear = case.limits.min_crank_speed_rpm * d.gear_ratio
        if through_gear >= d.motor.max_speed_rpm:
            raise CaseError(
                self.field,
                f"must be above the minimum crank speed through the gear ({through_gear:g} rpm)",
                d.motor.max_speed_rpm,
            )

    def top_crank_speed(self, case: Any) -> float | None:
        return None if case.drive is None else _top_crank_speed(case)

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"motor_top_crank_speed": _top_crank_speed(case)}

    def rows(self, nlp: Transcription) -> list[Row]:
        peaks = nlp.speeds
        return [Row("motor speed", peaks.values / nlp.param("motor_top_crank_speed"), -np.inf, 1.0, peaks.sampled)]

    def limit(self, case: Any) -> float:
        return case.drive.motor.max_speed_rpm

    def crank_factor(self, case: Any) -> float:
        return case.drive.gear_ratio


def _top_crank_speed(case: Any) -> float:
    """The motor's top speed on the crank [rad/s]."""
    return case.drive.motor.max_speed_rpm * RPM / case.drive.gear_ratio


class MotorPeakTorqueLimit(Limit):
    """|motor torque| <= the peak-torque envelope at the motor's speed (the peak up to the base speed,
    constant power above it): ``|T_m| max(1, n / n_base) <= peak`` at every sample of a drive NLP, as one
    row (kink at the base speed; the base speed is the drive model's parameter ``motor_base_speed``); on
    the dense grid; in the bound, the two linear forms whose larger is the motor torque, driving side."""

    id = "motor_peak_torque"
    name = "motor peak torque"
    unit = "of the envelope"
    field = "drive.motor.peak_torque_Nm"
    order = 90
    precheck_at_one_draw_speed = True
    parameters = ("motor_peak",)
    refined = "motor_peak"
    backoff = DRIVE_BACKOFF
    motor = True
    uses_drive = True

    def applies(self, case: Any) -> bool:
        return case.drive is not None

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """At constant speed the draw needs the most torque where the forming force acts on the longest
        lever: the motor cannot make the draw even at the lowest draw speed the case allows."""
        motor = case.drive.motor
        w2 = given if given is not None else lowest
        theta, state = draw_drive_state(case, w2)
        envelope = envelope_torque(state["motor_speed_rad_s"], motor.peak_torque_Nm, motor.base_speed_rpm * RPM)
        use = np.abs(state["motor_torque_Nm"]) / envelope
        k = int(np.argmax(use))
        if use[k] <= 1.0:
            return None
        needed = float(abs(state["motor_torque_Nm"][k]))
        return Impossible(
            f"{self.field} = {motor.peak_torque_Nm:g} cannot make the draw: at "
            f"{math.degrees(theta[k]):.1f} deg and {w2 / RPM:.3g} rpm the motors must give {needed:.0f} N m"
            + (f" ({100 * use[k]:.0f} % of the envelope at that speed)" if envelope[k] < motor.peak_torque_Nm else ""),
            self.field,
            motor.peak_torque_Nm,
            needed,
            math.degrees(theta[k]),
        )

    def parameter_values(self, case: Any) -> dict[str, float]:
        motor = case.drive.motor
        return {"motor_peak": motor.peak_torque_Nm * (1 - self.backoff)}

    def rows(self, nlp: Transcription) -> list[Row]:
        above_base = math_module(nlp.motor_speed).fmax(1.0, nlp.motor_speed / nlp.param("motor_base_speed"))
        return [Row("motor peak torque", nlp.motor_torque * above_base / nlp.param("motor_peak"), -1.0, 1.0, True)]

    def check(self, dense: Dense) -> list[Check]:
        motor = dense.case.drive.motor
        s = dense.drive_state
        envelope = envelope_torque(s["motor_speed_rad_s"], motor.peak_torque_Nm, motor.base_speed_rpm * RPM)
        use = np.abs(s["motor_torque_Nm"]) / envelope
        check = Check.of(self.id, self.name, float(np.max(use)), 1.0, self.unit, "max", LIMIT_REL_TOL)
        return [check.located(dense.t, dense.theta, use, 1.0)]

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        """Motor torque at both ends of every interval, as the two linear forms whose larger is the motor
        torque: ``T_c / (i eta) + J_m i alpha`` and ``T_c eta / i + J_m i alpha``, with ``T_c`` linear in s and
        alpha (``press.dynamics``, a linkage's links included). Both <= peak is exactly ``T_m <= peak``. The
        forming force is taken on each interval's side of theta2 and BDC."""
        d = mesh.case.drive_model
        peak = mesh.case.drive.motor.peak_torque_Nm
        n = mesh.dtheta.size
        rows = []
        for tc in crank_torque_at_ends(mesh):
            for form in (tc / (d.i * d.eta) + d.J_m * d.i * mesh.alpha, tc * d.eta / d.i + d.J_m * d.i * mesh.alpha):
                rows.append((form, np.full(n, -np.inf), np.full(n, peak)))
        return rows


def crank_torque_at_ends(mesh: BoundMesh) -> list[Any]:
    """The crank torque [N m] at the start and at the end of every interval of the bound's mesh, linear in the
    speed squared there and the interval's acceleration (``press.dynamics``, a linkage's links included); the
    forming force taken on each interval's side of theta2 and BDC."""
    case = mesh.case
    d, m = case.drive_model, case.machine
    out = []
    for theta, speed2 in ((mesh.theta[:-1] + SAME_ANGLE_RAD, mesh.s), (mesh.theta[1:] - SAME_ANGLE_RAD, mesh.s_next)):
        h, d1, d2, _ = m.jets(theta)
        d1, d2 = d1 * 1e-3, d2 * 1e-3
        f_env = forming_force(theta, h, d) + d.F_cb - d.M * GRAVITY
        J, dJ, weight = link_terms(m.frames(theta), d.links) if d.links else (0.0, 0.0, 0.0)
        out.append((d.J0 + d.M * d1**2 + J) * mesh.alpha + (d.M * d1 * d2 + 0.5 * dJ) * speed2 - f_env * d1 + weight)
    return out


class MotorRMSTorqueLimit(Limit):
    """The RMS motor torque over the cycle <= ``drive.motor.rated_torque_Nm`` (the motors' heat). A drive
    NLP integrates ``T_m^2`` by the trapezoidal rule over its samples, which can overstate the exact
    integral (the search then loosens its row once by the measured room); the verification integrates by
    quadrature (``planning.model.drive``). The bound does not take it (it is not a limit at a crank angle)."""

    id = "motor_rms_torque"
    name = "motor RMS torque"
    unit = "N m"
    field = "drive.motor.rated_torque_Nm"
    order = 100
    parameters = ("motor_rms",)
    refined = "motor_rms"
    backoff = DRIVE_BACKOFF
    overestimated = True
    motor = True
    uses_drive = True

    def applies(self, case: Any) -> bool:
        return case.drive is not None

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """The draw alone gives ``integral T_m^2 dt = integral T_m^2 dtheta / w2``, and no cycle is longer
        than one turn at the minimum crank speed, so ``RMS^2 >=`` that integral over ``2 pi / w_min``."""
        if given is None:
            return None
        motor = case.drive.motor
        theta, state = draw_drive_state(case, given)
        sq = state["motor_torque_Nm"] ** 2
        draw_heat = float(np.sum(np.diff(theta) * (sq[1:] + sq[:-1]) / 2)) / given
        longest = 2 * math.pi / (case.limits.min_crank_speed_rpm * RPM)
        least_rms = math.sqrt(draw_heat / longest)
        if least_rms <= motor.rated_torque_Nm * (1 + RMS_PROOF_MARGIN):
            return None
        return Impossible(
            f"{self.field} = {motor.rated_torque_Nm:g} cannot be met: the draw alone at "
            f"{given / RPM:.3g} rpm gives an RMS torque of at least {least_rms:.0f} N m over the longest cycle "
            f"limits.min_crank_speed_rpm = {case.limits.min_crank_speed_rpm:g} allows ({longest:.1f} s)",
            self.field,
            motor.rated_torque_Nm,
            least_rms,
        )

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"motor_rms": case.drive.motor.rated_torque_Nm * (1 - self.backoff)}

    def rows(self, nlp: Transcription) -> list[Row]:
        heat = trapezoid(nlp.motor_torque**2, nlp.times)
        return [Row("motor RMS torque", heat / (nlp.period * nlp.param("motor_rms") ** 2), -np.inf, 1.0, True)]

    def check(self, dense: Dense) -> list[Check]:
        rated = dense.case.drive.motor.rated_torque_Nm
        rms = dense.integrals["rms_motor_torque_Nm"]
        return [Check.of(self.id, self.name, rms, rated, self.unit, "max", LIMIT_REL_TOL * rated)]

    def relaxed_rows(self, mesh: RelaxedMesh) -> None:
        """Not in the upper bound (the RMS of a cycle is no condition at an angle): left out."""
        return None


def draw_drive_state(case: Any, w2: float) -> tuple[np.ndarray, dict]:
    """The drive's state through the draw at constant speed ``w2`` [rad/s] (2001 angles theta2 .. theta3)."""
    _, th2, th3, _ = case.key_angles
    theta = np.linspace(th2, th3, 2001)
    state = drive_state(theta, np.full_like(theta, w2), np.zeros_like(theta), case.machine, case.drive_model)
    return theta, state
