"""``cam_twincat.st`` (``--cam twincat``): the proved cam as a TwinCAT NC motion function, a global variable list.

An ``ARRAY [1..n] OF MC_MotionFunctionPoint`` (Tc2_MC2_Camming): each point's ``MasterPos`` [deg],
``SlavePos`` [deg], ``SlaveVelo`` (dY/dX: the velocity at a master velocity of 1), ``SlaveAcc``
(d2Y/dX2), ``SlaveJerk`` (d3Y/dX3 of the interval that starts there) and the function to the next point:
``MOTIONFUNCTYPE_POLYNOM5_MM`` (a fifth-order polynomial, motion to motion) for XYVA points,
``MOTIONFUNCTYPE_POLYNOM1`` (a straight line) for a linear table; every point a motion point, the next one
the next index. Load it with ``MC_CamTableSelect`` (an ``MC_CAM_REF`` of table type motion function
pointing at the array). Structured Text of IEC 61131-3."""

from __future__ import annotations

from typing import TYPE_CHECKING

from planning.model.cam import Interpolation
from planning.reports.outputs import Output, Writer, Written
from planning.reports.outputs._cam import OPTIONS, real, text_writers, variable_name

if TYPE_CHECKING:
    from planning.reports.cam_export import CamExport

FILE = "cam_twincat.st"
FUNCTION = {Interpolation.POLY5: "MOTIONFUNCTYPE_POLYNOM5_MM", Interpolation.LINEAR: "MOTIONFUNCTYPE_POLYNOM1"}


def text(export: CamExport) -> str:
    """The global variable list."""
    cam, name = export.cam, variable_name(export.case.name)
    _, v, a, j = cam.at(cam.master_deg[:-1])  # the intervals' from their start (a table's slope)
    _, v_end, a_end, j_end = cam.at_end()  # the last point's, from the interval that ends there
    if cam.slope is not None:  # XYVA: the points' own
        v, a, v_end, a_end = cam.slope[:-1], cam.curvature[:-1], cam.slope[-1], cam.curvature[-1]
    values = zip(cam.master_deg, cam.slave_deg, [*v, v_end], [*a, a_end], [*j, j_end], strict=True)
    function = f"MC_MotionFunctionType.{FUNCTION[cam.interpolation]}"
    point = "MC_MotionPointType.MOTIONPOINTTYPE_MOTION"
    rows = [
        f"        (PointIndex := {k}, FunctionType := {function}, PointType := {point}, "
        f"RelIndexNextPoint := 1, MasterPos := {real(x)}, SlavePos := {real(ys)}, SlaveVelo := {real(vs)}, "
        f"SlaveAcc := {real(acc)}, SlaveJerk := {real(js)})"
        for k, (x, ys, vs, acc, js) in enumerate(values, start=1)
    ]
    lines = [
        *(f"(* {line} *)" for line in export.header_lines()),
        f"(* TwinCAT NC camming (Tc2_MC2_Camming): MC_MotionFunctionPoint, {FUNCTION[cam.interpolation]} *)",
        "VAR_GLOBAL",
        f"    {name} : ARRAY[1..{len(rows)}] OF MC_MotionFunctionPoint := [",
        ",\n".join(rows),
        "    ];",
        "END_VAR",
    ]
    return "\n".join(lines) + "\n"


def _writers(w: Written) -> dict[str, Writer]:
    return text_writers(w, "twincat", FILE, text)


OUTPUT = Output(FILE, "cam (TwinCAT ST)", (FILE,), _writers, order=34, options=OPTIONS)
