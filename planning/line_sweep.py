"""``pressplan line LINE --vary FIELD=START:STOP:COUNT``: a grid over a line's fields, each point the whole line
planned and verified (``planning.solver.line``), on local worker processes or a Dask cluster (the sweep's
``execute``). A field is the line file's (``transfers.0.speed_mm_s``, ``feeder.time_s``) or a station's case
field after the station's name (``draw.limits.slider_accel_mm_s2``, ``trim.robots.loader.speed_mm_s``). One row
per point: the values, the line's strokes per minute and cycle, its bottleneck, the status and why not; the
rows in the grid's order in ``line_sweep.csv``, the figure ``line_sweep.png``.
"""

from __future__ import annotations

import csv
import itertools
from collections.abc import Callable
from pathlib import Path
from typing import Any

from planning.model.case_file import CaseFileError
from planning.model.line import TransferModel
from planning.model.line_file import read_line
from planning.model.outcome import Outcome
from planning.solver.line import solve_line
from planning.solver.outcomes import PlanningError
from planning.sweep import Vary, execute, numeric_fields, parse_vary, points_of

LINE_SWEEP_FILES = ("line_sweep.csv", "line_sweep.png")
ROW_FIELDS = ("spm", "cycle_time_s", "bottleneck", "status", "message")
BLOCK_POINTS = 1  # a line's point takes seconds: one to a worker at a time


def line_fields(path: str | Path) -> list[str]:
    """The numeric fields a sweep of the line file ``path`` can vary: each transfer's, the ends', each
    station's case fields after its name."""
    line = read_line(path)
    numeric = [f for f in TransferModel.model_fields if f not in ("unloads", "loads")]
    fields = [f"transfers.{k}.{f}" for k in range(len(line.stations) - 1) for f in numeric]
    fields += ["feeder.time_s", "exit.time_s"]
    return fields + [f"{station.name}.{f}" for station in line.stations for f in numeric_fields()]


def parse_line_vary(text: str, path: str | Path) -> Vary:
    """``FIELD=START:STOP:COUNT`` over one of :func:`line_fields`; ``SweepError`` naming what is wrong."""
    return parse_vary(text, line_fields(path), "a line's numeric field")


def check_corners(path: str | Path, sets: dict[str, Any], varies: list[Vary]) -> None:
    """Read the line at each corner of the grid (every field at its first or last value): a value no line
    takes is bad input before any point is solved (:class:`CaseFileError` naming it, from ``--vary``)."""
    for corner in itertools.product(*((v.start, v.stop) for v in varies)):
        point = dict(zip((v.field for v in varies), corner, strict=True))
        try:
            read_line(path, {**sets, **point})
        except CaseFileError as exc:
            values = ", ".join(f"{f}={x:g}" for f, x in point.items())
            raise CaseFileError(f"{exc} (from --vary, at {values})", exc.field) from None


def solve_points(path: str, sets: dict[str, Any], fields: list[str], points: list[tuple]) -> list[dict[str, Any]]:
    """The rows of ``points`` (``(index, values)``): each the line with ``sets`` and its values set, planned."""
    rows = []
    for index, values in points:
        point = dict(zip(fields, values, strict=True))
        row: dict[str, Any] = {"index": index, **point}
        try:
            solution = solve_line(read_line(path, {**sets, **point}))
        except CaseFileError as exc:
            rows.append({**row, "status": str(Outcome.BAD_INPUT), "message": str(exc)})
            continue
        except PlanningError as exc:
            rows.append({**row, "status": str(exc.outcome), "message": exc.reason})
            continue
        neck = solution.bottleneck
        rows.append(
            {
                **row,
                "spm": solution.spm,
                "cycle_time_s": solution.period_s,
                "bottleneck": f"{neck.kind} {neck.name}",
                "status": str(Outcome.VERIFIED),
            }
        )
    return rows


def run_line_sweep(
    path: str | Path,
    sets: dict[str, Any],
    varies: list[Vary],
    workers: int = 2,
    scheduler: str | None = None,
    progress: Callable[[int, int, int], None] | None = None,
) -> list[dict[str, Any]]:
    """Every point of the grid of ``varies`` planned (module docstring); the rows in the grid's order."""
    fields = [v.field for v in varies]
    points = list(enumerate(points_of(varies)))
    work = [(str(path), sets, fields, points[i : i + BLOCK_POINTS]) for i in range(0, len(points), BLOCK_POINTS)]
    rows: list[dict[str, Any]] = []
    if work and workers > 1 and not scheduler:  # the first point here: the forked workers inherit its NLPs
        rows += solve_points(*work.pop(0))
    for done in execute(solve_points, work, workers, scheduler):
        rows += done
        if progress:
            progress(len(rows), len(points), sum(r["status"] != str(Outcome.VERIFIED) for r in rows))
    return sorted(rows, key=lambda r: r["index"])


def write_rows(path: Path, rows: list[dict[str, Any]], fields: list[str]) -> None:
    """``line_sweep.csv``: one row per point, the swept values first."""
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=["index", *fields, *ROW_FIELDS], extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: row.get(k, "") for k in writer.fieldnames})
