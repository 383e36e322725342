"""Figures of a solved plan, drawn from its files (``result.json``, ``trajectory.csv`` and, when the
case has a published solution, ``published_profile.csv``). Headless: matplotlib's Agg canvas, no
pyplot. Two motion figures, one against time from TDC, one against crank angle: the paper's three result
plots (Figs. 7, 8, 9) and the crank jerk, every limit of the case dashed where it applies and named by
its field, the robot's window and the draw shaded, the key points as ticks above. Legends stand outside
the panels, so they never hide a curve."""

from __future__ import annotations

import io
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from planning.model.outcome import Outcome
from planning.reports.limit_lines import LimitLine, limit_lines, needing, robot_windows
from planning.tolerances import TINY_RATE

WINDOW_COLOUR, DRAW_COLOUR = "#d9ecff", "#e2f0d9"  # the robot's window, the draw
KEY_TICKS = {"closing": "θ1", "draw_start": "θ2", "draw_end": "θ3", "opening": "θ4"}
LEGEND_RIGHT = 0.66  # the panels end here; their legends stand right of them
LEGEND_ANCHOR = (1.09, 1.0)  # a legend's top left corner, in its panel's axes fraction (past the twin's label)
PLOT_FORMATS = ("png", "svg", "pdf")
FIGURES = ("motion_vs_time", "motion_vs_angle")
HOLD_COLOUR = "#8c7a5b"  # a hold's standstill


def read_table(path: Path) -> dict[str, np.ndarray]:
    """A CSV with a header row (after any ``#`` comment lines) as columns by name; ``ValueError`` when
    it has no header, no rows or rows that do not fit the header."""
    skip = 0
    header = None
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            skip += 1
            if not line.startswith("#"):
                header = line.strip().split(",")
                break
    if header is None:
        raise ValueError(f"{path.name} has no header row")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an empty table is reported below, not warned about
        data = np.loadtxt(path, delimiter=",", skiprows=skip, ndmin=2)
    if data.shape[0] < 2 or data.shape[1] != len(header):
        raise ValueError(f"{path.name} has {data.shape[0]} rows of {data.shape[1]} columns under {len(header)} names")
    return {name: data[:, i] for i, name in enumerate(header)}


def _decorate(ax, result: dict[str, Any], axis: str, x: np.ndarray, label: bool) -> None:
    """The robot's window shaded (its achieved time written once; none with robots on their interference
    curves), the draw shaded, the key points as dotted lines."""
    window = result.get("transfer_window_s")
    required = result.get("process", {}).get("transfer_time_s")
    text = f"robot window θ4 → θ1: {window:.3f} s" + (f" (≥ {required:g} s)" if required is not None else "")
    windows = [] if result.get("robots") else robot_windows(result, axis, x)  # robots: their curves, no window
    for i, (a, b) in enumerate(windows):
        ax.axvspan(a, b, color=WINDOW_COLOUR, alpha=0.7, lw=0, zorder=0, label=text if label and i == 0 else None)
    keys = {k["name"]: k for k in result["key_points"]}
    at = "time_s" if axis == "time" else "angle_deg"
    ax.axvspan(
        keys["draw_start"][at],
        keys["draw_end"][at],
        color=DRAW_COLOUR,
        alpha=0.7,
        lw=0,
        zorder=0,
        label="draw θ2 → θ3" if label else None,
    )
    for k in result["key_points"]:
        ax.axvline(k[at], color="#444444", lw=0.8, ls=":", zorder=1)
    _hold_band(ax, result, keys["draw_end"], axis, label)
    ax.grid(True, lw=0.3, alpha=0.6)


def _hold_band(ax, result: dict[str, Any], draw_end: dict, axis: str, label: bool) -> None:  # noqa: ANN001
    """A hold's standstill hatched (against time; against crank angle a line at its angle), labelled once."""
    hold = result.get("hold")
    if not hold:
        return
    text = f"hold: {hold['time_s']:g} s at {hold['height_mm']:g} mm above BDC" if label else None
    if axis == "time":
        start = draw_end["time_s"] + hold["brake_s"]
        ax.axvspan(
            start,
            start + hold["time_s"],
            facecolor="none",
            edgecolor=HOLD_COLOUR,
            hatch="///",
            lw=0,
            zorder=0,
            label=text,
        )
    else:
        ax.axvline(hold["angle_deg"], color=HOLD_COLOUR, lw=1.2, zorder=1, label=text)


def _key_ticks(ax, result: dict[str, Any], axis: str) -> None:
    """theta1 ... theta4 as ticks of a second x axis above the panel: never over the data."""
    at = "time_s" if axis == "time" else "angle_deg"
    top = ax.secondary_xaxis("top")
    top.set_xticks([k[at] for k in result["key_points"]])
    top.set_xticklabels([KEY_TICKS.get(k["name"], k["name"]) for k in result["key_points"]], fontsize=8)
    top.tick_params(length=3)


def _limit(
    ax,  # noqa: ANN001 - a matplotlib Axes
    x: np.ndarray,
    value: float | np.ndarray,
    label: str | None,
    colour: str,
    where: np.ndarray | None = None,
    both: bool = False,
) -> None:
    """A limit drawn as a dashed line over the x where it applies (``where``; None: everywhere), at
    +value (and -value when ``both``; ``value`` a number or one per x), labelled once for the legend."""
    for sign in (1, -1) if both else (1,):
        y = sign * np.broadcast_to(np.asarray(value, dtype=float), np.shape(x)).copy()
        if where is not None:
            y[~where] = np.nan
        ax.plot(x, y, color=colour, ls="--", lw=1.0, label=label if sign == 1 else None, zorder=2)


def _legend(ax, *axes, anchor: tuple[float, float] = LEGEND_ANCHOR) -> None:  # noqa: ANN001 - matplotlib Axes
    """One legend for a panel and its twins, outside the axes to the right (never over the data)."""
    handles, labels = [], []
    for a in (ax, *axes):
        h, lab = a.get_legend_handles_labels()
        handles += h
        labels += lab
    ax.legend(
        handles, labels, loc="upper left", bbox_to_anchor=anchor, borderaxespad=0.0, fontsize=7.5, framealpha=0.95
    )


MAX_POINTS = 2000  # per plotted line: beyond this a 1 ms trajectory adds nothing visible


def _thin(table: dict[str, np.ndarray] | None) -> dict[str, np.ndarray] | None:
    """Every k-th row (first and last kept) so that a line has at most :data:`MAX_POINTS` points."""
    if table is None:
        return None
    n = len(next(iter(table.values())))
    step = max(1, int(np.ceil(n / MAX_POINTS)))
    idx = np.unique(np.concatenate([np.arange(0, n, step), [n - 1]]))
    return {k: v[idx] for k, v in table.items()}


def _overlay(ax, x, published: dict[str, np.ndarray] | None, column: str, colour: str, alpha: float) -> None:
    """The rebuilt published solution, dotted (limits are dashed), when there is one."""
    if published is not None:
        ax.plot(x, published[column], color=colour, lw=1.2, ls=":", alpha=alpha, label="published solution (rebuilt)")


def _draw_limits(axes_of: dict[str, Any], lines: list[LimitLine]) -> None:
    """Each limit line on the panel of the quantity it bounds (``planning.reports.limit_lines``)."""
    for line in lines:
        ax = axes_of[line.quantity]
        colour = line.colour
        if line.point:
            ys = [*line.upper, *(line.lower if line.lower is not None else [])]
            ax.plot([line.x[0]] * len(ys), ys, ls="none", marker="_", ms=14, mew=2.2, color=colour, label=line.label)
            continue
        _limit(ax, line.x, line.upper, line.label, colour)
        if line.lower is not None:
            _limit(ax, line.x, line.lower, None, colour)


def _figure(result, traj, published, axis: str) -> Figure:
    """Five panels against time or crank angle: slide height; crank speed; crank acceleration; crank jerk;
    slide speed and acceleration (two axes, their zeros on one line). Every limit the case sets
    (``limit_lines``) is a dashed line over the part of the cycle where it applies, named by its case field
    in the legend; the legends sit right of the panels."""
    traj, published = _thin(traj), _thin(published)
    lim = result.get("limits", {})
    x = traj["time_s"] if axis == "time" else traj["crank_angle_deg"]
    xp = None
    if published is not None:
        xp = published["time_s"] if axis == "time" else published["crank_angle_deg"]
    paper = published is not None  # the paper's figure numbers only beside the paper's own solution
    xlabel = "time from TDC [s]" if axis == "time" else "crank angle from TDC [deg]"
    fig = Figure(figsize=(13.5, 15), dpi=80)
    fig.subplots_adjust(left=0.07, right=LEGEND_RIGHT, top=0.94, bottom=0.05, hspace=0.32)
    FigureCanvasAgg(fig)
    axes = fig.subplots(5, 1, sharex=True)
    title = (
        f"{result['case']}: {result['spm']:.2f} strokes/min, cycle {result['cycle_time_s']:.3f} s "
        f"({result['motion_law']}, {result['placement']} placement, {result['status']})"
    )
    fig.suptitle(title, fontsize=11)
    for ax in axes:
        _decorate(ax, result, axis, x, ax is axes[0])
    _key_ticks(axes[0], result, axis)
    height_ax, speed_ax = axes[0], axes[1]
    accel_ax, jerk_ax = axes[2], axes[3]
    slide_ax, slide_accel_ax = axes[4], axes[4].twinx()

    height_ax.plot(x, traj["slider_height_mm"], color="tab:blue", lw=1.6, label="slide height")
    speed_ax.plot(x, traj["crank_speed_rpm"], color="tab:red", lw=1.6, label="crank speed")
    _overlay(speed_ax, xp, published, "crank_speed_rpm", "tab:red", 0.7)
    accel_ax.plot(x, traj["crank_accel_rad_s2"], color="tab:purple", lw=1.6, label="crank acceleration")
    _overlay(accel_ax, xp, published, "crank_accel_rad_s2", "tab:purple", 0.7)
    jerk_ax.plot(x, traj["crank_jerk_rad_s3"], color="tab:brown", lw=1.2, label="crank jerk")
    slide_ax.plot(x, traj["slider_speed_mm_s"], color="tab:green", lw=1.6, label="slide speed (up +)")
    slide_accel_ax.plot(x, traj["slider_accel_mm_s2"], color="tab:orange", lw=1.6, label="slide acceleration")
    _overlay(slide_accel_ax, xp, published, "slider_accel_mm_s2", "tab:orange", 0.6)
    _draw_limits(
        {
            "slider_height_mm": height_ax,
            "crank_speed_rpm": speed_ax,
            "crank_accel_rad_s2": accel_ax,
            "crank_jerk_rad_s3": jerk_ax,
            "slider_speed_mm_s": slide_ax,
            "slider_accel_mm_s2": slide_accel_ax,
        },
        limit_lines(result, traj, axis),
    )
    for ax in (accel_ax, jerk_ax):
        ax.axhline(0, color="black", lw=0.6)
    speed_ax.set_ylim(0, 1.1 * max(float(np.max(traj["crank_speed_rpm"])), lim.get("crank_speed_rpm") or 0.0))
    _zeros_on_one_line(slide_ax, traj["slider_speed_mm_s"], lim.get("slider_speed_mm_s"))
    _zeros_on_one_line(slide_accel_ax, traj["slider_accel_mm_s2"], lim.get("slider_accel_mm_s2"))
    height_ax.set_ylabel("slide height above BDC [mm]", color="tab:blue")
    speed_ax.set_ylabel("crank speed [rpm]", color="tab:red")
    accel_ax.set_ylabel("crank acceleration [rad/s²]")
    jerk_ax.set_ylabel("crank jerk [rad/s³]")
    slide_ax.set_ylabel("slide speed [mm/s]", color="tab:green")
    slide_accel_ax.set_ylabel("slide acceleration [mm/s²]", color="tab:orange")
    _legend(height_ax)
    _legend(speed_ax)
    _legend(accel_ax)
    _legend(jerk_ax)
    _legend(slide_ax, slide_accel_ax)
    for ax, what, figure_number in (
        (height_ax, "slide height", 7),
        (speed_ax, "crank speed", 7),
        (accel_ax, "crank acceleration", 8),
        (jerk_ax, "crank jerk", None),
        (slide_ax, "slide speed and acceleration", 9),
    ):
        paper_figure = f" (paper Fig. {figure_number})" if paper and figure_number else ""
        ax.set_title(what + paper_figure, fontsize=9, loc="left")
    axes[-1].set_xlabel(xlabel)
    axes[-1].set_xlim(x[0], x[-1])
    return fig


def _zeros_on_one_line(ax, values: np.ndarray, limit: float | None) -> None:  # noqa: ANN001 - an Axes
    """A y-axis symmetric about zero (the data and the limit within it): two axes so set share their zero."""
    top = 1.15 * max(float(np.max(np.abs(values))), limit or 0.0)
    ax.set_ylim(-top, top)


def plot_files(
    result: dict[str, Any], traj: dict[str, np.ndarray], published: dict[str, np.ndarray] | None, fmt: str = "png"
) -> dict[str, Figure]:
    """The figures by file name (``motion_vs_time.<fmt>``, ``motion_vs_angle.<fmt>``, and those of
    :func:`figure_names` the result has: ``drive.<fmt>`` with a drive, ...)."""
    return {f"{name}.{fmt}": figure_of(name, result, traj, published) for name in figure_names(result)}


def figure_names(result: dict[str, Any]) -> tuple[str, ...]:
    """The names of ``result``'s figures (file names without the format), in order: :data:`FIGURES`, then those of
    :data:`OPTIONAL_FIGURES` whose key ``result`` holds."""
    return FIGURES + tuple(name for name, (key, _) in OPTIONAL_FIGURES.items() if key in result)


def figure_of(
    name: str, result: dict[str, Any], traj: dict[str, np.ndarray], published: dict[str, np.ndarray] | None
) -> Figure:
    """The figure ``name`` (one of :func:`figure_names`; a ``KeyError`` for another name) of ``result`` and its
    trajectory ``traj``."""
    if name in FIGURES:
        return _figure(result, traj, published, name.split("_")[-1])
    return OPTIONAL_FIGURES[name][1](result, traj)


def rendered(
    name: str, result: dict[str, Any], traj: dict[str, np.ndarray], published: dict[str, np.ndarray] | None, fmt: str
) -> bytes:
    """The file of the figure ``name`` (:func:`figure_of`) in the format ``fmt``, as :func:`save` writes it."""
    buffer = io.BytesIO()
    figure_of(name, result, traj, published).savefig(buffer, format=fmt)
    return buffer.getvalue()


ROBOT_COLOURS = {"unloader": "#d62728", "loader": "#2ca02c"}  # matplotlib's tab:red and tab:green


def interference_figure(result: dict[str, Any], traj: dict[str, np.ndarray]) -> Figure:
    """The robots on their interference curves over one cycle: the slide's height and the height each tool
    needs (where it needs any), the least clearance marked; below, each tool's position on its path, the time
    it spends over the die shaded."""
    fig = Figure(figsize=(12, 6.4), layout="constrained")
    FigureCanvasAgg(fig)
    heights, paths = fig.subplots(2, 1, sharex=True, height_ratios=(3, 2))
    t = traj["time_s"]
    heights.plot(t, traj["slider_height_mm"], color="#1f77b4", lw=1.8, label="slide height")
    drawn = set()
    for r in result["robots"]["robots"]:  # (a pendulum cycle's: each robot once in each window)
        name, colour = r["name"], ROBOT_COLOURS.get(r["name"], "k")
        need = np.asarray(traj[f"{name}_needed_height_mm"], dtype=float)
        if name not in drawn:
            drawn.add(name)
            shown = np.where(needing(need), need, np.nan)
            heights.plot(t, shown, color=colour, lw=1.4, label=f"height the {name}'s tool needs")
            position = traj[f"{name}_position_mm"]
            paths.plot(t, position, color=colour, lw=1.4, label=f"{name} on its path")
            paths.fill_between(t, 0, position, where=need > 0, color=colour, alpha=0.15, lw=0)
        if r["least_clearance_mm"] is not None:
            at, which = r["least_clearance_time_s"], f"{name} {r['window']}" if "window" in r else name
            label = f"{which}: least clearance {round(r['least_clearance_mm'], 2) + 0.0:.2f} mm"  # no "-0.00"
            heights.plot([at], [r["needed_there_mm"]], "v", color=colour, ms=7, label=label)
    heights.set_ylabel("height above BDC [mm]")
    heights.set_ylim(bottom=0)
    heights.legend(loc="best", fontsize=8)
    heights.set_title(f"robots on their interference curves ({result['robots']['order']})", fontsize=9, loc="left")
    paths.set_ylabel("position from the die centre [mm]")
    pendulum = result.get("mode") == "pendulum"
    paths.set_xlabel("time from the forward swing's start [s]" if pendulum else "time from TDC [s]")
    paths.set_ylim(bottom=0)
    paths.legend(loc="center", fontsize=8, title="shaded: the tool over the die", title_fontsize=8)
    for ax in (heights, paths):
        ax.grid(alpha=0.3)
        ax.set_xlim(t[0], t[-1])
    return fig


def capacity_figure(result: dict[str, Any], traj: dict[str, np.ndarray]) -> Figure:
    """The press's own capacity (``press.capacity``): the forming force table against the tonnage curve over
    the slide's height; with a drive, the crank torque over the cycle against its capacity, both signs."""
    c = result["capacity"]
    drive = "crank_torque_Nm" in traj and c["crank_torque_capacity_kNm"] is not None
    fig = Figure(figsize=(12, 4.8), layout="constrained")
    FigureCanvasAgg(fig)
    force, torque = fig.subplots(1, 2) if drive else (fig.subplots(1, 1), None)
    if c["tonnage_curve"] is not None:
        h, f = np.array(c["tonnage_curve"]).T
        force.plot(h, f, color="#b22222", lw=1.6, label="tonnage curve (press.capacity)")
    table = result.get("process", {}).get("forming_force_kN")
    if table:
        h, f = np.array(sorted(table)).T
        force.plot(h, f, "o-", color="#1f77b4", lw=1.4, ms=4, label="process.forming_force_kN")
    use = c.get("tonnage_use")
    if use:
        closest = f"closest: {100 * use['share']:.0f} % of the curve"
        force.plot([use["height_mm"]], [use["force_kN"]], "x", color="k", ms=8, label=closest)
    tops = [max(h for h, _ in table)] if table else []
    tops += [4 * c["rated_distance_mm"]] if c.get("rated_distance_mm") else []
    if tops and c["tonnage_curve"] is not None:  # where the process works, not the whole stroke
        force.set_xlim(0.0, min(2.0 * max(tops), c["tonnage_curve"][-1][0]))
    force.set_xlabel("slide height above BDC [mm]")
    force.set_ylabel("force [kN]")
    force.set_title("the forming force against the press's tonnage curve", fontsize=9, loc="left")
    force.set_ylim(bottom=0)
    force.grid(True, lw=0.3, alpha=0.6)
    force.legend(fontsize=8)
    if torque is not None:
        x = traj["crank_angle_deg"]
        _decorate(torque, result, "angle", x, True)
        _key_ticks(torque, result, "angle")
        torque.plot(x, np.asarray(traj["crank_torque_Nm"]) / 1e3, color="#1f77b4", lw=1.4, label="crank torque")
        cap = c["crank_torque_capacity_kNm"]
        _limit(torque, x, cap, f"press.capacity.crank_torque_kNm = {cap:.1f} kN m", "#b22222", both=True)
        torque.set_ylabel("crank torque [kN m]")
        torque.set_xlabel("crank angle from TDC [deg]")
        torque.set_title("the crank's torque over the cycle", fontsize=9, loc="left")
        _legend(torque)
    fig.suptitle(f"{result['case']}: the press's capacity at {result['spm']:.3f} strokes/min")
    return fig


def energy_figure(result: dict[str, Any], traj: dict[str, np.ndarray]) -> Figure:
    """From the motor to the grid over the cycle: shaft, bus and grid power with the grid's limit and the mean
    bus power; with a storage, its energy between empty and full; the stages shaded (README, "From the motor
    to the grid")."""
    p = result["power"]
    t = _thin(traj)
    x = t["crank_angle_deg"]
    storage = p["storage_usable_kJ"] > 0
    fig = Figure(figsize=(12, 7.5 if storage else 5), layout="constrained")
    FigureCanvasAgg(fig)
    power, store = fig.subplots(2, 1, sharex=True, height_ratios=(1.6, 1)) if storage else (fig.subplots(1, 1), None)
    for ax, label in ((power, True), (store, False)):
        if ax is not None:
            _decorate(ax, result, "angle", x, label)
    _key_ticks(power, result, "angle")
    power.plot(x, t["motor_power_kW"], color="#2ca02c", lw=1.2, label="motor shaft power")
    power.plot(x, t["bus_power_kW"], color="#1f77b4", lw=1.2, label="DC-bus power (losses in)")
    grid_label = "grid power (with the storage)" if storage else "grid power (no storage: the bus less braking)"
    power.plot(x, t["grid_power_kW"], color="#d62728", lw=1.6, label=grid_label)
    power.axhline(
        p["mean_bus_power_kW"],
        color="#555555",
        lw=1.0,
        ls="-.",
        label=f"mean bus power {p['mean_bus_power_kW']:.0f} kW",
    )
    if p.get("grid_limit_kW") is not None:
        _limit(power, x, p["grid_limit_kW"], f"drive.grid.peak_power_kW = {p['grid_limit_kW']:g} kW", "#b22222")
    power.axhline(0.0, color="#444444", lw=0.6)
    power.set_ylabel("power [kW] (drawn > 0)")
    _legend(power)
    fig.suptitle(_energy_title(result, p))
    if store is None:
        power.set_xlabel("crank angle from TDC [deg]")
        return fig
    store.plot(x, t["storage_energy_kJ"], color="#9467bd", lw=1.4, label="stored energy")
    usable = p["storage_usable_kJ"]
    _limit(store, x, usable, f"drive.storage.usable_energy_kJ = {usable:g} kJ", "#b22222")
    _limit(store, x, 0.0, "empty", "#444444")
    store.set_ylabel("storage [kJ]")
    store.set_xlabel("crank angle from TDC [deg]")
    _legend(store)
    return fig


def _energy_title(result: dict[str, Any], p: dict[str, Any]) -> str:
    return (
        f"{result['case']}: from the motor to the grid at {result['spm']:.3f} strokes/min\n"
        f"grid peak {p['grid_peak_kW']:.0f} kW (without storage {p['bus_peak_kW']:.0f} kW), "
        f"{p['grid_energy_kJ']:.0f} kJ per stroke from the grid; losses: copper {p['copper_loss_kJ']:.0f}, "
        f"converter {p['converter_loss_kJ']:.0f}, gear {p['gear_loss_kJ']:.0f}, storage {p['storage_loss_kJ']:.0f}, "
        f"resistor {p['resistor_loss_kJ']:.0f} kJ"
    )


def _plus_minus(ax, value: float, label: str, **style) -> None:  # noqa: ANN001 - a matplotlib Axes
    """Horizontal lines at +value and -value, one legend entry."""
    ax.axhline(value, label=label, **style)
    ax.axhline(-value, **style)


def drive_figure(result: dict[str, Any], traj: dict[str, np.ndarray]) -> Figure:
    """The servo-sizing picture: the cycle's operating points in the torque-speed plane over the motor's
    peak envelope and rated line; motor torque and power against crank angle with the stages shaded."""
    d = result["drive"]
    motor = d["motor"]
    t = _thin(traj)
    fig = Figure(figsize=(12, 8.5), layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(2, 2, width_ratios=(1, 1.35))
    plane = fig.add_subplot(grid[:, 0])
    n_top = max(motor["max_speed_rpm"], float(np.max(np.abs(t["motor_speed_rpm"])))) * 1.05
    n = np.linspace(0.0, motor["max_speed_rpm"], 400)
    envelope = motor["peak_torque_Nm"] * np.minimum(1.0, motor["base_speed_rpm"] / np.maximum(n, TINY_RATE)) / 1e3
    for sign in (1, -1):
        plane.plot(n, sign * envelope, color="#b22222", lw=1.6, label="peak envelope" if sign > 0 else None)
    _plus_minus(plane, motor["rated_torque_Nm"] / 1e3, "rated (RMS limit)", color="#e08000", lw=1.2, ls="--")
    plane.axvline(motor["max_speed_rpm"], color="#b22222", lw=1.0, ls=":", label="max speed")
    points = plane.scatter(
        t["motor_speed_rpm"],
        t["motor_torque_Nm"] / 1e3,
        c=t["crank_angle_deg"],
        s=5,
        cmap="viridis",
        zorder=3,
        label="cycle (colour: crank angle)",
    )
    plane.axhline(d["rms_motor_torque_Nm"] / 1e3, color="#1f77b4", lw=1.0, ls="-.", label="RMS of the cycle")
    fig.colorbar(points, ax=plane, label="crank angle [deg]", shrink=0.6)
    plane.set_xlim(0, n_top)
    plane.set_xlabel("motor speed [rpm]")
    plane.set_ylabel("motor torque [kN m]")
    plane.set_title("torque-speed plane (all motors)")
    plane.grid(True, lw=0.3, alpha=0.6)
    plane.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2)
    torque = fig.add_subplot(grid[0, 1])
    power = fig.add_subplot(grid[1, 1], sharex=torque)
    x = t["crank_angle_deg"]
    for ax, label in ((torque, True), (power, False)):
        _decorate(ax, result, "angle", x, label)
    _key_ticks(torque, result, "angle")
    torque.plot(x, t["motor_torque_Nm"] / 1e3, color="#1f77b4", lw=1.4, label="motor torque")
    speed = np.abs(t["motor_speed_rpm"])
    at_speed = motor["peak_torque_Nm"] * np.minimum(1.0, motor["base_speed_rpm"] / np.maximum(speed, TINY_RATE)) / 1e3
    envelope_label = "drive.motor.peak_torque_Nm: the envelope at the motor's speed"
    _limit(torque, x, at_speed, envelope_label, "#b22222", both=True)  # falls above the base speed
    rated = motor["rated_torque_Nm"] / 1e3
    _limit(torque, x, rated, f"drive.motor.rated_torque_Nm = {rated:g} kN m (RMS limit)", "#e08000", both=True)
    torque.set_ylabel("motor torque [kN m]")
    _legend(torque)
    power.plot(x, t["motor_power_kW"], color="#2ca02c", lw=1.4, label="motor power (drawn > 0)")
    power.axhline(0.0, color="#444444", lw=0.6)
    power.set_ylabel("motor power [kW]")
    power.set_xlabel("crank angle from TDC [deg]")
    _legend(power)
    fig.suptitle(
        f"{result['case']}: the drive at {result['spm']:.3f} strokes/min\n"
        f"peak {d['peak_motor_torque_Nm'] / 1e3:.1f} kN m "
        f"({d['peak_torque_use_pct']:.0f} % of envelope), RMS {d['rms_motor_torque_Nm'] / 1e3:.1f} kN m "
        f"({d['rms_torque_use_pct']:.0f} % of rated), net {d['energy_net_kJ']:.0f} kJ per stroke"
    )
    return fig


def save(fig: Figure, path: Path) -> None:
    """Write one figure; the format follows the file name (``.png`` at 90 dpi)."""
    fig.savefig(path, format=path.suffix.lstrip("."))


def _column(rows: list[dict[str, Any]], key: str) -> np.ndarray:
    """One column of sweep rows as floats (NaN where empty)."""
    return np.array([float(r[key]) if r.get(key) not in ("", None) else np.nan for r in rows])


def sweep_figure(rows: list[dict[str, Any]], fields: list[str], title: str) -> Figure:
    """SPM against the swept field (one field: the points without a verified plan as red crosses on a row
    of their own below the curve) or a heat map of SPM (two fields: each cell's SPM written in it, the
    cells without a plan hatched); legends outside the data."""
    from matplotlib.patches import Patch, Rectangle

    fig = Figure(figsize=(10, 6.5), dpi=90)
    FigureCanvasAgg(fig)
    spm = np.array([float(r["spm"]) if r.get("spm") not in ("", None) else np.nan for r in rows])
    ok = np.array([Outcome.of(r.get("status")).succeeded for r in rows])
    if len(fields) == 1:
        ax, fails = fig.subplots(2, 1, sharex=True, height_ratios=(1, 0.08))
        fig.subplots_adjust(right=0.75, hspace=0.08)
        x = np.array([float(r[fields[0]]) for r in rows])
        ax.plot(x[ok], spm[ok], "o-", color="tab:blue", ms=4, lw=1.4, label="verified plan")
        fails.plot(x[~ok], np.zeros((~ok).sum()), "x", color="tab:red", ms=7, mew=1.5, label="no verified plan")
        fails.set_yticks([])
        fails.set_ylabel("failed", rotation=0, ha="right", va="center", fontsize=8)
        fails.set_xlabel(fields[0])
        ax.set_ylabel("strokes per minute")
        ax.grid(True, lw=0.3)
        fails.grid(True, axis="x", lw=0.3)
        grid = _column(rows, "grid_peak_kW")
        twins = [fails]
        if np.any(np.isfinite(grid[ok])):  # the drive's electrical side: the plant's peak beside the SPM
            power = ax.twinx()
            power.plot(x[ok], grid[ok], "s-", color="tab:red", ms=4, lw=1.4, label="grid peak [kW]")
            mean = _column(rows, "mean_bus_power_kW")[ok]
            power.plot(x[ok], mean, "--", color="tab:gray", lw=1.2, label="mean bus power [kW]")
            power.set_ylabel("power [kW]")
            power.set_ylim(bottom=0)
            twins.append(power)
        _legend(ax, *twins, anchor=(1.02 if len(twins) == 1 else 1.12, 1.0))
    else:
        ax = fig.subplots()
        fig.subplots_adjust(right=0.78)
        xs = sorted({float(r[fields[0]]) for r in rows})
        ys = sorted({float(r[fields[1]]) for r in rows})
        z = np.full((len(ys), len(xs)), np.nan)
        for r, v, good in zip(rows, spm, ok, strict=True):
            z[ys.index(float(r[fields[1]])), xs.index(float(r[fields[0]]))] = v if good else np.nan
        mesh = ax.pcolormesh(xs, ys, z, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="strokes per minute")
        dx = (xs[1] - xs[0]) if len(xs) > 1 else 1.0
        dy = (ys[1] - ys[0]) if len(ys) > 1 else 1.0
        small = len(xs) * len(ys) <= MAX_CELL_LABELS
        for i, yv in enumerate(ys):
            for j, xv in enumerate(xs):
                if np.isnan(z[i, j]):
                    ax.add_patch(
                        Rectangle((xv - dx / 2, yv - dy / 2), dx, dy, fill=False, hatch="xx", lw=0, edgecolor="tab:red")
                    )
                elif small:
                    bright = (z[i, j] - np.nanmin(z)) > 0.6 * (np.nanmax(z) - np.nanmin(z))
                    ax.text(
                        xv,
                        yv,
                        f"{z[i, j]:.2f}",
                        ha="center",
                        va="center",
                        fontsize=7,
                        color="black" if bright else "white",
                    )
        ax.legend(
            handles=[Patch(fill=False, hatch="xx", edgecolor="tab:red", label="no verified plan")],
            loc="upper left",
            bbox_to_anchor=(1.25, 1.0),
            borderaxespad=0.0,
            fontsize=8,
        )
        ax.set_xlabel(fields[0])
        ax.set_ylabel(fields[1])
    ax.set_title(title, fontsize=10)
    return fig


MAX_CELL_LABELS = 400  # a heat map writes each cell's SPM up to this many cells


def laws_figure(curves: dict[str, dict[str, np.ndarray]], title: str) -> Figure:
    """Crank speed and crank acceleration against crank angle from TDC, one line per motion law.
    ``curves``: law -> columns ``crank_angle_deg``, ``crank_speed_rpm``, ``crank_accel_rad_s2``."""
    fig = Figure(figsize=(10, 7), dpi=90)
    FigureCanvasAgg(fig)
    top, bottom = fig.subplots(2, 1, sharex=True)
    for law, c in curves.items():
        top.plot(c["crank_angle_deg"], c["crank_speed_rpm"], lw=1.3, label=law)
        bottom.plot(c["crank_angle_deg"], c["crank_accel_rad_s2"], lw=1.1, label=law)
    top.set_ylabel("crank speed [rpm]")
    bottom.set_ylabel("crank acceleration [rad/s²]")
    bottom.set_xlabel("crank angle from TDC [deg]")
    bottom.set_xlim(0.0, 360.0)
    for ax in (top, bottom):
        ax.grid(True, lw=0.3)
    fig.subplots_adjust(right=0.8)
    _legend(top, anchor=(1.02, 1.0))
    top.set_title(title, fontsize=10)
    return fig


def tradeoff_figure(rows: list[dict[str, Any]], case: Any, title: str) -> Figure:
    """The motor-sizing picture: RMS and peak motor torque against SPM with the motor's rated and peak
    torque as lines (top), energy from the supply per stroke against SPM on an axis around the data
    (middle), and what the optimised plan saves against the baseline, in % (bottom); optimised plans
    solid, the baseline (the max-SPM plan with the spare time given to the transfer) dashed; with the
    grid's side (``grid_peak_kW`` in the rows) the grid's peak on a second axis of the middle panel and its
    saving below; a rate without a plan as a red line. Legends right of the panels."""
    fig = Figure(figsize=(12, 10), dpi=90)
    fig.subplots_adjust(left=0.08, right=0.68, top=0.94, bottom=0.07, hspace=0.25)
    FigureCanvasAgg(fig)
    top, middle, bottom = fig.subplots(3, 1, sharex=True)
    ok = [r for r in rows if Outcome.of(r.get("status")).succeeded]
    spm = np.array([float(r["target_spm"]) for r in ok])

    def column(name: str) -> np.ndarray:
        return np.array([float(r[name]) for r in ok])

    motor = case.drive.motor
    curves = (  # axis, column, scale, marker, colour, label; each optimised (solid) and baseline (dashed)
        (top, "rms_motor_torque_Nm", 1e-3, "o", "tab:blue", "RMS"),
        (top, "peak_motor_torque_Nm", 1e-3, "s", "tab:orange", "peak"),
        (middle, "energy_kJ", 1.0, "o", "tab:green", "energy"),
    )
    for ax, name, unit, marker, colour, what in curves if ok else ():
        for prefix, style, label in (
            ("", dict(lw=1.5, ms=4), "optimised"),
            ("baseline_", dict(lw=1, ms=3, mfc="none"), "baseline"),
        ):
            ls = "-" if not prefix else "--"
            ax.plot(spm, column(prefix + name) * unit, marker + ls, color=colour, label=f"{what}, {label}", **style)
    grid = bool(ok) and all(r.get("grid_peak_kW") is not None for r in ok)
    if grid:
        right = middle.twinx()
        right.plot(spm, column("grid_peak_kW"), "D-", color="tab:purple", lw=1.5, ms=4, label="grid peak, optimised")
        right.plot(
            spm,
            column("baseline_grid_peak_kW"),
            "D--",
            color="tab:purple",
            lw=1,
            ms=3,
            mfc="none",
            label="grid peak, baseline",
        )
        right.set_ylabel("grid peak [kW]", color="tab:purple")
        highest = max(float(np.max(column("grid_peak_kW"))), float(np.max(column("baseline_grid_peak_kW"))))
        right.set_ylim(0, 1.1 * highest)  # the highest point inside the frame, not on its edge
    savings = (
        ("rms_motor_torque_Nm", "o", "tab:blue", "RMS torque"),
        ("energy_kJ", "o", "tab:green", "energy per stroke"),
    ) + ((("grid_peak_kW", "D", "tab:purple", "grid peak"),) if grid else ())
    for name, marker, colour, what in savings:
        if ok:
            saving = 100.0 * (1.0 - column(name) / column("baseline_" + name))
            bottom.plot(spm, saving, marker + "-", color=colour, lw=1.5, ms=4, label=f"{what} saved")
    bottom.axhline(0.0, color="#444444", lw=0.6)
    top.axhline(motor.rated_torque_Nm / 1e3, color="tab:blue", lw=1, ls=":", label="drive.motor.rated_torque_Nm")
    top.axhline(motor.peak_torque_Nm / 1e3, color="tab:orange", lw=1, ls=":", label="drive.motor.peak_torque_Nm")
    failed = [float(r["target_spm"]) for r in rows if not Outcome.of(r.get("status")).succeeded]
    for ax in (top, middle, bottom):
        for i, x in enumerate(failed):
            ax.axvline(x, color="tab:red", lw=0.8, alpha=0.6, label="no plan at this rate" if i == 0 else None)
    top.set_ylabel("motor torque [kN m]")
    top.set_ylim(bottom=0)
    middle.set_ylabel("energy from the supply\nper stroke [kJ]")
    middle.margins(y=0.15)  # around the data: the difference between the curves is the point
    bottom.set_ylabel("saved against\nthe baseline [%]")
    bottom.set_xlabel("strokes per minute")
    for ax in (top, middle, bottom):
        ax.grid(True, lw=0.3)
        twins = (right,) if grid and ax is middle else ()
        _legend(ax, *twins, anchor=(1.12 if twins else 1.02, 1.0))
    top.set_title(title, fontsize=10)
    return fig


LINE_COLOURS = (  # one per station, up to a line's most (planning.model.line.MAX_STATIONS)
    "#1f77b4",
    "#d62728",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#8c564b",
    "#e377c2",
    "#17becf",
    "#bcbd22",
    "#7f7f7f",
    "#393b79",
    "#637939",
)


def line_figure(result: dict[str, Any], traj: dict[str, np.ndarray]) -> Figure:
    """A press line over one master cycle, two with a pendulum press (``planning.reports.line``): each press's
    slide and the height its robots' tools need (dashed, where they need any); below, each robot's cycle as bars:
    inside a press in the press's colour, its moves between the presses grey, away (the feeder's, the exit's)
    light."""
    fig = Figure(figsize=(12, 7.2), layout="constrained")
    FigureCanvasAgg(fig)
    heights, bars = fig.subplots(2, 1, sharex=True, height_ratios=(3, 2))
    t, period = traj["time_s"], result["period_s"]
    horizon = result.get("horizon_s", period)  # two master cycles with a pendulum press (its swings alternate)
    colour = {s["name"]: LINE_COLOURS[k % len(LINE_COLOURS)] for k, s in enumerate(result["stations"])}
    for s in result["stations"]:
        name = s["name"]
        heights.plot(t, traj[f"{name}_slide_mm"], color=colour[name], lw=1.8, label=f"{name}: slide")
        need = np.asarray(traj[f"{name}_needed_height_mm"], dtype=float)
        heights.plot(t, np.where(needing(need), need, np.nan), "--", color=colour[name], lw=1.2)
    heights.plot([], [], "--", color="k", lw=1.2, label="height the robots' tools need")
    heights.set_ylabel("height above BDC [mm]")
    heights.set_ylim(bottom=0)
    heights.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, borderaxespad=0.0)
    neck = result["bottleneck"]
    title = f"{result['line']}: {result['spm']:.3f} strokes/min, cycle {period:.4f} s"
    heights.set_title(title + f"; bottleneck: {neck['kind']} {neck['name']}", fontsize=9, loc="left")
    names = []
    for row, robot in enumerate(result["robots"]):
        names.append(robot["name"])
        for stretch in robot["stretches"]:
            if stretch["what"] == "wait":
                continue
            inside = stretch["station"]
            face = colour[inside] if inside else ("#bbbbbb" if stretch["what"] != "away" else "#e6e6e6")
            for start in np.arange(stretch["start_s"] - period, horizon, period):  # (a stretch over an end wraps)
                bars.broken_barh([(start, stretch["duration_s"])], (row - 0.35, 0.7), facecolors=face)
    bars.set_yticks(range(len(names)), names, fontsize=8)
    bars.invert_yaxis()
    bars.set_xlabel("time on the line's master [s]")
    what = "robots: inside a press (its colour), moving between presses (grey), away (light)"
    bars.set_title(what, fontsize=9, loc="left")
    for ax in (heights, bars):
        ax.grid(alpha=0.3)
        ax.set_xlim(0.0, horizon)
    return fig


def swing_figure(result: dict[str, Any], traj: dict[str, np.ndarray]) -> Figure:
    """A pendulum plan (``planning.reports.pendulum``): the crank angle, its signed speed and the slide against
    time (the robot's windows through the turns shaded), and the slide against crank angle for each swing."""
    fig = Figure(figsize=(11, 7.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots(2, 2)
    t, theta, h = traj["time_s"], traj["crank_angle_deg"], traj["slider_height_mm"]
    safety_mm, die_mm = result["swing"]["safety_height_mm"], result["swing"]["die_height_mm"]
    f, b = result["swings"]["forward"]["key_points"], result["swings"]["backward"]["key_points"]
    period = result["cycle_time_s"]
    windows = [(f[3]["time_s"], b[0]["time_s"]), (b[3]["time_s"], period), (0.0, f[0]["time_s"])]
    ax[0, 0].plot(t, theta, color="C0")
    ax[0, 0].set(xlabel="time [s]", ylabel="crank angle [deg from TDC]", title="the crank swings through BDC")
    ax[0, 1].plot(t, traj["crank_speed_rpm"], color="C1")
    ax[0, 1].axhline(0.0, color="0.6", lw=0.8)
    ax[0, 1].set(xlabel="time [s]", ylabel="crank speed [rpm] (negative: backward)", title="crank speed")
    ax[1, 0].plot(t, h, color="C2", label="slide")
    ax[1, 0].set(xlabel="time [s]", ylabel="slide height above BDC [mm]", title="slide: two strokes a cycle")
    for a in (ax[0, 0], ax[0, 1], ax[1, 0]):
        for k, (lo, hi) in enumerate(windows):
            label = "theta4 .. theta1" if "robots" in result else "robot's window"
            a.axvspan(lo, hi, color="0.85", zorder=0, label=label if (k == 0 and a is ax[1, 0]) else None)
    forward = t <= result["swings"]["forward"]["time_s"]
    ax[1, 1].plot(theta[forward], h[forward], color="C0", label="forward swing")
    ax[1, 1].plot(theta[~forward], h[~forward], color="C3", ls="--", label="backward swing")
    for a in (ax[1, 0], ax[1, 1]):
        if safety_mm is not None:  # (with robots their curves, not one height)
            a.axhline(safety_mm, color="C4", lw=1, ls=":", label="safety height")
        a.axhline(die_mm, color="C5", lw=1, ls=":", label="die height")
    for key in f + b:
        ax[1, 1].plot(key["angle_deg"], key["height_mm"], "k.", ms=5)
    ax[1, 1].set(
        xlabel="crank angle [deg from TDC]", ylabel="slide height above BDC [mm]", title="slide against crank angle"
    )
    ax[1, 0].legend(loc="upper right", fontsize=8)
    ax[1, 1].legend(loc="upper center", fontsize=8)
    fig.suptitle(
        f"{result['case']}: {result['spm']:.3f} strokes/min in pendulum strokes ({result['status']})", fontsize=11
    )
    return fig


# the figures a result has where it holds a key: name -> (that key, the function that draws it)
OPTIONAL_FIGURES = {
    "drive": ("drive", drive_figure),
    "energy": ("power", energy_figure),
    "capacity": ("capacity", capacity_figure),
    "interference": ("robots", interference_figure),
}
