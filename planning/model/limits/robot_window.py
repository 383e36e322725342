"""The robot's window: from theta4 to theta1 (through TDC) the slide stays at or above the safety height,
for at least the transfer time. Two limits, one case field each."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.errors import CaseError
from planning.model.limits.base import (
    BoundMesh,
    Check,
    Dense,
    Draw,
    Impossible,
    Limit,
    RelaxedMesh,
    Row,
    Transcription,
    total,
)
from planning.model.units import RPM
from planning.tolerances import LIMIT_REL_TOL, TIME_TOL_S


class TransferTimeLimit(Limit):
    """The time from theta4 to theta1 through TDC is at least ``process.transfer_time_s``."""

    id = "transfer_time"
    name = "transfer time theta4 -> theta1"
    unit = "s"
    field = "process.transfer_time_s"
    order = 10
    parameters = ("transfer_time",)

    def applies(self, case: Any) -> bool:
        return case.robots is None  # the robots' interference curves replace the window (``robots``)

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"transfer_time": case.process.transfer_time_s}

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """The window's angle crossed at the minimum crank speed takes the longest any motion can take."""
        th1, _, _, th4 = case.key_angles
        window = th1 + 2 * math.pi - th4
        w_min = case.limits.min_crank_speed_rpm * RPM
        if window / w_min >= case.process.transfer_time_s:
            return None
        return Impossible(
            f"process.transfer_time_s = {case.process.transfer_time_s:g} cannot be met: at "
            f"limits.min_crank_speed_rpm = {case.limits.min_crank_speed_rpm:g} the crank crosses the "
            f"{math.degrees(window):.1f} deg from theta4 to theta1 in at most {window / w_min:.3f} s",
            self.field,
            case.process.transfer_time_s,
            window / w_min,
        )

    def rows(self, nlp: Transcription) -> list[Row]:
        return [Row("transfer time", nlp.window_time - nlp.param("transfer_time"), 0.0, np.inf)]

    def check(self, dense: Dense) -> list[Check]:
        t1, _, _, t4 = dense.key_times
        window = t1 + dense.plan.period - t4
        return [Check.of(self.id, self.name, window, dense.case.process.transfer_time_s, self.unit, "min", TIME_TOL_S)]

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        window = np.flatnonzero(mesh.window).tolist()
        return [(total(mesh.tau[window]), mesh.case.process.transfer_time_s, np.inf)]

    def relaxed_rows(self, mesh: RelaxedMesh) -> list[tuple[Any, Any, Any]]:
        """The window's intervals' times add up as in the grid bound (each at least the motion's)."""
        return self.bound_rows(mesh)


class SafetyHeightLimit(Limit):
    """From theta4 to theta1 the slide is at or above ``process.safety_height_mm`` (the transfer robot's
    safety height)."""

    id = "safety_height"
    name = "slider at or above the safety height from theta4 to theta1"
    unit = "mm"
    field = "process.safety_height_mm"
    order = 11

    def applies(self, case: Any) -> bool:
        return case.robots is None

    def validate(self, case: Any) -> None:
        if not self.applies(case):
            return
        m = case.machine
        safety = case.process.safety_height_mm
        if safety > m.stroke:
            raise CaseError(self.field, f"is above the stroke {m.stroke:g} mm", safety)
        for key in ("closing_deg", "opening_deg"):
            deg = getattr(case.key_points, key)
            h = float(m.height(math.radians(deg)))
            if h < safety:
                raise CaseError(
                    f"key_points.{key}", f"slider is at {h:.1f} mm there, below {self.field} = {safety:g}", deg
                )

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        """The lowest slide position over the whole window theta4 -> TDC -> theta1, not only its ends."""
        case = draw.case
        lowest, angle = lowest_in_window(case)
        th1, _, _, th4 = (math.degrees(a) for a in case.key_angles)
        name = (
            f"lowest slider height from opening {th4:g} deg through TDC to closing {th1:g} deg "
            f"(at {math.degrees(angle):.1f} deg) >= safety height"
        )
        return [Check.of(self.id, name, lowest, case.process.safety_height_mm, self.unit, "min", 0.0)]

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """The slide's path is fixed by the key angles: a window whose arc dips below the safety height
        cannot be met by any motion (a window that passes BDC: key angles in radians, as a rule)."""
        low, angle = lowest_in_window(case)
        safety = case.process.safety_height_mm
        if low >= safety:
            return None
        k = case.key_points
        reason = (
            f"key_points.opening_deg = {k.opening_deg:g} and key_points.closing_deg = {k.closing_deg:g}: from "
            f"opening through TDC to closing the crank turns {k.closing_deg + 360 - k.opening_deg:.1f} deg and "
            f"the slide goes down to {low:.1f} mm at {math.degrees(angle):.1f} deg, below {self.field} = "
            f"{safety:g}; the robot's window must stay above it{radians_hint(case)}"
        )
        return Impossible(reason, "key_points.opening_deg", k.opening_deg, None, math.degrees(angle))

    def check(self, dense: Dense) -> list[Check]:
        t1, _, _, t4 = dense.key_times
        window = (dense.t >= t4) | (dense.t <= t1)
        safety = dense.case.process.safety_height_mm
        th1, _, _, th4 = dense.plan.key_angles
        ends = dense.case.machine.height(np.array([th1, th4]))  # the window's ends, exactly (not a grid point)
        lowest = float(min(np.min(dense.h[window], initial=np.inf), np.min(ends)))
        return [Check.of(self.id, self.name, lowest, safety, self.unit, "min", LIMIT_REL_TOL * safety)]


def lowest_in_window(case: Any) -> tuple[float, float]:
    """The slide's lowest position over the robot's window, theta4 -> TDC -> theta1: ``(height [mm],
    crank angle [rad])``."""
    th1, _, _, th4 = case.key_angles
    return case.machine.lowest_on_arc(th4, th1 + 2 * math.pi)


RADIANS_HINT_DEG = 2 * math.pi  # [deg] key angles all below this were likely written in radians


def radians_hint(case: Any) -> str:
    """``"; the key angles look like radians (...)"`` when every key angle is below 2 pi degrees (the whole
    cycle in a few degrees of crank), else ``""``."""
    angles = [getattr(case.key_points, f) for f in ("closing_deg", "draw_start_deg", "draw_end_deg", "opening_deg")]
    if max(angles) >= RADIANS_HINT_DEG:
        return ""
    given = ", ".join(f"{a:g}" for a in angles)
    meant = ", ".join(f"{math.degrees(a):.1f}" for a in angles)
    return f"; the key angles look like radians: {given} rad are {meant} deg"
