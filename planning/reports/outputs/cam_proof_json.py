"""``cam_proof.json`` (with any ``--cam`` target): the cam's proof as its controller runs it (``planning.solver.
cam_proof``): the cam (interpolation, points, slave), the master speed it was proved at, the slide's largest
deviation from the plan, the steps across the cam's end, the highest master speed at which every limit
holds with what breaks 1 % above it, and every check with its margin."""

from __future__ import annotations

from planning.reports.folder import write_json
from planning.reports.outputs import Output, Writer, Written
from planning.reports.outputs._cam import OPTIONS

FILE = "cam_proof.json"


def _writers(w: Written) -> dict[str, Writer]:
    if not w.option("cam"):
        return {}
    from planning.reports.cam_export import proof_dict

    data = proof_dict(w.cam)
    return {FILE: lambda path: write_json(path, data)}


OUTPUT = Output(FILE, "cam proof (JSON)", (FILE,), _writers, order=36, options=OPTIONS)
