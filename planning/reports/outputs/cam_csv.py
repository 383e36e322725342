"""``cam_xyva.csv`` or ``cam_points.csv`` (``--cam csv``): the proved cam as a generic CSV.

XYVA points (``--cam-interpolation poly5``): a header row ``master_deg,crank_angle_deg,dcrank_dmaster,
d2crank_dmaster2,slider_height_mm`` (the motor as the slave: ``master_deg,motor_angle_deg,dmotor_dmaster,
d2motor_dmaster2,crank_angle_deg,slider_height_mm``) after ``#`` lines that say what the file holds and what
its proof found. A point table (spline or linear): the same ``#`` lines, the columns named in the last of
them, then ``master_deg,slave`` pairs (with the crank's angle and the slide's height beside, for an HMI):
the layout cam-table loaders read (``pyplcopen.load_cam_table_csv``). Every number with all its digits."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from planning.model.cam import Interpolation
from planning.reports.outputs import Output, Writer, Written
from planning.reports.outputs._cam import CRANK, OPTIONS

if TYPE_CHECKING:
    from planning.reports.cam_export import CamExport

XYVA_FILE, TABLE_FILE = "cam_xyva.csv", "cam_points.csv"


def columns(export: CamExport) -> tuple[tuple[str, ...], np.ndarray]:
    """The file's column names and rows."""
    cam, crank = export.cam, export.proof.cam
    s = export.slave
    if cam.interpolation is Interpolation.POLY5:
        names = ("master_deg", export.slave_name, f"d{s}_dmaster", f"d2{s}_dmaster2")
        values = [cam.master_deg, cam.slave_deg, cam.slope, cam.curvature]
    else:
        names = ("master_deg", export.slave_name)
        values = [cam.master_deg, cam.slave_deg]
    if s != CRANK:
        names += ("crank_angle_deg",)
        values.append(crank.slave_deg)
    return names + ("slider_height_mm",), np.column_stack([*values, export.slide_mm])


def text(export: CamExport) -> str:
    """The whole file."""
    names, rows = columns(export)
    head = [f"# {line}" for line in export.header_lines()]
    body = [",".join(repr(float(x)) for x in row) for row in rows]
    if export.cam.interpolation is Interpolation.POLY5:
        return "\n".join([*head, ",".join(names), *body]) + "\n"
    return "\n".join([*head, "# " + ",".join(names), *body]) + "\n"


def _writers(w: Written) -> dict[str, Writer]:
    if "csv" not in w.option("cam"):
        return {}
    export = w.cam
    name = XYVA_FILE if export.cam.interpolation is Interpolation.POLY5 else TABLE_FILE
    content = text(export)
    return {name: lambda path: path.write_text(content, encoding="utf-8")}


OUTPUT = Output("cam_xyva.csv", "cam (CSV)", (XYVA_FILE, TABLE_FILE), _writers, order=32, options=OPTIONS)
