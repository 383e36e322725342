"""A proved cam as the controllers' files take it: what every cam output shares (the slave, the numbers'
notation, the header that says what the file holds and what its proof found).

The slave is the crank's angle [deg], or where the case has a drive the motor's (the crank's times the gear
ratio: ``--cam-slave motor``, its default there); the master is 0 .. 360 deg per stroke, both ends given
(the end, 360 deg, is the start a turn on: the slave 360 deg (times the ratio) further, the same slope and
curvature). Every figure of the proof is the run cam's (``planning.solver.cam_proof``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from planning.model.cam import Cam, Interpolation
from planning.model.case import Case
from planning.reports.outputs._cam import CRANK, FORMATS, MOTOR, CamOptionError
from planning.solver.cam_proof import OVERRIDE_STEP, SPEED_RESOLUTION, CamProof, CamSpec, cam_for, motor_cam, slide_at
from planning.solver.outcomes import Unverified

if TYPE_CHECKING:
    from planning.reports.outputs import Written


@dataclass(frozen=True)
class CamExport:
    """A ``proof``'s cam for a ``case`` with its ``slave`` (``crank`` or ``motor``)."""

    proof: CamProof
    case: Case
    slave: str = CRANK

    @property
    def ratio(self) -> float:
        """Slave degrees per crank degree: the gear ratio for the motor, else 1."""
        return float(self.case.drive.gear_ratio) if self.slave == MOTOR else 1.0

    @cached_property
    def cam(self) -> Cam:
        """The cam with its slave (the motor's angle: every slave value times the ratio)."""
        return motor_cam(self.proof.cam, self.ratio) if self.slave == MOTOR else self.proof.cam

    @cached_property
    def slide_mm(self) -> np.ndarray:
        """The slide's height [mm above BDC] at the cam's points."""
        return slide_at(self.proof.cam, self.case)

    @property
    def master_speed_deg_s(self) -> float:
        """The master's speed the cam was proved at [deg/s]."""
        return 360.0 / self.proof.plan.period * self.proof.speed

    @property
    def spm(self) -> float:
        """Strokes per minute at that master speed."""
        return self.proof.plan.spm * self.proof.speed

    @property
    def slave_name(self) -> str:
        return f"{self.slave}_angle_deg"

    def header_lines(self) -> list[str]:
        """What the file holds and what the proof found, one statement a line (no comment marks)."""
        p, cam = self.proof, self.cam
        kind = {
            Interpolation.POLY5: "XYVA points, a fifth-order polynomial between two (Y, dY/dX, d2Y/dX2 at both ends)",
            Interpolation.SPLINE: "points, the periodic cubic spline through them (C2)",
            Interpolation.LINEAR: "points, straight lines between them",
        }[cam.interpolation]
        slave = "crank angle" if self.slave == CRANK else f"motor angle (crank angle x gear ratio {self.ratio:g})"
        swing = cam.slave_turn_deg == 0.0  # a pendulum cycle: the slave back where it started
        master = (
            "master: 0 .. 360 deg per cycle of two swings, two strokes (0 = the forward swing's start, at rest)"
            if swing
            else "master: 0 .. 360 deg per stroke (0 = TDC)"
        )
        turn = "back where it started" if swing else "360 deg (x ratio) on"
        lines = [
            f"pressplan cam for {self.case.name}: {cam.points} {kind}",
            f"{master}; slave: {slave} [deg], 0 at TDC",
            f"master speed {self.master_speed_deg_s:.6f} deg/s = {self.spm:.6f} strokes/min "
            f"({100 * p.speed:.2f} % of the plan's {p.plan.spm:.6f})",
            f"ends: both given; at 360 deg the slave is {turn}, the same slope and curvature "
            + ("(continuous across the end)" if p.ends_join else "(the slope steps there as at every point)"),
            f"proof: run as the controller interpolates it, every limit of the case "
            f"{'holds' if p.passed else 'does NOT hold'}; slide within {_mm(p.deviation_mm)} of the plan "
            f"(crank within {p.deviation_deg:.3g} deg)",
            f"highest master speed with every limit held: {_override(p)}",
        ]
        return lines


def proof_dict(export: CamExport) -> dict:
    """The proof as ``cam_proof.json`` writes it: the cam, the master speed, the deviation, the ends, the
    highest master speed and every check with its margin."""
    p = export.proof
    above = None
    if p.above is not None:
        above = {
            "speed_pct": 100 * p.highest_speed * (1 + OVERRIDE_STEP),
            "passed": p.above.passed,
            "failures": [c.id for c in p.above.failures()],
        }
    return {
        "case": export.case.name,
        "interpolation": p.cam.interpolation.value,
        "points": p.cam.points,
        "slave": export.slave,
        "slave_per_crank_deg": export.ratio,
        "plan_spm": p.plan.spm,
        "speed_pct": 100 * p.speed,
        "master_speed_deg_s": export.master_speed_deg_s,
        "passed": p.passed,
        "deviation_mm": p.deviation_mm,
        "deviation_deg": p.deviation_deg,
        "end_steps": dict(zip(("deg", "slope", "curvature"), p.end_steps, strict=True)),
        "ends_join": p.ends_join,
        "highest_speed_pct": override_pct(p),
        "above": above,
        "checks": [{**c.as_dict(), "margin": c.margin} for c in p.evaluation.verification.checks],
    }


def proof_lines(export: CamExport) -> list[str]:
    """The proof for people: the header's statements and each limit's margin (the command's summary)."""
    p = export.proof
    lines = export.header_lines()[:1] + export.header_lines()[2:]
    for c in p.evaluation.verification.checks:
        state = "PASS" if c.passed else "FAIL"
        lines.append(f"  {state}  {c.name}: {c.value:.6g} {c.unit} (limit {c.limit:.6g}, margin {c.margin:+.4g})")
    return lines


def _mm(value: float) -> str:
    return f"{value:.3g} mm"


def _override(proof: CamProof) -> str:
    """The highest master speed as a percentage of the plan's, and what breaks just above it."""
    if proof.highest_speed <= 0.0:
        return "none from 10 % of the proved speed up"
    pct = override_pct(proof)
    if proof.above is None:
        return f"at least {pct:.2f} % of the plan's"
    broken = ", ".join(c.name for c in proof.above.failures()[:2])
    return f"{pct:.2f} % of the plan's (1 % above it: {broken})"


def override_pct(proof: CamProof) -> float:
    """The highest master speed, a percentage of the plan's, rounded down to 0.01 %."""
    return math.floor(100 * proof.highest_speed * 100) / 100


def export_of(w: Written) -> CamExport | None:
    """The proved cam the options ask for (None without ``--cam``); :class:`CamOptionError` for options that
    do not go together, ``planning.solver.outcomes.Unverified`` for a cam that breaks a limit."""
    targets = w.option("cam")
    if not targets:
        return None
    spec, slave = spec_of(w)
    proof = cam_for(w.solution.plan, w.case, spec)
    export = CamExport(proof, w.case, slave)
    if not proof.passed:
        check = proof.failure()
        raise Unverified(refusal(export), check)
    return export


def spec_of(w: Written):  # noqa: ANN201 - a (CamSpec, slave) pair
    """The :class:`~planning.solver.cam_proof.CamSpec` and the slave of the options (checked together)."""
    interpolation = Interpolation(w.option("cam_interpolation"))
    for target in w.option("cam"):
        if interpolation not in FORMATS[target]:
            takes = " or ".join(i.value for i in FORMATS[target])
            raise CamOptionError("--cam-interpolation", f"{target} takes {takes} cams, not {interpolation.value}")
    slave = w.option("cam_slave") or (MOTOR if w.case.drive is not None else CRANK)
    if slave == MOTOR and w.case.drive is None:
        raise CamOptionError("--cam-slave", "motor: the case has no drive: (add a drive: section with its gear_ratio)")
    count, tolerance = w.option("cam_count"), w.option("cam_tolerance_mm")
    if tolerance is not None and interpolation is not Interpolation.POLY5:
        raise CamOptionError("--cam-tolerance-mm", "places XYVA points (--cam-interpolation poly5)")
    if tolerance is not None and count != "auto":
        raise CamOptionError("--cam-tolerance-mm", "give it or --cam-count, not both")
    spec = CamSpec(
        interpolation,
        None if count == "auto" else int(count),
        tolerance,
        w.option("cam_speed_pct") / 100.0,
        w.option("cam_cycle_ms") / 1000.0,
    )
    return spec, slave


def refusal(export: CamExport) -> str:
    """Why a cam is not written: the limit it breaks at the proved speed, by how much, and where it would hold."""
    p = export.proof
    check = p.failure()
    cam = f"the {p.cam.interpolation.value} cam of {p.cam.points} points"
    broken = f"{check.name} = {check.value:.6g} {check.unit} (limit {check.limit:.6g})"
    where = (
        f"it holds up to {100 * p.highest_speed:.2f} % of the plan's master speed (--cam-speed)"
        if p.highest_speed > 0
        else "it holds at no master speed searched"
    )
    remedy = "more points" if p.cam.interpolation is Interpolation.POLY5 else "more points, or poly5"
    if p.highest_speed >= 1.0 - SPEED_RESOLUTION:  # it holds at the plan's own speed: the master asked is too fast
        remedy = f"run it at most {100 * p.highest_speed:.2f} % (--cam-speed)"
    return f"{cam} breaks {broken} at {100 * p.speed:.2f} % of the plan's master speed; {where}; {remedy}"
