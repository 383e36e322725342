"""One swing's symbols in a pendulum NLP, whatever law plans it (``planning.solver.pendulum_nlp``): its parameters,
its feed's and return's segments with their knot states, and the rows every law's swing shares (the slide's
acceleration and speed at samples of every segment, the die zone on the return)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from planning.model.case import Case
from planning.model.free_swing import samples_per_segment
from planning.model.pendulum import SwingSetup
from planning.model.profile import advance_segment, knot_states
from planning.solver.halves_nlp import angle_at
from planning.solver.nlp import Rows

SLIDE_ACCEL = "limits.slider_accel_mm_s2"


@dataclass
class SwingSymbols:
    """One swing's symbols: its parameters, the feed's and the return's segments (``(starts, states, segments)``
    as :func:`~planning.solver.halves_nlp.angle_at` takes them) and the states at their ends."""

    setup: SwingSetup
    params: Any  # SwingParameters or FreeSwingParameters
    v: dict[str, Any]
    feed: tuple[list, list, list]
    ret: tuple[list, list, list]
    feed_end: tuple[Any, Any, Any]
    return_end: tuple[Any, Any, Any]


def segments_from(segs: list, theta0: Any, omega0: Any) -> tuple[tuple[list, list, list], tuple[Any, Any, Any]]:
    """The segments ``segs`` from the state ``(theta0, omega0, 0)``: ``(starts, states, segs)`` and the end state."""
    states = knot_states(theta0, omega0, 0.0, segs)
    starts = [0.0]
    for seg in segs[:-1]:
        starts.append(starts[-1] + seg.duration)
    return (starts, states[:-1], segs), states[-1]


def sampled_rows(rows: Rows, s: SwingSymbols, case: Case, limits: dict[str, float], zone: bool = False) -> None:
    """The slide's acceleration (and speed) at samples of every segment of the feed and the return; the die speed at
    the return's die-zone angles; with ``zone`` also at every sample at or below the die height
    (``max(h - h_die, v_die - |v|) >= 0``, as the optimal law's rotary NLP: a free profile may speed up between
    fixed angles)."""
    fractions = ca.DM(np.linspace(0.0, 1.0, samples_per_segment(s.params.motion_law) + 1)[:-1])
    lim = case.limits
    v_die = limits["die_speed"]
    for _, states, segs in (s.feed, s.ret):
        for seg, st in zip(segs, states, strict=True):
            th, om, al, _ = advance_segment(seg, *st, fractions * seg.duration)
            h, d1, d2, _ = s.setup.jets(th)
            rows.add("slider acceleration", (d2 * om**2 + d1 * al) / limits["slider_accel"], -1.0, 1.0, SLIDE_ACCEL)
            if lim.slider_speed_mm_s is not None:
                rows.add("slider speed", d1 * om / limits["slider_speed"], -1.0, 1.0, "limits.slider_speed_mm_s")
            if zone:
                below = (h - lim.die_height_mm) / case.machine.length_scale
                inside = ca.fmax(below, (v_die - ca.fabs(d1 * om)) / v_die)
                rows.add("die zone speed at the samples", inside, 0.0, math.inf, "limits.die_speed_mm_s")
    for k, u in enumerate(s.setup.die_zone):  # the return in the die zone: at its fixed angles
        th_x, om_x = angle_at(s.v[f"die_time_{k}"], *s.ret)
        slope = abs(float(s.setup.jets(u)[1]))
        rows.add("die zone angles", ca.vertcat(th_x - u), 0.0, 0.0, "limits.die_height_mm")
        rows.add("die zone speed", slope * om_x / v_die, -math.inf, 1.0, "limits.die_speed_mm_s")
