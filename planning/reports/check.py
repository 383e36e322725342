"""``pressplan check``: the key points of a case and its process checks at the draw speed (no solve)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.case import KEY_POINT_NAMES, RPM, Case, draw_speed_bounds

ROUND_OFF = 1e-9  # relative: a check at the highest draw speed sits on its limit up to floating-point round-off


def check_case(case: Case) -> dict[str, Any]:
    """Key-point table and PASS/FAIL checks at the draw speed (the given one, else the highest the
    limits allow); plain data with engineering units in the keys."""
    m = case.machine
    bounds = draw_speed_bounds(case)
    w_max = min(bounds.values())
    w2 = case.process.draw_speed_rpm * RPM if case.process.draw_speed_rpm is not None else w_max
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
    lim = case.limits
    safety = case.process.safety_height_mm
    checks = [
        _check("slider height at closing >= safety height", h[0], safety, "mm", "min"),
        _check("slider height at opening >= safety height", h[3], safety, "mm", "min"),
        _check(
            "slider speed at draw start <= draw_start_speed_mm_s", abs(v[1]), lim.draw_start_speed_mm_s, "mm/s", "max"
        ),
        _check(
            f"slider speed at or below {lim.die_height_mm:g} mm <= die_speed_mm_s",
            lim.die_speed_mm_s * w2 / bounds["die_speed"] if math.isfinite(bounds["die_speed"]) else 0.0,
            lim.die_speed_mm_s,
            "mm/s",
            "max",
        ),
        _check(
            "|slider acceleration| during the draw <= slider_accel_mm_s2",
            lim.slider_accel_mm_s2 * (w2 / bounds["slider_accel"]) ** 2,
            lim.slider_accel_mm_s2,
            "mm/s^2",
            "max",
        ),
    ]
    return {
        "case": case.name,
        "draw_speed_rpm": w2 / RPM,
        "draw_speed_given": case.process.draw_speed_rpm is not None,
        "key_points": points,
        "checks": checks,
        "max_draw_speed_rpm": w_max / RPM,
        "max_draw_speed_by_limit_rpm": {k: (b / RPM if math.isfinite(b) else None) for k, b in bounds.items()},
        "warnings": warnings(case),
    }


def warnings(case: Case) -> list[str]:
    """What a press engineer should know before solving: a draw end (theta3) where the slide is still
    below the die height, so the return cannot speed up until it has left the die zone."""
    out = []
    m = case.machine
    die = case.limits.die_height_mm
    th3 = case.key_angles[2]
    h3 = float(m.height(th3))
    if h3 < die and die < m.stroke:
        leave = float(m.angles_at_height(die)[1])
        out.append(
            f"the slide is still below limits.die_height_mm = {die:g} mm at theta3 = "
            f"{math.degrees(th3):.2f} deg ({h3:.2f} mm); it leaves the die zone at {math.degrees(leave):.2f} deg. "
            "Until then the die-height speed limit holds the return back, whatever the motion law"
        )
    return out


def _check(name: str, value: float, limit: float, unit: str, kind: str) -> dict[str, Any]:
    value = float(value)
    margin = limit - value if kind == "max" else value - limit
    return {
        "name": name,
        "value": value,
        "limit": float(limit),
        "unit": unit,
        "margin": margin,
        "passed": bool(np.isfinite(value) and margin >= -ROUND_OFF * abs(limit)),
    }


def check_text(report: dict[str, Any]) -> str:
    """Console table of a :func:`check_case` report."""
    given = "given" if report["draw_speed_given"] else "highest allowed"
    lines = [
        f"{report['case']}: key points at the draw speed {report['draw_speed_rpm']:.3f} rpm ({given})",
        "",
        f"  {'key point':<11} {'angle deg':>9} {'height mm':>10} {'slider speed mm/s':>18}",
    ]
    for k in report["key_points"]:
        lines.append(
            f"  {k['name']:<11} {k['angle_deg']:9.2f} {k['height_mm']:10.2f} "
            f"{k['slider_speed_mm_s']:14.2f} {k['direction']:<3}"
        )
    lines += ["", "  checks"]
    for c in report["checks"]:
        mark = "PASS" if c["passed"] else "FAIL"
        lines.append(
            f"  {mark}  {c['name']}: {c['value']:.1f} {c['unit']} (limit {c['limit']:g}, margin {c['margin']:+.1f})"
        )
    by = ", ".join(
        f"{k.replace('_', ' ')} {v:.3f}" for k, v in report["max_draw_speed_by_limit_rpm"].items() if v is not None
    )
    lines += ["", f"  highest draw speed the limits allow: {report['max_draw_speed_rpm']:.3f} rpm ({by})"]
    lines += [f"  WARNING: {w}" for w in report["warnings"]]
    return "\n".join(lines)
