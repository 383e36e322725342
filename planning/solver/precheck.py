"""Cheap necessary conditions before any NLP: each limit's precheck, and the draw speed's range.

The draw runs at constant crank speed, so every limit that holds in the draw bounds the draw speed
(``Limit.draw_speed_bound``); the lowest of those bounds is the highest draw speed, the minimum crank
speed the lowest. A case whose range is empty, or whose limits fail their own prechecks
(``Limit.precheck``; for a draw at constant slide speed not those that read the draw at one crank speed,
``Limit.precheck_at_one_draw_speed``), is :class:`~planning.solver.outcomes.Infeasible` before any solve.
"""

from __future__ import annotations

import math

from planning.model.case import RPM, Case
from planning.model.limits import BY_ID, draw_speed_bounds, limits_of
from planning.solver.outcomes import Infeasible


def precheck(case: Case) -> tuple[float, float]:
    """The draw-speed range ``(lo, hi)`` [rad/s] of ``case`` (a given draw speed: both ends); raises
    :class:`Infeasible` naming the limit that makes the case impossible."""
    bounds = draw_speed_bounds(case)
    w_min = case.limits.min_crank_speed_rpm * RPM
    given = case.process.draw_speed_rpm * RPM if case.process.draw_speed_rpm is not None else None
    highest = min(bounds.values())
    for limit in limits_of(case):
        if case.free_draw and limit.precheck_at_one_draw_speed:
            continue  # a draw at constant slide speed: its crank need not turn at one speed
        impossible = limit.precheck(case, given, w_min)
        if impossible is not None:
            raise Infeasible(
                impossible.reason, impossible.field, impossible.value, impossible.needed, impossible.angle_deg
            )
    if given is not None:
        return given, given
    if case.free_draw:  # a draw at constant slide speed: no constant draw speed to bound (the NLP's samples hold it)
        return w_min, math.inf
    if highest < w_min:
        key = min(bounds, key=bounds.get)
        raise Infeasible(
            f"{BY_ID[key].field} ({BY_ID[key].name}) allows a draw speed of at most "
            f"{highest / RPM:.3f} rpm, below limits.min_crank_speed_rpm = {case.limits.min_crank_speed_rpm:g}",
            limit="limits.min_crank_speed_rpm",
            value=case.limits.min_crank_speed_rpm,
            needed=highest / RPM,
        )
    return w_min, highest
