"""The figures: ``motion_vs_time`` and ``motion_vs_angle`` (the slide and the crank, every limit where it
applies), ``drive`` (with a drive: the torque-speed plane, torque and power), ``energy`` (with the drive's
electrical side), ``capacity`` (with ``press.capacity``: the tonnage curve, the crank torque) and ``interference``
(with robots: the slide against each tool's needed height, their paths); drawn from
``result.json``'s data and the trajectory (``pressplan plot`` redraws them from those files)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from planning.reports.folder import OutputError
from planning.reports.outputs import Option, Output, Writer, Written

if TYPE_CHECKING:
    import numpy as np

PLOT_FORMATS = ("png", "svg", "pdf")
FORMAT = Option(
    "--format",
    {"dest": "plot_format", "choices": PLOT_FORMATS, "default": "png", "help": "figure format (default png)"},
)
NO_PLOTS = Option("--no-plots", {"dest": "no_plots", "action": "store_true", "help": "do not draw the figures"})


def _writers(w: Written) -> dict[str, Writer]:
    from planning.reports.report import TRAJECTORY_COLUMNS

    published = w.published
    pub_cols = dict(zip(TRAJECTORY_COLUMNS, published.T, strict=True)) if published is not None else None
    return _drawn(w.result, w.columns, pub_cols, w.option("plot_format"), w.side_by_side_workers)


def _drawn(
    result: dict,
    traj: dict[str, np.ndarray],
    published: dict[str, np.ndarray] | None,
    plot_format: str,
    side_by_side_workers: bool,
) -> dict[str, Writer]:
    """The writers of the figures of ``result``, drawn now: with ``side_by_side_workers``, where a core is free
    (``planning.solver.ahead.core_free``), in two forked workers at once (``side_by_side``: the same files, byte for
    byte; a figure takes a few tenths of a second to draw and save), else here in turn."""
    from planning.reports.plots import figure_names, rendered
    from planning.solver.ahead import core_free, in_turn, side_by_side

    names = figure_names(result)
    draw = side_by_side if side_by_side_workers and core_free() else in_turn
    files = draw(rendered, [(name, result, traj, published, plot_format) for name in names])
    return {f"{name}.{plot_format}": _bytes_writer(data) for name, data in zip(names, files, strict=True)}


def _bytes_writer(data: bytes) -> Writer:
    return lambda path: path.write_bytes(data)


def redraw(folder: Path, plot_format: str = "png", side_by_side_workers: bool = False) -> dict[str, Writer]:
    """The figures redrawn from a finished output folder's result.json and trajectory.csv (``pressplan plot``;
    ``side_by_side_workers``: as :attr:`Written.side_by_side_workers`)."""
    from planning.reports.plots import read_table, save

    try:
        result = json.loads((folder / "result.json").read_text(encoding="utf-8"))
        traj = read_table(folder / "trajectory.csv")
        pub_path = folder / "published_profile.csv"
        published = read_table(pub_path) if pub_path.exists() else None
        if result.get("mode") == "pendulum":  # a pendulum plan's own figure (``planning.reports.pendulum``)
            from planning.reports.plots import swing_figure

            figure = swing_figure(result, traj)
            return {f"swing.{plot_format}": lambda p: save(figure, p)}
        return _drawn(result, traj, published, plot_format, side_by_side_workers)
    except (OSError, ValueError, KeyError, IndexError, TypeError, AttributeError) as exc:
        reason = " ".join(str(exc).split())[:120] or type(exc).__name__
        raise OutputError(f"{folder}: not a finished pressplan output folder ({reason})") from None


OUTPUT = Output(
    "motion_vs_time.*",
    "the figures",
    ("motion_vs_time.*", "motion_vs_angle.*", "drive.*", "energy.*", "capacity.*", "interference.*"),
    _writers,
    order=90,
    figure=True,
    options=(FORMAT, NO_PLOTS),
)
