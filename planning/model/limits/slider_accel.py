"""The slide's acceleration stays within ``limits.slider_accel_mm_s2`` over the whole cycle."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pydantic import Field

from planning.model.limits.base import (
    BoundMesh,
    Check,
    Dense,
    Draw,
    Envelope,
    Impossible,
    Limit,
    RelaxedMesh,
    Row,
    Transcription,
)
from planning.model.units import SliderAccel
from planning.tolerances import ACCEL_BACKOFF, DEAD_CENTRE_SLOPE, HARDER_BACKOFF, LIMIT_REL_TOL, SAME_RELATIVE


class SliderAccelLimit(Limit):
    """|a| = |d2h/dtheta2 w^2 + dh/dtheta alpha| <= the limit: at every sample of an NLP (the dense check
    decides between them), in the draw (a bound on the draw speed), at both ends of every interval of
    the bound (linear in the speed squared there)."""

    id = "slider_accel"
    name = "|slider acceleration|"
    unit = "mm/s^2"
    field = "limits.slider_accel_mm_s2"
    order = 40
    section_fields = {
        "slider_accel_mm_s2": (
            SliderAccel,
            Field(
                ...,
                title="slide acceleration limit [mm/s²]",
                description="The slide's |acceleration| over the whole cycle.",
            ),
        ),
    }
    parameters = ("accel_limit",)
    refined = "accel_limit"
    backoff = ACCEL_BACKOFF
    harder_backoff = HARDER_BACKOFF

    def draw_speed_bound(self, draw: Draw) -> float:
        curvature = float(np.max(np.abs(draw.d2)))
        return math.sqrt(draw.case.limits.slider_accel_mm_s2 / curvature) if curvature > 0 else math.inf

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        limit = draw.case.limits.slider_accel_mm_s2
        value = limit * (speed / self.draw_speed_bound(draw)) ** 2
        name = "|slider acceleration| during the draw <= limits.slider_accel_mm_s2"
        return [Check.of(self.id, name, value, limit, self.unit, "max", 0.0)]

    def precheck(self, case: Any, given: float | None, lowest: float) -> Impossible | None:
        if given is None:
            return None
        bound = self.draw_speed_bound(Draw.of(case))
        if given <= bound * (1 + SAME_RELATIVE):
            return None
        limit = case.limits.slider_accel_mm_s2
        a_draw = limit * (given / bound) ** 2
        return Impossible(
            f"at the draw speed {case.process.draw_speed_rpm:g} rpm the slider acceleration in the draw reaches "
            f"{a_draw:.0f} mm/s^2 > limits.slider_accel_mm_s2 = {limit:g}",
            self.field,
            limit,
            a_draw,
        )

    def parameter_values(self, case: Any) -> dict[str, float]:
        return {"accel_limit": case.limits.slider_accel_mm_s2 * (1 - self.backoff)}

    def rows(self, nlp: Transcription) -> list[Row]:
        accel = nlp.outside_draw(nlp.curvature * nlp.omega**2 + nlp.slope * nlp.alpha)
        return [Row("slider acceleration", accel / nlp.param("accel_limit"), -1.0, 1.0, sampled=True)]

    def check(self, dense: Dense) -> list[Check]:
        limit = dense.case.limits.slider_accel_mm_s2
        accel = np.abs(dense.a)
        check = Check.of(self.id, self.name, float(np.max(accel)), limit, self.unit, "max", LIMIT_REL_TOL * limit)
        return [check.located(dense.t, dense.theta, accel, limit)]

    def bound_rows(self, mesh: BoundMesh) -> list[tuple[Any, Any, Any]]:
        A = mesh.case.limits.slider_accel_mm_s2
        start = mesh.d2[:-1] * mesh.s + mesh.d1[:-1] * mesh.alpha
        end = mesh.d2[1:] * mesh.s_next + mesh.d1[1:] * mesh.alpha
        n = mesh.dtheta.size
        return [(start, -A * np.ones(n), A * np.ones(n)), (end, -A * np.ones(n), A * np.ones(n))]

    def relaxed_rows(self, mesh: RelaxedMesh) -> list[tuple[Any, Any, Any]]:
        """The slide's own kinematics, exact for any motion: ``d(v^2)/dtheta = 2 h' a`` with ``v = h' omega``,
        so over an interval where h is monotone ``|h'_(i+1)^2 s_(i+1) - h'_i^2 s_i| <= 2 A |h_(i+1) - h_i|``; at
        a dead centre (h' = 0) ``|h'' s| <= A``."""
        A = mesh.case.limits.slider_accel_mm_s2
        w, w_next = mesh.d1[:-1] ** 2 * mesh.s, mesh.d1[1:] ** 2 * mesh.s_next
        room = 2 * A * np.abs(np.diff(mesh.h))
        rows = [(w_next - w, -room, room)]
        dead = np.flatnonzero(np.abs(mesh.d1[:-1]) <= DEAD_CENTRE_SLOPE * np.max(np.abs(mesh.d1)))
        if dead.size:
            rows.append((mesh.d2[dead] * mesh.s[dead.tolist()], -A * np.ones(dead.size), A * np.ones(dead.size)))
        return rows

    def relaxed_envelopes(self, mesh: RelaxedMesh) -> list[Envelope]:
        """Over a piece [a, b] of interval i: ``v^2 <= v_i^2 + 2 A |h(b) - h_i|`` and ``<= v_(i+1)^2 + 2 A |h_(i+1) -
        h(a)|``, so ``s <= that / min h'^2`` over the piece (pieces where h' vanishes: none)."""
        A = mesh.case.limits.slider_accel_mm_s2
        moving = mesh.slope2_min > 0
        m = np.where(moving, mesh.slope2_min, 1.0)
        start, end = mesh.cell, mesh.cell + 1
        from_start = (mesh.d1[start] ** 2 * mesh.s_a + 2 * A * np.abs(mesh.h_b - mesh.h[start])) / m
        from_end = (mesh.d1[end] ** 2 * mesh.s_b + 2 * A * np.abs(mesh.h[end] - mesh.h_a)) / m
        return [Envelope(from_start, moving, "start"), Envelope(from_end, moving, "end")]
