"""Random but realistic press cases for the property tests (hypothesis strategies and a plain builder).

Ranges: crank radius R 100-800 mm, L/R 2-6; theta1 40-80 deg, theta2 in [theta1 + 35, 165], theta3
175-200, theta4 280-320 deg; safety height a little below the lower of the slide heights at theta1 and
theta4; die height 0.3-3 % of the stroke (below the slide at theta2); transfer 0.3-4 s; slider
acceleration limit 4-40 mm/s^2 per mm of crank radius; the speed limits set from a draw speed that is
30-100 % of the crank speed the acceleration limit allows at constant speed; the draw speed given or
left to the planner.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from hypothesis import strategies as st

from press.crank_slider import CrankSlider


def build_case(u: list[float], name: str = "random", offset_share: float = 0.0) -> dict[str, Any]:
    """A case mapping from 14 numbers in [0, 1) (a hypothesis draw or a seeded generator); ``offset_share``:
    the slide's offset as a share of the crank radius (an offset crank-slider; 0: in line)."""
    lerp = lambda a, b, x: a + (b - a) * x  # noqa: E731
    R = round(lerp(100, 800, u[0]), 1)
    L = round(R * lerp(2, 6, u[1]), 1)
    e = float(round(offset_share * R, 1))
    m = CrankSlider(R, L, e)
    th1 = round(lerp(40, 80, u[2]), 2)
    th2 = round(lerp(th1 + 35, 165, u[3]), 2)
    th3 = round(lerp(175, 200, u[4]), 2)
    th4 = round(lerp(280, 320, u[5]), 2)
    h1, h4 = (float(m.height(math.radians(a))) for a in (th1, th4))
    safety = round(min(h1, h4) * lerp(0.9, 0.999, u[6]), 2)
    h2 = float(m.height(math.radians(th2)))
    die = round(min(m.stroke * lerp(0.003, 0.03, u[7]), 0.5 * h2), 2)
    accel = round(R * lerp(4, 40, u[8]), 1)
    w_acc = math.sqrt(accel / (R + R**2 / L))
    w_draw = w_acc * lerp(0.3, 1.0, u[9])
    d1_2 = abs(float(m.derivatives(math.radians(th2))[0]))
    lo, hi = (float(a) for a in m.angles_at_height(die))
    grid = np.linspace(max(math.radians(th2), lo), min(math.radians(th3), hi), 201)
    slope = float(np.max(np.abs(m.derivatives(grid)[0]))) if grid[0] < grid[-1] else 0.0
    slope = max(slope, abs(float(m.derivatives(hi)[0])) if hi > math.radians(th3) else 0.0)
    case: dict[str, Any] = {
        "name": name,
        "press": {"crank_radius_mm": R, "rod_length_mm": L, **({"offset_mm": e} if e else {})},
        "key_points": {"closing_deg": th1, "draw_start_deg": th2, "draw_end_deg": th3, "opening_deg": th4},
        "process": {"safety_height_mm": safety, "transfer_time_s": round(lerp(0.3, 4.0, u[10]), 2)},
        "limits": {
            "draw_start_speed_mm_s": round(d1_2 * w_draw * lerp(1.0, 1.5, u[11]) + 1.0, 1),
            "die_height_mm": die,
            "die_speed_mm_s": round(max(slope * w_draw * lerp(1.0, 1.5, u[12]), 1.0) + 1.0, 1),
            "slider_accel_mm_s2": accel,
        },
    }
    if u[13] < 0.5:
        case["process"]["draw_speed_rpm"] = round(w_draw * 60 / (2 * math.pi) * 0.95, 3)
    return case


UNIT = st.floats(0.0, 1.0, exclude_max=True, allow_nan=False)
CASES = st.lists(UNIT, min_size=14, max_size=14).map(build_case)


def seeded_case(seed: int) -> dict[str, Any]:
    """The same kind of case from a seed (for surveys and the slow run)."""
    return build_case(list(np.random.default_rng(seed).random(14)), name=f"random-{seed}")


def seeded_offset_case(seed: int) -> dict[str, Any]:
    """An offset crank-slider from a seed: the slide's line 0 ... 12 % of the crank radius to either side."""
    u = np.random.default_rng(seed).random(15)
    return build_case(list(u[:14]), name=f"random-offset-{seed}", offset_share=round(0.24 * u[14] - 0.12, 3))


LINKAGES = {  # the shipped linkage presses whose geometry the random linkages scale
    "link-drive": ("link_drive", "link-drive-side-panel.yaml"),
    "knuckle-joint": ("knuckle_joint", "knuckle-joint-coining.yaml"),
}


def seeded_linkage_case(seed: int, mechanism: str) -> dict[str, Any]:
    """A linkage press from a seed: the shipped ``mechanism``'s geometry scaled by 0.7 ... 1.4 (every length),
    its key angles moved by up to +-8 deg, the safety height a little below the slide at theta1 and theta4,
    the die height 0.3 ... 3 % of the stroke, the slide's acceleration limit and the speed limits around the
    shipped ones, the transfer time 0.3 ... 3 s, the draw speed given or left to the planner (no drive)."""
    from pathlib import Path

    from planning.model.case_file import case_from_data, load_yaml

    u = np.random.default_rng(seed).random(12)
    section, file = LINKAGES[mechanism]
    data = load_yaml((Path(__file__).resolve().parents[1] / "cases" / file).read_text(encoding="utf-8"))
    for key in ("drive", "published", "source"):
        data.pop(key, None)
    scale = 0.7 + 0.7 * u[0]
    geometry = data["press"][section]
    for key, value in geometry.items():
        if key.endswith("_mm"):
            geometry[key] = round(value * scale, 2)
    kp = data["key_points"]
    for k, key in enumerate(("closing_deg", "draw_start_deg", "draw_end_deg", "opening_deg")):
        kp[key] = round(kp[key] + 16 * (u[1 + k] - 0.5), 2)
    data["name"] = f"random-{mechanism}-{seed}"
    data["process"] = {"safety_height_mm": 1.0, "transfer_time_s": round(0.3 + 2.7 * u[5], 2)}
    data["limits"]["die_height_mm"] = 0.0  # the machine first; the die height from it below
    machine = case_from_data(data).machine
    th = [math.radians(kp[key]) for key in ("closing_deg", "draw_start_deg", "draw_end_deg", "opening_deg")]
    h1, h2, _, h4 = (float(machine.height(a)) for a in th)
    data["process"]["safety_height_mm"] = round(min(h1, h4) * (0.9 + 0.099 * u[6]), 2)
    limits = data["limits"]
    limits["die_height_mm"] = round(min(machine.stroke * (0.003 + 0.027 * u[7]), 0.5 * h2), 2)
    for k, key in enumerate(("slider_accel_mm_s2", "die_speed_mm_s", "draw_start_speed_mm_s")):
        limits[key] = round(limits[key] * scale * (0.7 + 0.6 * u[8 + k]), 1)
    if u[11] < 0.5:
        from planning.model.limits import draw_speed_bounds

        highest = min(draw_speed_bounds(case_from_data(data)).values())
        data["process"]["draw_speed_rpm"] = round(highest * 60 / (2 * math.pi) * 0.9, 3)
    return data
