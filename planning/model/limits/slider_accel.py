"""The slide's acceleration stays within ``limits.slider_accel_mm_s2`` over the whole cycle."""

from __future__ import annotations

from typing import Any

from pydantic import Field

from planning.model.limits.base import Draw, Impossible, RelaxedMesh
from planning.model.limits.canonical import AccelLimit
from planning.model.units import SliderAccel
from planning.tolerances import ACCEL_BACKOFF, HARDER_BACKOFF, SAME_RELATIVE


class SliderAccelLimit(AccelLimit):
    """``|a| = |h'' omega^2 + h' alpha| <= A`` (canonical: ``a = h'``, ``b = h''``): at every sample of an NLP (the
    dense check decides between them), in the draw (a bound on the draw speed), at both ends of every
    interval of the bound; in the certified upper bound the slide's own kinematics, ``mu = h'^2``, ``I = 2 h``
    (``d(v^2)/dtheta = 2 h' a``: over an interval where h is monotone ``|h'^2 s| <= 2 A |h_(i+1) - h_i|``)."""

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
    parameter = "accel_limit"
    row_name = "slider acceleration"
    refined = "accel_limit"
    shared = True
    backoff = ACCEL_BACKOFF
    harder_backoff = HARDER_BACKOFF

    def coefficients(self, theta: Any, d1: Any, d2: Any) -> tuple[Any, Any]:
        return d1, d2

    def cap(self, case: Any) -> float:
        return case.limits.slider_accel_mm_s2

    def integrating_factor(self, mesh: RelaxedMesh) -> tuple[Any, Any, Any, Any, Any]:
        return mesh.d1**2, mesh.slope2_min, 2 * mesh.h, 2 * mesh.h_a, 2 * mesh.h_b

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
