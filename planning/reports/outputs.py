"""The files of a solved plan (``solve``) and of a redrawn folder (``plot``), as writers for
:func:`planning.reports.folder.write_atomic`."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from planning.model.case import Case
from planning.reports.cam_table import CAM_COLUMNS, DEFAULT_POINTS, cam_header, cam_table
from planning.reports.folder import OutputError, write_json, write_table
from planning.reports.report import (
    TRAJECTORY_COLUMNS,
    result_dict,
    sample_profile,
    summary_text,
    trajectory,
    trajectory_columns,
)
from planning.reports.source_solution import rebuild_profile
from planning.solver.solution import Solution


def solution_writers(
    solution: Solution,
    case: Case,
    *,
    cam_points: int = DEFAULT_POINTS,
    plot_format: str | None = "png",
    result: dict | None = None,
) -> dict[str, Callable[[Path], None]]:
    """The files ``pressplan solve`` writes: result.json, trajectory.csv, cam_table.csv, summary.txt,
    published_profile.csv (when the case has a published solution) and the figures
    (``plot_format`` None: no figures); ``result``: the solution's :func:`result_dict` when the caller has
    it already."""
    result = result if result is not None else result_dict(solution, case)
    columns = trajectory(solution, case)
    traj = np.column_stack(list(columns.values()))
    cam = cam_table(solution.plan, cam_points)
    cam_head = cam_header(solution.plan, case.name, cam_points)
    writers: dict[str, Callable[[Path], None]] = {
        "result.json": lambda p: write_json(p, result),
        "trajectory.csv": lambda p: write_table(p, traj, trajectory_columns(case)),
        "cam_table.csv": lambda p: write_table(p, cam, CAM_COLUMNS, cam_head),
        "summary.txt": lambda p: p.write_text(summary_text(result) + "\n", encoding="utf-8"),
    }
    rebuilt = rebuild_profile(case)
    published = sample_profile(rebuilt, case.machine) if rebuilt is not None else None
    if published is not None:
        writers["published_profile.csv"] = lambda p: write_table(p, published, TRAJECTORY_COLUMNS)
    if plot_format:
        from planning.reports.plots import plot_files, save

        pub_cols = dict(zip(TRAJECTORY_COLUMNS, published.T, strict=True)) if published is not None else None
        for name, fig in plot_files(result, columns, pub_cols, plot_format).items():
            writers[name] = lambda p, fig=fig: save(fig, p)
    return writers


def plot_writers(folder: Path, plot_format: str = "png") -> dict[str, Callable[[Path], None]]:
    """Figures redrawn from a finished output folder's result.json and trajectory.csv."""
    from planning.reports.plots import plot_files, read_table, save

    try:
        result = json.loads((folder / "result.json").read_text(encoding="utf-8"))
        traj = read_table(folder / "trajectory.csv")
        pub_path = folder / "published_profile.csv"
        published = read_table(pub_path) if pub_path.exists() else None
        figures = plot_files(result, traj, published, plot_format)
    except (OSError, ValueError, KeyError, IndexError, TypeError, AttributeError) as exc:
        reason = " ".join(str(exc).split())[:120] or type(exc).__name__
        raise OutputError(f"{folder}: not a finished pressplan output folder ({reason})") from None
    return {name: (lambda p, fig=fig: save(fig, p)) for name, fig in figures.items()}


def write_outputs(
    solution: Solution,
    case: Case,
    out: str | Path,
    *,
    cam_points: int = DEFAULT_POINTS,
    plot_format: str | None = "png",
) -> list[Path]:
    """Write every file of ``pressplan solve`` into the folder ``out``, all or nothing; the paths written."""
    from planning.reports.folder import write_atomic

    return write_atomic(Path(out), solution_writers(solution, case, cam_points=cam_points, plot_format=plot_format))
