"""``pressplan check``: the key points of a case and its process checks at the draw speed (no solve)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.case import KEY_POINT_NAMES, RPM, Case
from planning.model.limits import draw_speed_bounds, limits_of
from planning.model.limits.base import Check, Draw
from planning.model.limits.robot_window import radians_hint
from planning.model.plausibility import warnings_of
from planning.model.units import rounded_down
from planning.tolerances import SAME_SCORE, TINY

# the checks (limit ids) that take the draw at one crank speed: not for a draw at constant slide speed
AT_CONSTANT_DRAW = ("die_speed", "slider_speed", "slider_accel")
ROUND_OFF = SAME_SCORE  # relative: a check at the highest draw speed sits on its limit up to floating-point round-off


def check_case(case: Case) -> dict[str, Any]:
    """Key-point table and PASS/FAIL checks at the draw speed (the given one, else the highest the
    limits allow; each limit's own ``at_draw_speed``); plain data with engineering units in the keys."""
    m = case.machine
    bounds = draw_speed_bounds(case)
    w_max = min(bounds.values())
    w2 = case.process.draw_speed_rpm * RPM if case.process.draw_speed_rpm is not None else w_max
    if case.free_draw:  # the crank's speed at theta2 where the slide enters the draw at its set speed, or at the
        # draw-start limit where that is lower (the draw then speeds up to its set speed: the plan's NLP holds both)
        entry = min(x for x in (case.process.draw_slide_speed_mm_s, case.limits.draw_start_speed_mm_s) if x)
        w2 = entry / abs(float(m.derivatives(case.key_angles[1])[0]))
    th = case.key_angles
    h, v, _, _ = m.slider(th, w2)
    points = [
        {
            "name": name,
            "angle_deg": float(math.degrees(th[i])),
            "height_mm": float(h[i]),
            "slider_speed_mm_s": float(abs(v[i])),
            "direction": "down" if v[i] < 0 else "up",
        }
        for i, name in enumerate(KEY_POINT_NAMES)
    ]
    draw = Draw.of(case)
    checks = [_check(c) for limit in limits_of(case) for c in limit.at_draw_speed(draw, w2)]
    if case.free_draw:  # no constant draw speed: the checks that assume one left out (the slide's speed in it)
        checks = [c for c in checks if c["id"] not in AT_CONSTANT_DRAW]
    if case.pendulum:  # no window through TDC (the swings turn before it), no rotary cycle for the robots
        checks = [c for c in checks if c["id"] not in ("safety_height", "robots")]
    bdc = math.degrees(m.bdc_angle)
    return {
        "case": case.name,
        "press": {
            "mechanism": m.kind,
            "stroke_mm": m.stroke,
            "tdc_deg": 0.0,  # key angles count from TDC
            "bdc_deg": bdc,
            "down_deg": bdc,  # crank angle from TDC to BDC: the slide goes down
            "up_deg": 360.0 - bdc,
            "down_share_pct": bdc / 3.6,
            # the dead centres in the mechanism's own crank angle (its maker's drawings, mechpress, presslink)
            "own_angle_origin": m.own_angle_origin,
            "tdc_own_deg": round(math.degrees(m.tdc_own_angle), 9) + 0.0,  # no "-0.00" from round-off
            "bdc_own_deg": math.degrees(m.tdc_own_angle + m.bdc_angle) % 360.0,
        },
        "draw_speed_rpm": w2 / RPM,
        "draw_speed_given": case.process.draw_speed_rpm is not None,
        "key_points": points,
        "checks": checks,
        "max_draw_speed_rpm": w_max / RPM,
        "max_draw_speed_by_limit_rpm": {k: (b / RPM if math.isfinite(b) else None) for k, b in bounds.items()},
        "warnings": warnings(case),
        **({"hold": _hold(case)} if case.hold_angle is not None else {}),
        **({"slide_draw": _slide_draw(case, draw)} if case.free_draw else {}),
        **({"pendulum": _pendulum(case)} if case.pendulum else {}),
    }


def _pendulum(case: Case) -> dict[str, Any]:
    """A pendulum stroke: where the swings may turn [deg] and each swing's key angles and highest draw speed."""
    from planning.model.pendulum import backward_key_angles, swing_bounds, swing_setups

    (s_lo, s_hi), (e_lo, e_hi) = swing_bounds(case)
    forward, backward = swing_setups(case, {})  # the case's own limits
    robots = {}
    if case.robots is not None:  # the least cycle the robots allow (``planning.solver.pendulum_bound``)
        from planning.solver.pendulum_bound import robot_demands

        least, what = max(robot_demands(case, (forward, backward)))
        robots = {"robots": {"least_cycle_s": least, "set_by": what}}
    return {
        "turn_start_deg": [math.degrees(s_lo), math.degrees(s_hi)],
        "turn_end_deg": [math.degrees(e_lo), math.degrees(e_hi)],
        "backward_key_angles_deg": [math.degrees(a) for a in backward_key_angles(case)],
        "max_draw_speed_rpm": {"forward": forward.draw_speed_bound / RPM, "backward": backward.draw_speed_bound / RPM},
        **robots,
    }


def _slide_draw(case: Case, draw: Draw) -> dict[str, Any]:
    """A draw at constant slide speed v: the slide's speed at theta2 (v, or the draw-start limit where that is
    lower: the draw then speeds up to v) and the crank's there [rpm], the crank's speed v asks, ``v / |dh/dtheta|``,
    at its highest over the draw [rpm], and the first angle [deg] where that is above the crank's top speed (the
    limits' lowest, ``Limit.top_crank_speed``), or None: from there the crank's limits cap the slide's speed."""
    v = case.process.draw_slide_speed_mm_s
    asked = v / np.maximum(np.abs(draw.d1), TINY)
    tops = [t for limit in limits_of(case) if (t := limit.top_crank_speed(case)) is not None]
    over = np.flatnonzero(asked > min(tops)) if tops else np.array([], dtype=int)
    enters = min(v, case.limits.draw_start_speed_mm_s or v)  # the slide at theta2: at most the draw-start limit
    return {
        "set_mm_s": v,
        "enters_mm_s": enters,
        "crank_at_draw_start_rpm": float(asked[0] * enters / v) / RPM,
        "highest_asked_rpm": float(np.max(asked)) / RPM,
        "capped_from_deg": float(math.degrees(draw.theta[over[0]])) if over.size else None,
    }


def _hold(case: Case) -> dict[str, float]:
    """The hold at the bottom: its time [s], the slide's height [mm above BDC], the crank's angle [deg] and the
    angle the crank brakes over from theta3 [deg]."""
    hold_deg = math.degrees(case.hold_angle)
    return {
        "time_s": case.process.hold_time_s,
        "height_mm": case.hold_height_mm,
        "angle_deg": hold_deg,
        "brake_deg": hold_deg - case.key_points.draw_end_deg,
    }


def warnings(case: Case) -> list[str]:
    """What a press engineer should know before solving: key angles that look like radians, and the entries
    that are valid but probably not meant (``planning.model.plausibility``), each naming its field."""
    hint = radians_hint(case)
    return ([hint.removeprefix("; ")] if hint else []) + [f"{w.field}: {w.message}" for w in warnings_of(case)]


def _check(check: Check) -> dict[str, Any]:
    """A check as the report lists it; passed up to floating-point round-off (a check at the highest draw
    speed sits on its limit)."""
    value, limit = float(check.value), float(check.limit)
    margin = limit - value if check.kind == "max" else value - limit
    return {
        "id": check.id,
        "name": check.name,
        "value": value,
        "limit": limit,
        "unit": check.unit,
        "margin": margin,
        "passed": bool(np.isfinite(value) and margin >= -ROUND_OFF * abs(limit)),
    }


# a draw-speed bound's words, by limit id
LIMIT_WORDS = {"motor_speed": "motor speed (on the crank)", "hold": "braking to the hold"}


def _rpm(value: float, given: str) -> str:
    """A draw speed as ``check`` prints it: a given one as it is, the highest allowed rounded down (typed back
    into the case, it is allowed)."""
    return f"{value:.3f}" if given == "given" else rounded_down(value)


def check_text(report: dict[str, Any]) -> str:
    """Console table of a :func:`check_case` report."""
    given = "given" if report["draw_speed_given"] else "highest allowed"
    if report.get("slide_draw"):
        given = "the slide's set speed at theta2"
    p = report["press"]
    lines = [
        f"{report['case']}: key points at the draw speed {_rpm(report['draw_speed_rpm'], given)} rpm ({given})",
        f"  {p['mechanism']}: stroke {p['stroke_mm']:.3f} mm; TDC at {p['tdc_own_deg']:.2f} deg, BDC at "
        f"{p['bdc_own_deg']:.2f} deg of the crank's own angle (from {p['own_angle_origin']})",
        f"  key angles count from TDC: the slide goes down for {p['down_deg']:.2f} deg "
        f"({p['down_share_pct']:.1f} % of the turn), up for {p['up_deg']:.2f} deg",
        "",
        f"  {'key point':<11} {'angle deg':>9} {'height mm':>10} {'slider speed mm/s':>18}",
    ]
    for k in report["key_points"]:
        lines.append(
            f"  {k['name']:<11} {k['angle_deg']:9.2f} {k['height_mm']:10.2f} "
            f"{k['slider_speed_mm_s']:14.2f} {k['direction']:<3}"
        )
    hold = report.get("hold")
    if hold:
        lines.append(
            f"  hold: the slide stands {hold['time_s']:g} s at {hold['height_mm']:g} mm above BDC (crank at "
            f"{hold['angle_deg']:.2f} deg), the crank braking to it over {hold['brake_deg']:.2f} deg from theta3"
        )
    slide = report.get("slide_draw")
    if slide:
        capped = (
            f"; above the crank's top speed from {slide['capped_from_deg']:.2f} deg: its limits cap the slide there"
            if slide["capped_from_deg"] is not None
            else ""
        )
        enters = (
            f" (the slide enters at the draw-start limit, {slide['enters_mm_s']:g} mm/s, and speeds up to it)"
            if slide["enters_mm_s"] < slide["set_mm_s"]
            else ""
        )
        lines.append(
            f"  draw at {slide['set_mm_s']:g} mm/s slide speed{enters}: the crank at "
            f"{slide['crank_at_draw_start_rpm']:.3f} rpm at theta2, asked up to {slide['highest_asked_rpm']:.4g} rpm "
            f"in the draw{capped}"
        )
    swing = report.get("pendulum")
    if swing:
        back = ", ".join(
            f"{name} {a:.2f}" for name, a in zip(KEY_POINT_NAMES, swing["backward_key_angles_deg"], strict=True)
        )
        top = swing["max_draw_speed_rpm"]
        lines += [
            f"  pendulum: the forward swing starts at rest between {swing['turn_start_deg'][0]:.2f} and "
            f"{swing['turn_start_deg'][1]:.2f} deg and turns between {swing['turn_end_deg'][0]:.2f} and "
            f"{swing['turn_end_deg'][1]:.2f} deg (the planner decides)",
            f"  the backward swing's key angles [deg]: {back}",
            f"  highest draw speed of each swing: forward {rounded_down(top['forward'])} rpm, backward "
            f"{rounded_down(top['backward'])} rpm",
        ]
        if "robots" in swing:
            r = swing["robots"]
            lines.append(
                f"  the robots need a cycle of at least {r['least_cycle_s']:.4f} s ({120 / r['least_cycle_s']:.3f} "
                f"strokes/min at most): {r['set_by']}"
            )
    lines += ["", "  checks"]
    for c in report["checks"]:
        mark = "PASS" if c["passed"] else "FAIL"
        lines.append(
            f"  {mark}  {c['name']}: {c['value']:.1f} {c['unit']} (limit {c['limit']:g}, margin {c['margin']:+.1f})"
        )
    by = ", ".join(
        f"{LIMIT_WORDS.get(k, k.replace('_', ' '))} {rounded_down(v)}"
        for k, v in report["max_draw_speed_by_limit_rpm"].items()
        if v is not None
    )
    if not slide:  # a draw at constant slide speed has no constant draw speed
        lines += ["", f"  highest draw speed the limits allow: {rounded_down(report['max_draw_speed_rpm'])} rpm ({by})"]
    lines += [f"  WARNING: {w}" for w in report["warnings"]]
    return "\n".join(lines)
