"""At and below the die height the slide moves no faster than ``limits.die_speed_mm_s``."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pydantic import Field

from planning.model.errors import CaseError
from planning.model.limits.base import (
    Check,
    Dense,
    Draw,
    Row,
    Transcription,
    sample_vector,
)
from planning.model.limits.canonical import SpeedCap
from planning.model.units import Height, SliderSpeed
from planning.tolerances import LIMIT_REL_TOL, SAME_HEIGHT_MM, SAME_RELATIVE
from press.backend import math_module


class DieSpeedLimit(SpeedCap):
    """|slide speed| <= ``limits.die_speed_mm_s`` wherever the slide is at or below
    ``limits.die_height_mm`` (a speed cap, ``k = h'``, where it applies; its bounds and caps derive from it):
    in the draw (a bound on the draw speed), where the slide passes the die
    height outside the draw (rows at the crossings), and, where a transcription's crank speed may peak
    inside the die zone, at every sample below the die height (``max(h - h_die, v_die - |v|) >= 0``,
    continuous)."""

    id = "die_speed"
    name = "slider speed at or below the die height"
    unit = "mm/s"
    field = "limits.die_speed_mm_s"
    order = 30
    section_fields = {
        "die_height_mm": (
            Height,
            Field(
                ...,
                title="die height [mm above BDC]",
                description="At and below this height the slide is no faster than the die speed.",
            ),
        ),
        "die_speed_mm_s": (
            SliderSpeed,
            Field(..., title="die speed [mm/s]", description="The slide's highest speed at and below the die height."),
        ),
    }
    parameters = ("die_speed", "die_height", "die_exit_speed")
    refined = "die_speed"
    refuses_draw_speed_above_bound = True

    def validate(self, case: Any) -> None:
        m = case.machine
        die = case.limits.die_height_mm
        if die > m.stroke:
            raise CaseError("limits.die_height_mm", f"is above the stroke {m.stroke:g} mm", die)
        h2 = float(m.height(math.radians(case.key_points.draw_start_deg)))
        if die >= h2:
            raise CaseError(
                "limits.die_height_mm", f"must be below the slider height at the draw start ({h2:.1f} mm)", die
            )

    def draw_speed_bound(self, draw: Draw) -> float:
        """|dh/dtheta| peaks in the die zone of the draw or where the draw crosses the die height."""
        case, m = draw.case, draw.case.machine
        die = case.limits.die_height_mm
        th2, th3 = draw.theta[0], draw.theta[-1]
        inside = draw.h <= die
        lo, hi = m.angles_at_height(min(die, m.stroke))
        edges = [a for a in (float(lo), float(hi)) if th2 <= a <= th3]
        slopes = (
            np.abs(np.concatenate([draw.d1[inside], m.derivatives(np.array(edges))[0]]))
            if (inside.any() or edges)
            else []
        )
        peak = float(np.max(slopes)) if len(slopes) else 0.0
        return case.limits.die_speed_mm_s / peak if peak > 0 else math.inf

    def at_draw_speed(self, draw: Draw, speed: float) -> list[Check]:
        lim = draw.case.limits
        bound = self.draw_speed_bound(draw)
        value = lim.die_speed_mm_s * speed / bound if math.isfinite(bound) else 0.0
        name = f"slider speed at or below {lim.die_height_mm:g} mm <= limits.die_speed_mm_s"
        return [Check.of(self.id, name, value, lim.die_speed_mm_s, self.unit, "max", 0.0)]

    def parameter_values(self, case: Any) -> dict[str, float]:
        v_die = case.limits.die_speed_mm_s
        return {"die_speed": v_die, "die_height": case.limits.die_height_mm, "die_exit_speed": v_die}

    def rows(self, nlp: Transcription) -> list[Row]:
        v_die = nlp.param("die_speed")
        speeds = sample_vector([slope * omega for omega, slope in nlp.crossings])
        out = [Row("die-height speed", speeds / v_die, -np.inf, 1.0)]
        if nlp.exit_speeds:  # refined on their own: the crossing's row keeps the limit as it is
            exits = sample_vector([slope * omega for omega, slope in nlp.exit_speeds])
            out.append(Row("die exit speed", exits / nlp.param("die_exit_speed"), -np.inf, 1.0, True, "die_exit_speed"))
        if nlp.zone:
            h = nlp.outside_draw(nlp.height)
            v = nlp.outside_draw(nlp.slope) * nlp.outside_draw(nlp.omega)
            m = math_module(h)
            zone = m.fmax((h - nlp.param("die_height")) / nlp.length_unit, (v_die - m.fabs(v)) / v_die)
            out.append(Row("die-zone speed", zone, 0.0, np.inf, sampled=True))
        return out

    def check(self, dense: Dense) -> list[Check]:
        case, plan = dense.case, dense.plan
        m, lim = case.machine, case.limits
        low = dense.h <= lim.die_height_mm
        crossings = [float(x) for x in m.angles_at_height(min(lim.die_height_mm, m.stroke))]
        times = np.array([plan.profile.time_at_angle(angle) for angle in crossings])
        th, om, al, je = plan.profile.at_time(times)
        at_crossings = np.abs(m.slider(th, om, al, je)[1])
        fastest = max(([float(np.max(np.abs(dense.v[low])))] if low.any() else [0.0]) + at_crossings.tolist())
        limit = lim.die_speed_mm_s
        check = Check.of(self.id, self.name, fastest, limit, self.unit, "max", LIMIT_REL_TOL * limit)
        speed = np.concatenate([np.abs(dense.v[low]), at_crossings])  # the zone's samples and the crossings, in time
        t, theta = np.concatenate([dense.t[low], times]), np.concatenate([dense.theta[low], th])
        order = np.argsort(t, kind="stable")
        return [check.located(t[order], theta[order], speed[order], limit)]

    def limit(self, case: Any) -> float:
        return case.limits.die_speed_mm_s

    def where(self, case: Any, h: np.ndarray, bound: bool = False) -> np.ndarray:
        """At or below the die height (at the bound's nodes up to round-off: the crossings count)."""
        die = case.limits.die_height_mm
        return h <= die * (1 + SAME_RELATIVE) + SAME_HEIGHT_MM if bound else h <= die
