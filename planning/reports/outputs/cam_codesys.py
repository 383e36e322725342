"""``cam_codesys.st`` (``--cam codesys``): the proved XYVA cam as a CODESYS SoftMotion global variable list.

An ``ARRAY [0..n] OF SMC_CAMXYVA`` (``dX`` master [deg], ``dY`` slave [deg], ``dV`` dY/dX, ``dA`` d2Y/dX2:
SM3_Basic's XYVA element; a fifth-order polynomial between two) and the ``MC_CAM_REF`` that points at it
(``byType := 3``: SMC_CAM_TYPE.XYVA; ``xStart`` 0, ``xEnd`` 360; ``nElements`` the points, both ends), for
``MC_CamTableSelect`` and ``MC_CamIn`` with a periodic master. Structured Text of IEC 61131-3."""

from __future__ import annotations

from typing import TYPE_CHECKING

from planning.reports.outputs import Output, Writer, Written
from planning.reports.outputs._cam import OPTIONS, real, text_writers, variable_name

if TYPE_CHECKING:
    from planning.reports.cam_export import CamExport

FILE = "cam_codesys.st"
CAM_FILE_ELEMENTS = 128  # SM3's cam file reader holds this many elements by default


def text(export: CamExport) -> str:
    """The global variable list."""
    cam, name = export.cam, variable_name(export.case.name)
    n = cam.master_deg.size
    notes = [*export.header_lines(), "CODESYS SoftMotion (SM3_Basic): SMC_CAMXYVA points, MC_CAM_REF byType 3 (XYVA)"]
    if n > CAM_FILE_ELEMENTS:
        notes.append(f"{n} elements: more than the {CAM_FILE_ELEMENTS} SM3's cam file reader holds by default")
    rows = [
        f"        (dX := {real(x)}, dY := {real(y)}, dV := {real(v)}, dA := {real(a)})"
        for x, y, v, a in zip(cam.master_deg, cam.slave_deg, cam.slope, cam.curvature, strict=True)
    ]
    lines = [
        *(f"(* {line} *)" for line in notes),
        "VAR_GLOBAL",
        f"    {name}_Points : ARRAY[0..{n - 1}] OF SMC_CAMXYVA := [",
        ",\n".join(rows),
        "    ];",
        f"    {name} : MC_CAM_REF := (byType := 3, xStart := 0.0, xEnd := 360.0, nElements := {n}, nTappets := 0, "
        f"pce := ADR({name}_Points));",
        "END_VAR",
    ]
    return "\n".join(lines) + "\n"


def _writers(w: Written) -> dict[str, Writer]:
    return text_writers(w, "codesys", FILE, text)


OUTPUT = Output(FILE, "cam (CODESYS ST)", (FILE,), _writers, order=33, options=OPTIONS)
