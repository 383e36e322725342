"""Figures of a solved plan, drawn from its files (``result.json``, ``trajectory.csv`` and, when the
case has a published solution, ``published_profile.csv``). Headless: matplotlib's Agg canvas, no
pyplot. Two figures, each with the paper's three result plots stacked (Figs. 7, 8, 9): one against
time from TDC, one against crank angle. Key points marked, limits dashed, stages shaded."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

STAGE_COLOURS = {"transfer": "#d9ecff", "feed": "#fff2cc", "draw": "#e2f0d9", "return": "#fde2e2"}
KEY_LABELS = {
    "closing": "θ1 closing",
    "draw_start": "θ2 draw start",
    "draw_end": "θ3 draw end",
    "opening": "θ4 opening",
}
PLOT_FORMATS = ("png", "svg", "pdf")
FIGURES = ("motion_vs_time", "motion_vs_angle")


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


def _stages(result: dict[str, Any], axis: str) -> list[tuple[str, float, float]]:
    """(stage, start, end) spans in time [s] or crank angle [deg], merged over neighbouring segments."""
    spans: list[tuple[str, float, float]] = []
    for seg in result["segments"]:
        stage = seg["name"].split(":")[0]
        if axis == "time":
            a, b = seg["start_time_s"], seg["start_time_s"] + seg["duration_s"]
        else:
            a, b = seg["start_angle_deg"], seg["end_angle_deg"]
        if spans and spans[-1][0] == stage:
            spans[-1] = (stage, spans[-1][1], b)
        else:
            spans.append((stage, a, b))
    return spans


def _decorate(ax, result: dict[str, Any], axis: str, label_stages: bool) -> None:
    for stage, a, b in _stages(result, axis):
        ax.axvspan(a, b, color=STAGE_COLOURS.get(stage, "#eeeeee"), alpha=0.6, lw=0, zorder=0)
        if label_stages and b > a:
            ax.text(
                (a + b) / 2,
                0.97,
                stage,
                transform=ax.get_xaxis_transform(),
                ha="center",
                va="top",
                fontsize=8,
                color="#555555",
                style="italic",
            )
    for k in result["key_points"]:
        x = k["time_s"] if axis == "time" else k["angle_deg"]
        ax.axvline(x, color="#444444", lw=0.8, ls=":", zorder=1)
    ax.grid(True, lw=0.3, alpha=0.6)


def _key_labels(ax, result: dict[str, Any], axis: str) -> None:
    for k in result["key_points"]:
        x = k["time_s"] if axis == "time" else k["angle_deg"]
        ax.text(
            x,
            0.02,
            " " + KEY_LABELS.get(k["name"], k["name"]),
            transform=ax.get_xaxis_transform(),
            rotation=90,
            fontsize=7.5,
            va="bottom",
            ha="right",
            color="#333333",
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
    """The rebuilt published solution, dashed, when there is one."""
    if published is not None:
        ax.plot(x, published[column], color=colour, lw=1.0, ls="--", alpha=alpha, label="published solution (rebuilt)")


def _figure(result, traj, published, axis: str) -> Figure:
    traj, published = _thin(traj), _thin(published)
    lim = result.get("limits", {})
    proc = result.get("process", {})
    x = traj["time_s"] if axis == "time" else traj["crank_angle_deg"]
    xp = None
    if published is not None:
        xp = published["time_s"] if axis == "time" else published["crank_angle_deg"]
    xlabel = "time from TDC [s]" if axis == "time" else "crank angle from TDC [deg]"
    fig = Figure(figsize=(11, 10.5), dpi=90)
    fig.subplots_adjust(left=0.08, right=0.91, top=0.93, bottom=0.06, hspace=0.22)
    FigureCanvasAgg(fig)
    axes = fig.subplots(3, 1, sharex=True)
    title = (
        f"{result['case']}: {result['spm']:.2f} strokes/min, cycle {result['cycle_time_s']:.3f} s "
        f"({result['motion_law']}, {result['placement']} placement, {result['status']})"
    )
    fig.suptitle(title, fontsize=11)

    # (a) Fig. 7: slider height and crank speed
    ax = axes[0]
    _decorate(ax, result, axis, True)
    ax.plot(x, traj["slider_height_mm"], color="tab:blue", lw=1.6, label="slider height")
    for name, val in (("safety height", proc.get("safety_height_mm")), ("die height", lim.get("die_height_mm"))):
        if val is not None:
            ax.axhline(val, color="tab:blue", ls="--", lw=0.9)
            ax.text(x[-1], val, f" {name} {val:g} mm", fontsize=7.5, va="bottom", ha="right", color="tab:blue")
    ax.set_ylabel("slider height above BDC [mm]", color="tab:blue")
    ax2 = ax.twinx()
    ax2.plot(x, traj["crank_speed_rpm"], color="tab:red", lw=1.6, label="crank speed")
    _overlay(ax2, xp, published, "crank_speed_rpm", "tab:red", 0.7)
    ax2.set_ylabel("crank speed [rpm]", color="tab:red")
    ax2.set_ylim(bottom=0)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="center left", fontsize=8, framealpha=0.9)
    ax.set_title("slider height and crank speed (paper Fig. 7)", fontsize=9, loc="left")
    _key_labels(ax, result, axis)

    # (b) Fig. 8: crank acceleration
    ax = axes[1]
    _decorate(ax, result, axis, False)
    ax.plot(x, traj["crank_accel_rad_s2"], color="tab:purple", lw=1.6, label="crank acceleration")
    _overlay(ax, xp, published, "crank_accel_rad_s2", "tab:purple", 0.7)
    ax.axhline(0, color="black", lw=0.6)
    ax.set_ylabel("crank acceleration [rad/s²]")
    ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    ax.set_title("crank acceleration (paper Fig. 8)", fontsize=9, loc="left")

    # (c) Fig. 9: slider speed and acceleration
    ax = axes[2]
    _decorate(ax, result, axis, False)
    ax.plot(x, traj["slider_speed_mm_s"], color="tab:green", lw=1.6, label="slider speed (up +)")
    ax.set_ylabel("slider speed [mm/s]", color="tab:green")
    ax2 = ax.twinx()
    ax2.plot(x, traj["slider_accel_mm_s2"], color="tab:orange", lw=1.6, label="slider acceleration")
    a_lim = lim.get("slider_accel_mm_s2")
    if a_lim is not None:
        for sign in (1, -1):
            ax2.axhline(sign * a_lim, color="tab:orange", ls="--", lw=0.9)
        ax2.text(x[-1], a_lim, f"±{a_lim:g} mm/s² limit ", fontsize=7.5, va="top", ha="right", color="tab:orange")
        ax2.set_ylim(-1.15 * a_lim, 1.15 * a_lim)
    _overlay(ax2, xp, published, "slider_accel_mm_s2", "tab:orange", 0.6)
    ax2.set_ylabel("slider acceleration [mm/s²]", color="tab:orange")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="lower left", fontsize=8, framealpha=0.9)
    ax.set_title("slider speed and acceleration (paper Fig. 9)", fontsize=9, loc="left")

    axes[-1].set_xlabel(xlabel)
    axes[-1].set_xlim(x[0], x[-1])
    return fig


def plot_files(
    result: dict[str, Any], traj: dict[str, np.ndarray], published: dict[str, np.ndarray] | None, fmt: str = "png"
) -> dict[str, Figure]:
    """The figures by file name (``motion_vs_time.<fmt>``, ``motion_vs_angle.<fmt>``, and ``drive.<fmt>``
    when the result has a drive)."""
    out = {f"{name}.{fmt}": _figure(result, traj, published, name.split("_")[-1]) for name in FIGURES}
    if "drive" in result:
        out[f"drive.{fmt}"] = drive_figure(result, traj)
    return out


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
    grid = fig.add_gridspec(2, 2, width_ratios=(1, 1.35))
    plane = fig.add_subplot(grid[:, 0])
    n_top = max(motor["max_speed_rpm"], float(np.max(np.abs(t["motor_speed_rpm"])))) * 1.05
    n = np.linspace(0.0, motor["max_speed_rpm"], 400)
    envelope = motor["peak_torque_Nm"] * np.minimum(1.0, motor["base_speed_rpm"] / np.maximum(n, 1e-9)) / 1e3
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
    plane.legend(fontsize=8, loc="lower right")
    torque = fig.add_subplot(grid[0, 1])
    power = fig.add_subplot(grid[1, 1], sharex=torque)
    x = t["crank_angle_deg"]
    for ax, label_stages in ((torque, True), (power, False)):
        _decorate(ax, result, "angle", label_stages)
    torque.plot(x, t["motor_torque_Nm"] / 1e3, color="#1f77b4", lw=1.4, label="motor torque")
    _plus_minus(torque, motor["peak_torque_Nm"] / 1e3, "peak torque", color="#b22222", lw=1.0, ls="--")
    torque.set_ylabel("motor torque [kN m]")
    torque.legend(fontsize=8, loc="lower left")
    power.plot(x, t["motor_power_kW"], color="#2ca02c", lw=1.4, label="motor power (drawn > 0)")
    power.axhline(0.0, color="#444444", lw=0.6)
    power.set_ylabel("motor power [kW]")
    power.set_xlabel("crank angle from TDC [deg]")
    power.legend(fontsize=8, loc="lower left")
    _key_labels(power, result, "angle")
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


def sweep_figure(rows: list[dict[str, Any]], fields: list[str], title: str) -> Figure:
    """SPM against the swept field (one field) or a heat map of SPM (two fields); failed points shown."""
    fig = Figure(figsize=(9, 6), dpi=90)
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    spm = np.array([float(r["spm"]) if r.get("spm") not in ("", None) else np.nan for r in rows])
    ok = np.array([r.get("status") == "verified" for r in rows])
    if len(fields) == 1:
        x = np.array([float(r[fields[0]]) for r in rows])
        ax.plot(x[ok], spm[ok], "o-", color="tab:blue", ms=4, lw=1.4, label="verified plan")
        if (~ok).any():
            ax.plot(
                x[~ok],
                np.full((~ok).sum(), np.nanmin(spm) if ok.any() else 0.0),
                "x",
                color="tab:red",
                label="no verified plan",
            )
        ax.set_xlabel(fields[0])
        ax.set_ylabel("strokes per minute")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=9)
    else:
        xs = sorted({float(r[fields[0]]) for r in rows})
        ys = sorted({float(r[fields[1]]) for r in rows})
        z = np.full((len(ys), len(xs)), np.nan)
        for r, v in zip(rows, spm, strict=True):
            z[ys.index(float(r[fields[1]])), xs.index(float(r[fields[0]]))] = v
        mesh = ax.pcolormesh(xs, ys, z, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="strokes per minute")
        ax.set_xlabel(fields[0])
        ax.set_ylabel(fields[1])
    ax.set_title(title, fontsize=10)
    return fig


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
    top.legend(fontsize=8, ncol=3)
    top.set_title(title, fontsize=10)
    return fig


def tradeoff_figure(rows: list[dict[str, Any]], case: Any, title: str) -> Figure:
    """The motor-sizing picture: RMS and peak motor torque against SPM with the motor's rated and peak
    torque as lines (top), energy from the supply per stroke against SPM (bottom); optimised plans solid,
    the baseline (the max-SPM plan with the spare time given to the transfer) dashed."""
    fig = Figure(figsize=(9, 7.5), dpi=90)
    FigureCanvasAgg(fig)
    top, bottom = fig.subplots(2, 1, sharex=True)
    ok = [r for r in rows if r.get("status") == "verified"]
    spm = np.array([float(r["target_spm"]) for r in ok])

    def column(name: str) -> np.ndarray:
        return np.array([float(r[name]) for r in ok])

    motor = case.drive.motor
    curves = (  # axis, column, scale, marker, colour, label; each optimised (solid) and baseline (dashed)
        (top, "rms_motor_torque_Nm", 1e-3, "o", "tab:blue", "RMS"),
        (top, "peak_motor_torque_Nm", 1e-3, "s", "tab:orange", "peak"),
        (bottom, "supply_energy_kJ", 1.0, "o", "tab:green", ""),
    )
    for ax, name, unit, marker, colour, what in curves if ok else ():
        for prefix, style, label in (
            ("", dict(lw=1.5, ms=4), "optimised"),
            ("baseline_", dict(lw=1, ms=3, mfc="none"), "baseline"),
        ):
            ls = "-" if not prefix else "--"
            ax.plot(
                spm,
                column(prefix + name) * unit,
                marker + ls,
                color=colour,
                label=", ".join(filter(None, (what, label))),
                **style,
            )
    top.axhline(motor.rated_torque_Nm / 1e3, color="tab:blue", lw=1, ls=":", label="rated torque")
    top.axhline(motor.peak_torque_Nm / 1e3, color="tab:orange", lw=1, ls=":", label="peak torque")
    failed = [float(r["target_spm"]) for r in rows if r.get("status") != "verified"]
    for x in failed:
        top.axvline(x, color="tab:red", lw=0.8, alpha=0.5)
    top.set_ylabel("motor torque [kN m]")
    top.set_ylim(bottom=0)
    bottom.set_ylabel("energy from the supply per stroke [kJ]")
    bottom.set_xlabel("strokes per minute" + (" (red: no plan at this rate)" if failed else ""))
    bottom.set_ylim(bottom=0)
    for ax in (top, bottom):
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=8, ncol=3)
    top.set_title(title, fontsize=10)
    return fig
