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

from planning.case import Case
from planning.optimize import Solution
from planning.report import TRAJECTORY_COLUMNS, result_dict, summary_text, trajectory


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


def write_trajectory(path: Path, table: np.ndarray) -> None:
    header = ",".join(TRAJECTORY_COLUMNS)
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.12g")


def solution_writers(solution: Solution, case: Case) -> dict[str, Callable[[Path], None]]:
    """The files ``pressplan solve`` writes: result.json, trajectory.csv, summary.txt."""
    result = result_dict(solution, case)
    table = trajectory(solution, case)
    return {
        "result.json": lambda p: write_json(p, result),
        "trajectory.csv": lambda p: write_trajectory(p, table),
        "summary.txt": lambda p: p.write_text(summary_text(result) + "\n", encoding="utf-8"),
    }
