"""``robot_cams.csv``: each robot's position on its path against the crank cam's virtual master (with robots;
``--cam-points`` rows): what the robot controller follows, slaved to the press's master."""

from __future__ import annotations

from planning.reports.folder import write_table
from planning.reports.outputs import Output, Writer, Written
from planning.reports.outputs.cam_table_csv import POINTS


def _writers(w: Written) -> dict[str, Writer]:
    if w.case.robots is None:
        return {}
    from planning.reports.robots import robot_cam_columns, robot_cam_header, robot_cam_table

    points = w.option("cam_points")
    table = robot_cam_table(w.solution, w.case, points)
    head = robot_cam_header(w.solution, w.case, points)
    return {"robot_cams.csv": lambda p: write_table(p, table, robot_cam_columns(w.case), head)}


OUTPUT = Output(
    "robot_cams.csv", "robot_cams.csv", ("robot_cams.csv",), _writers, order=31, page=True, options=(POINTS,)
)
