"""Where each limit of a case applies over a plan's cycle, as a line to draw: one definition for the
figures (``planning.reports.plots``) and the web page's charts.

A :class:`LimitLine` bounds one trajectory column (``quantity``) with ``upper`` (and ``lower`` for a
two-sided limit) given per sample, NaN where the limit does not apply: the safety height only in the
robot's window, the die speed only where the slide is at or below the die height, a robot's tool's need only
where its tool is over the die. The draw-start speed
holds at theta2 alone: a ``point`` line, one sample there. Labels name the case field and the value.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

COLOURS = {  # by case field, the figures' and the page's; the curve a limit bounds has its hue
    "process.safety_height_mm": "#1f77b4",  # matplotlib's tab:blue, as the slide height
    "limits.die_height_mm": "#5b8cc0",
    "limits.crank_speed_rpm": "#8b0000",
    "limits.min_crank_speed_rpm": "#e07070",
    "limits.crank_accel_rad_s2": "#4b0082",
    "limits.crank_jerk_rad_s3": "#5c3317",
    "limits.die_speed_mm_s": "#006400",
    "limits.slider_speed_mm_s": "#2e8b57",
    "limits.draw_start_speed_mm_s": "#006400",
    "limits.slider_accel_mm_s2": "#cc5500",
    "process.draw_slide_speed_mm_s": "#9acd32",  # a draw at constant slide speed
    "robots.unloader": "#d62728",  # matplotlib's tab:red and tab:green, as the interference figure's
    "robots.loader": "#2ca02c",
}


@dataclass(frozen=True)
class LimitLine:
    """The limit of case ``field`` on trajectory column ``quantity``: ``upper`` (and ``lower``) per sample
    of ``x``, NaN where it does not apply; ``point``: it holds at one crank angle (theta2), drawn as a mark."""

    field: str
    label: str
    quantity: str
    x: np.ndarray
    upper: np.ndarray
    lower: np.ndarray | None = None
    point: bool = False

    @property
    def colour(self) -> str:
        """The line's colour in the figures and on the page."""
        return COLOURS.get(self.field, "#444444")


def robot_windows(result: dict[str, Any], axis: str, x: np.ndarray) -> list[tuple[float, float]]:
    """The robot's window theta4 -> TDC -> theta1 as spans of ``x`` (time [s] or crank angle [deg]): from
    theta4 to the cycle's end and from its start to theta1."""
    if result.get("windows"):  # a pendulum stroke's: through each turn (``planning.reports.pendulum``)
        return [tuple(span) for span in result["windows"][axis]]
    keys = {k["name"]: k for k in result["key_points"]}
    at = "time_s" if axis == "time" else "angle_deg"
    return [(keys["opening"][at], float(x[-1])), (float(x[0]), keys["closing"][at])]


def needing(need: np.ndarray) -> np.ndarray:
    """Where a tool's need is drawn: the samples where it needs height and the one either side of each run
    (the line then reaches 0 where the tool leaves the die, not the last sample above it)."""
    over = need > 0
    return over | np.roll(over, 1) | np.roll(over, -1)


def planned_stop(result: dict[str, Any], columns: dict[str, np.ndarray]) -> np.ndarray:
    """Where the crank stops by plan (a hold: ``result.json``'s ``hold``, theta3 to the end of the return's
    rise), at the samples ``columns``; all False without a hold."""
    angle = np.mod(np.asarray(columns["crank_angle_deg"], dtype=float), 360.0)
    hold = result.get("hold")
    if not hold:
        return np.zeros(angle.shape, dtype=bool)
    start, end = hold["stop_from_deg"], hold["stop_to_deg"]
    return ((angle >= start) & (angle <= end)) | (angle + 360.0 <= end)  # a rise that ends past TDC


def limit_lines(result: dict[str, Any], columns: dict[str, np.ndarray], axis: str) -> list[LimitLine]:
    """Every limit ``result`` (``result.json``'s data: ``process``, ``limits``, ``key_points``) sets, over the
    samples ``columns`` (``trajectory.csv``'s), against time (``axis`` "time") or crank angle."""
    lim, proc = result.get("limits", {}), result.get("process", {})
    x = np.asarray(columns["time_s"] if axis == "time" else columns["crank_angle_deg"], dtype=float)
    everywhere = np.ones(len(x), dtype=bool)
    window = np.any([(x >= a) & (x <= b) for a, b in robot_windows(result, axis, x)], axis=0)
    height = np.asarray(columns["slider_height_mm"], dtype=float)
    lines: list[LimitLine] = []

    def add(field: str, label: str, quantity: str, value: float, where: np.ndarray, both: bool = False) -> None:
        upper = np.where(where, value, np.nan)
        lines.append(LimitLine(field, label, quantity, x, upper, -upper if both else None))

    if proc.get("safety_height_mm") is not None:
        safety = proc["safety_height_mm"]
        add(
            "process.safety_height_mm",
            f"process.safety_height_mm = {safety:g} mm (robot window)",
            "slider_height_mm",
            safety,
            window,
        )
    die = lim.get("die_height_mm")
    if die is not None:
        add("limits.die_height_mm", f"limits.die_height_mm = {die:g} mm", "slider_height_mm", die, everywhere)
    for key, quantity, text, where, both in (
        ("crank_speed_rpm", "crank_speed_rpm", "{v:g} rpm", everywhere, False),
        ("min_crank_speed_rpm", "crank_speed_rpm", "{v:g} rpm", ~planned_stop(result, columns), False),
        ("crank_accel_rad_s2", "crank_accel_rad_s2", "±{v:g} rad/s²", everywhere, True),
        ("crank_jerk_rad_s3", "crank_jerk_rad_s3", "±{v:g} rad/s³", everywhere, True),
        (
            "die_speed_mm_s",
            "slider_speed_mm_s",
            "±{v:g} mm/s (below the die height)",
            height <= (die if die is not None else -np.inf),
            True,
        ),
        ("slider_speed_mm_s", "slider_speed_mm_s", "±{v:g} mm/s", everywhere, True),
        ("slider_accel_mm_s2", "slider_accel_mm_s2", "±{v:g} mm/s²", everywhere, True),
    ):
        value = lim.get(key)
        if value is not None:
            add(f"limits.{key}", f"limits.{key} = " + text.format(v=value), quantity, value, where, both)
    v_draw = proc.get("draw_slide_speed_mm_s")
    if v_draw is not None:  # a draw at constant slide speed: its set speed over theta2 ... theta3
        keys = {k["name"]: k["angle_deg"] for k in result["key_points"]}
        angle = np.mod(np.asarray(columns["crank_angle_deg"], dtype=float), 360.0)
        drawing = (angle >= keys["draw_start"]) & (angle <= keys["draw_end"])
        label = f"process.draw_slide_speed_mm_s = ±{v_draw:g} mm/s (θ2 → θ3)"
        add("process.draw_slide_speed_mm_s", label, "slider_speed_mm_s", v_draw, drawing, both=True)
    v2 = lim.get("draw_start_speed_mm_s")
    if v2 is not None:
        keys = {k["name"]: k for k in result["key_points"]}
        at = np.array([keys["draw_start"]["time_s" if axis == "time" else "angle_deg"]])
        lines.append(
            LimitLine(
                "limits.draw_start_speed_mm_s",
                f"limits.draw_start_speed_mm_s = ±{v2:g} mm/s (at θ2)",
                "slider_speed_mm_s",
                at,
                np.array([v2]),
                np.array([-v2]),
                point=True,
            )
        )
    robots = (result.get("robots") or {}).get("robots", ())
    for name in dict.fromkeys(r["name"] for r in robots):  # each tool's need where it needs any (once a robot)
        robot = {"name": name}
        need = np.asarray(columns[f"{robot['name']}_needed_height_mm"], dtype=float)
        label = f"robots.{robot['name']}: the height its tool needs"
        upper = np.where(needing(need), need, np.nan)
        lines.append(LimitLine(f"robots.{robot['name']}", label, "slider_height_mm", x, upper))
    return lines
