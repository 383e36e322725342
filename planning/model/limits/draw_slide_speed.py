"""A draw at constant slide speed (``process.draw_slide_speed_mm_s`` = v): from theta2 to theta3 the slide moves
no faster than v, ``|dh/dtheta omega| <= v``, and the optimal law, planning for the most strokes, drives it at v
wherever the crank's own limits let it (near BDC ``dh/dtheta -> 0`` asks ``omega = v / |dh/dtheta| -> inf``: the
crank's speed, acceleration and jerk limits cap it there).

A speed cap ``k = h'`` over the draw's crank angles (not a height zone): the NLP's rows at the free draw's samples
(refined against the dense check, like the slider's speed), the dense check over theta2 ... theta3, the bound's
cap ``(v / |h'|)^2`` at the draw's nodes. How far the plan holds v (within :data:`~planning.tolerances.
DRAW_SPEED_BAND`) is the reports' (:func:`held_band`), not a limit: the crank's limits decide it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.limits.base import BoundMesh, Check, Dense, Draw, Impossible, Limit, Row, Transcription, runs
from planning.tolerances import ANGLE_TOL_RAD, DRAW_SPEED_BACKOFF, DRAW_SPEED_BAND, LIMIT_REL_TOL


def in_draw(case: Any, theta: np.ndarray) -> np.ndarray:
    """Whether each crank angle ``theta`` [rad] (any turn) lies in the draw, theta2 ... theta3, its ends included
    to :data:`~planning.tolerances.ANGLE_TOL_RAD` (the sample at a key point's time lies on it to round-off)."""
    _, th2, th3, _ = case.key_angles
    turn = np.mod(np.asarray(theta, dtype=float), 2 * math.pi)
    return (turn >= th2 - ANGLE_TOL_RAD) & (turn <= th3 + ANGLE_TOL_RAD)


def held_band(case: Any, theta: np.ndarray, speed: np.ndarray) -> tuple[int, int] | None:
    """``(first, last)``: the indices of the longest run of samples in the draw (at the crank angles ``theta``, in
    time order) whose ``|speed|`` [mm/s] stays within :data:`~planning.tolerances.DRAW_SPEED_BAND` of the set
    slide speed; None where none does."""
    v = case.process.draw_slide_speed_mm_s
    held = in_draw(case, theta) & (np.abs(speed) >= v * (1 - DRAW_SPEED_BAND))
    stretches = [run for run in runs(held) if run[1] > run[0]]  # a run of one sample is no stretch
    return max(stretches, key=lambda run: run[1] - run[0]) if stretches else None


class DrawSlideSpeedLimit(Limit):
    """``|dh/dtheta omega| <= v`` over the draw (module docstring)."""

    id = "draw_slide_speed"
    name = "slide speed in the draw"
    unit = "mm/s"
    field = "process.draw_slide_speed_mm_s"
    order = 46
    parameters = ("draw_slide_speed",)
    refined = "draw_slide_speed"
    backoff = DRAW_SPEED_BACKOFF

    def applies(self, case: Any) -> bool:
        return case.process.draw_slide_speed_mm_s is not None

    def limit(self, case: Any) -> float:
        return case.process.draw_slide_speed_mm_s

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"draw_slide_speed": case.process.draw_slide_speed_mm_s * (1 - self.backoff)}

    def rows(self, nlp: Transcription) -> list[Row]:
        if not nlp.free_draw_count:
            return []
        speed = nlp.in_free_draw(nlp.slope * nlp.omega)
        return [Row("slide speed in the draw", speed / nlp.param("draw_slide_speed"), -1.0, 1.0, sampled=True)]

    def check(self, dense: Dense) -> list[Check]:
        case = dense.case
        inside = in_draw(case, dense.theta)
        speed = np.abs(dense.v[inside])
        limit = self.limit(case)
        value = float(np.max(speed)) if speed.size else 0.0
        check = Check.of(self.id, self.name, value, limit, self.unit, "max", LIMIT_REL_TOL * limit)
        return [check.located(dense.t[inside], dense.theta[inside], speed, limit)]

    def bound_speeds(self, mesh: BoundMesh) -> tuple[np.ndarray | None, np.ndarray | None]:
        """``(v / |h'|)^2`` at the draw's nodes where the slide moves."""
        n = mesh.dtheta.size
        k = np.abs(mesh.d1[:-1])
        inside = in_draw(mesh.case, mesh.theta[:-1]) & (k > 0)
        upper = np.full(n, np.inf)
        upper[inside] = (self.limit(mesh.case) / k[inside]) ** 2
        return None, upper

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        """The crank never slower than its least speed: the slide then moves at least ``w_min |h'|``, which
        must stay within v where the draw's ``|h'|`` is largest."""
        draw = Draw.of(case)
        k = int(np.argmax(np.abs(draw.d1)))
        slowest = lowest * abs(float(draw.d1[k]))
        v = self.limit(case)
        if slowest <= v:
            return None
        reason = (
            f"{self.field} = {v:g} is below the {slowest:.4g} mm/s the slide moves at "
            f"{math.degrees(draw.theta[k]):.2f} deg with the crank at limits.min_crank_speed_rpm = "
            f"{case.limits.min_crank_speed_rpm:g}"
        )
        return Impossible(reason, self.field, v, slowest, math.degrees(draw.theta[k]))

    def relaxed_rows(self, mesh: Any) -> list[tuple[Any, Any, Any]] | None:
        """Left out of the certified upper bound (which stays an upper bound, looser)."""
        return None
