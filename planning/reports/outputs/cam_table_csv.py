"""``cam_table.csv``: the crank angle and its derivatives against a virtual master axis (``--cam-points`` rows)."""

from __future__ import annotations

from planning.reports.arguments import whole
from planning.reports.cam_table import CAM_COLUMNS, DEFAULT_POINTS, cam_header, cam_table
from planning.reports.folder import write_table
from planning.reports.outputs import Option, Output, Writer, Written

POINTS = Option(
    "--cam-points",
    {
        "dest": "cam_points",
        "type": whole(2, 1_000_000),
        "default": DEFAULT_POINTS,
        "metavar": "N",
        "help": f"cam table rows (default {DEFAULT_POINTS})",
    },
)


def _writers(w: Written) -> dict[str, Writer]:
    points = w.option("cam_points")
    plan = w.solution.plan
    table, head = cam_table(plan, points), cam_header(plan, w.case.name, points)
    return {"cam_table.csv": lambda p: write_table(p, table, CAM_COLUMNS, head)}


OUTPUT = Output("cam_table.csv", "cam_table.csv", ("cam_table.csv",), _writers, order=30, page=True, options=(POINTS,))
