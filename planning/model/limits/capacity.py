"""The press's own capacity as limits (``press.capacity``; the model and its equations: ``press.capacity``).

- :class:`TonnageLimit`: the forming force table (``process.forming_force_kN``) stays under the press's tonnage
  curve at every height of the draw. It is a property of the case, not of a motion: a table above the curve
  is refused when the case is read (one line naming ``process.forming_force_kN``), ``pressplan check`` lists
  its use of the curve, and the verification records it.
- :class:`CrankTorqueLimit`: the crank's torque (the drive model's, ``press.dynamics``: inertia, the forming
  force, gravity and the counterbalance) stays within the crank's torque capacity over the whole cycle, in a
  drive case: rows at every sample of a drive NLP, the dense check, the bound's rows at both ends of every
  interval (the crank torque is linear in the crank's acceleration and speed squared), a precheck at the
  draw. The certified upper bound leaves it out (stated).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.errors import CaseError
from planning.model.limits.base import BoundMesh, Check, Dense, Draw, Impossible, Limit, RelaxedMesh, Row, Transcription
from planning.model.units import RPM
from planning.tolerances import DRIVE_BACKOFF, LIMIT_REL_TOL
from press.capacity import rated_torque_kNm, tonnage_curve

TONNAGE_SAMPLES = 2001  # heights of the forming force table checked against the tonnage curve


def curve(case: Any) -> tuple[np.ndarray, np.ndarray]:
    """The case's tonnage curve: ``(heights [mm], allowed forces [kN])`` (``press.capacity.tonnage_curve``)."""
    c = case.press.capacity
    return tonnage_curve(case.machine, c.rated_force_kN, c.rated_distance_mm, c.force_table_kN)


def has_curve(case: Any) -> bool:
    """Whether the case states a tonnage curve (a rating or a table)."""
    c = case.press.capacity
    return c is not None and (c.force_table_kN is not None or c.rated_force_kN is not None)


def tonnage_use(case: Any) -> tuple[float, float, float, float]:
    """The forming force table against the tonnage curve: ``(largest force / allowed, height [mm], force
    [kN], allowed [kN])`` where the table comes closest to the curve (or passes it)."""
    table = sorted(case.process.forming_force_kN)
    heights = np.linspace(table[0][0], table[-1][0], TONNAGE_SAMPLES)
    force = np.interp(heights, [h for h, _ in table], [f for _, f in table])
    allowed = np.interp(heights, *curve(case))
    use = np.where(allowed > 0, force / np.maximum(allowed, 1.0), np.where(force > 0, np.inf, 0.0))
    k = int(np.argmax(use))
    return float(use[k]), float(heights[k]), float(force[k]), float(allowed[k])


class TonnageLimit(Limit):
    """The forming force table under the tonnage curve: ``F(h) <= F_allowed(h)`` at every height of the
    table (module docstring)."""

    id = "tonnage"
    name = "forming force within the press's tonnage curve"
    unit = "of the curve"
    field = "process.forming_force_kN"
    order = 5

    def applies(self, case: Any) -> bool:
        return has_curve(case) and case.process.forming_force_kN is not None

    def validate(self, case: Any) -> None:
        c = case.press.capacity
        if c is None:
            return
        if c.force_table_kN is None and (c.rated_force_kN is None) != (c.rated_distance_mm is None):
            missing = "rated_distance_mm" if c.rated_distance_mm is None else "rated_force_kN"
            raise CaseError(f"press.capacity.{missing}", "goes with the other rating key", None, False)
        if c.rated_distance_mm is not None and not 0 < c.rated_distance_mm < case.machine.stroke:
            raise CaseError(
                "press.capacity.rated_distance_mm",
                f"must lie above BDC, below the stroke {case.machine.stroke:g} mm",
                c.rated_distance_mm,
            )
        if c.crank_torque_kNm is None and c.rated_force_kN is None and c.force_table_kN is None:
            raise CaseError("press.capacity", "needs a rating, a tonnage curve or a crank torque capacity", None, False)
        if not self.applies(case):
            return
        use, h, force, allowed = tonnage_use(case)
        if use > 1 + LIMIT_REL_TOL:
            raise CaseError(
                self.field,
                f"asks {force:.0f} kN at {h:.1f} mm above BDC, above the press's tonnage curve there "
                f"({allowed:.0f} kN; press.capacity)",
                None,
                False,
            )

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        return [self._check(draw.case)]

    def check(self, dense: Dense) -> list[Check]:
        return [self._check(dense.case)]

    def _check(self, case: Any) -> Check:
        use, h, _, _ = tonnage_use(case)
        name = f"{self.name} (closest at {h:.1f} mm)"
        return Check.of(self.id, name, use, 1.0, self.unit, "max", LIMIT_REL_TOL)


def torque_capacity_kNm(case: Any) -> float | None:
    """The crank's torque capacity [kN m]: given, or the torque the rating implies (None: neither)."""
    c = case.press.capacity
    if c is None:
        return None
    if c.crank_torque_kNm is not None:
        return c.crank_torque_kNm
    if c.rated_force_kN is not None and c.rated_distance_mm is not None:
        return rated_torque_kNm(case.machine, c.rated_force_kN, c.rated_distance_mm)
    return None


class CrankTorqueLimit(Limit):
    """``|T_c| <= T_cap`` over the cycle, ``T_c`` the drive model's crank torque (module docstring)."""

    id = "crank_torque"
    name = "crank torque"
    unit = "kN m"
    field = "press.capacity.crank_torque_kNm"
    order = 85
    precheck_at_one_draw_speed = True
    parameters = ("crank_torque_cap",)
    refined = "crank_torque_cap"
    backoff = DRIVE_BACKOFF
    uses_drive = True
    motor = True  # held by the drive NLPs only: a plan of the kinematic NLP cannot be trusted to keep it

    def applies(self, case: Any) -> bool:
        return case.drive is not None and torque_capacity_kNm(case) is not None

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"crank_torque_cap": torque_capacity_kNm(case) * 1e3 * (1 - self.backoff)}

    def rows(self, nlp: Transcription) -> list[Row]:
        return [Row("crank torque", nlp.crank_torque / nlp.param("crank_torque_cap"), -1.0, 1.0, sampled=True)]

    def check(self, dense: Dense) -> list[Check]:
        cap = torque_capacity_kNm(dense.case)
        torque = np.abs(dense.drive_state["crank_torque_Nm"]) / 1e3
        check = Check.of(self.id, self.name, float(np.max(torque)), cap, self.unit, "max", LIMIT_REL_TOL * cap)
        return [check.located(dense.t, dense.theta, torque, cap)]

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        from planning.model.limits.motor import draw_drive_state

        case = draw.case
        if case.drive is None:
            return []
        _, state = draw_drive_state(case, speed)
        peak = float(np.max(np.abs(state["crank_torque_Nm"]))) / 1e3
        cap = torque_capacity_kNm(case)
        return [Check.of(self.id, f"{self.name} during the draw <= {self.field}", peak, cap, self.unit, "max", 0.0)]

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """At constant speed the draw needs the forming force's torque (and the slide's weight less the
        counterbalance): the crank cannot give it even at the lowest draw speed the case allows."""
        from planning.model.limits.motor import draw_drive_state

        w2 = given if given is not None else lowest
        theta, state = draw_drive_state(case, w2)
        torque = np.abs(state["crank_torque_Nm"]) / 1e3
        k = int(np.argmax(torque))
        cap = torque_capacity_kNm(case)
        if torque[k] <= cap * (1 + LIMIT_REL_TOL):
            return None
        return Impossible(
            f"the crank's torque capacity {cap:.1f} kN m ({self.field}, or the rating's) cannot make the draw: at "
            f"{math.degrees(theta[k]):.1f} deg and {w2 / RPM:.3g} rpm the crank must give {torque[k]:.1f} kN m",
            self.field,
            cap,
            float(torque[k]),
            math.degrees(theta[k]),
        )

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        """The crank torque at both ends of every interval, linear in the speed squared and the acceleration
        there (``press.dynamics``, a linkage's links included); the forming force on each interval's side of
        theta2 and BDC."""
        from planning.model.limits.motor import crank_torque_at_ends

        cap = torque_capacity_kNm(mesh.case) * 1e3
        n = mesh.dtheta.size
        return [(tc, np.full(n, -cap), np.full(n, cap)) for tc in crank_torque_at_ends(mesh)]

    def relaxed_rows(self, mesh: RelaxedMesh) -> None:
        """Not in the upper bound (its relaxation needs the drive's inertia along the whole interval): left out."""
        return None
