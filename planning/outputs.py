"""Writing a solved plan to an output folder, all or nothing.

Files are written into a hidden temporary folder beside the target and moved into place only when
every one of them is complete, so an earlier run's files are replaced only on success.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from planning.cam_table import CAM_COLUMNS, DEFAULT_POINTS, cam_header, cam_table
from planning.case import Case
from planning.optimize import Solution
from planning.published import rebuild_profile
from planning.report import TRAJECTORY_COLUMNS, result_dict, sample_profile, summary_text, trajectory


class OutputError(OSError):
    """The output folder cannot be written; ``str()`` is a one-line message."""


def ensure_writable(out: Path) -> None:
    """Fail early (before solving) when ``out`` cannot be created or written."""
    probe = out
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir():
        raise OutputError(f"{out}: output path is not a folder ({probe} is a file)")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(f"{out}: output folder is not writable")


def write_atomic(out: Path, writers: dict[str, Callable[[Path], None]]) -> list[Path]:
    """Run each ``writers[name](path)`` into a temporary folder, then move the files into ``out``."""
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=".pressplan-", dir=out))
    except OSError as exc:
        raise OutputError(f"{out}: cannot create the output folder ({exc.strerror})") from None
    try:
        for name, write in writers.items():
            write(tmp / name)
        moved = []
        for name in writers:
            os.replace(tmp / name, out / name)
            moved.append(out / name)
        return moved
    except OSError as exc:
        raise OutputError(f"{out}: cannot write the results ({exc.strerror})") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def write_json(path: Path, data: dict) -> None:
    path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n", encoding="utf-8")


def write_table(path: Path, table: np.ndarray, columns: tuple[str, ...], comments: str | None = None) -> None:
    """CSV with a header row, after optional ``#`` comment lines."""
    head = (comments + "\n" if comments else "") + ",".join(columns)
    np.savetxt(path, table, delimiter=",", header=head, comments="", fmt="%.12g")


def solution_writers(
    solution: Solution,
    case: Case,
    *,
    cam_points: int = DEFAULT_POINTS,
    plot_format: str | None = "png",
) -> dict[str, Callable[[Path], None]]:
    """The files ``pressplan solve`` writes: result.json, trajectory.csv, cam_table.csv, summary.txt,
    published_profile.csv (when the case has a published solution) and the figures
    (``plot_format`` None: no figures)."""
    result = result_dict(solution, case)
    traj = trajectory(solution, case)
    cam = cam_table(solution.plan, cam_points)
    cam_head = cam_header(solution.plan, case.name, cam_points)
    writers: dict[str, Callable[[Path], None]] = {
        "result.json": lambda p: write_json(p, result),
        "trajectory.csv": lambda p: write_table(p, traj, TRAJECTORY_COLUMNS),
        "cam_table.csv": lambda p: write_table(p, cam, CAM_COLUMNS, cam_head),
        "summary.txt": lambda p: p.write_text(summary_text(result) + "\n", encoding="utf-8"),
    }
    rebuilt = rebuild_profile(case)
    published = sample_profile(rebuilt, case.machine) if rebuilt is not None else None
    if published is not None:
        writers["published_profile.csv"] = lambda p: write_table(p, published, TRAJECTORY_COLUMNS)
    if plot_format:
        from planning.plots import plot_files, save

        columns = dict(zip(TRAJECTORY_COLUMNS, traj.T, strict=True))
        pub_cols = dict(zip(TRAJECTORY_COLUMNS, published.T, strict=True)) if published is not None else None
        for name, fig in plot_files(result, columns, pub_cols, plot_format).items():
            writers[name] = lambda p, fig=fig: save(fig, p)
    return writers


def plot_writers(folder: Path, plot_format: str = "png") -> dict[str, Callable[[Path], None]]:
    """Figures redrawn from a finished output folder's result.json and trajectory.csv."""
    from planning.plots import plot_files, read_table, save

    try:
        result = json.loads((folder / "result.json").read_text(encoding="utf-8"))
        traj = read_table(folder / "trajectory.csv")
        pub_path = folder / "published_profile.csv"
        published = read_table(pub_path) if pub_path.exists() else None
    except (OSError, ValueError, KeyError) as exc:
        raise OutputError(f"{folder}: not a finished pressplan output folder ({exc})") from None
    return {
        name: (lambda p, fig=fig: save(fig, p))
        for name, fig in plot_files(result, traj, published, plot_format).items()
    }
