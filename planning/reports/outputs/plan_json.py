"""``plan.json``: the plan itself, to be read again (``pressplan cam FOLDER``: a cam from a written folder).

The case as solved (every field, with the command line's ``--set``, ``--law`` and ``--objective``
applied), the NLP's variable values the plan is made of (``planning.model.plan.plan_of`` rebuilds the
profile from them exactly: the same closed forms), the placement, the optimal law's layout, and the
plan's period and strokes per minute (a reader checks the rebuilt plan against them)."""

from __future__ import annotations

from planning.model.free_profile import FreeProfileParameters
from planning.reports.folder import write_json
from planning.reports.outputs import Output, Writer, Written

FILE = "plan.json"
FORMAT = "pressplan plan 1"


def plan_dict(w: Written) -> dict:
    """What ``plan.json`` holds."""
    plan = w.solution.plan
    layout = plan.parameters.layout if isinstance(plan.parameters, FreeProfileParameters) else None
    return {
        "format": FORMAT,
        "case": w.case.model_dump(mode="json", exclude_none=True),
        "placement": plan.placement,
        "motion_law": plan.motion_law,
        "layout": None if layout is None else [list(phase) for phase in layout],
        "nlp_values": {k: float(v) for k, v in plan.nlp_values.items()},
        "period_s": plan.period,
        "spm": plan.spm,
    }


def _writers(w: Written) -> dict[str, Writer]:
    data = plan_dict(w)
    return {FILE: lambda path: write_json(path, data)}


OUTPUT = Output(FILE, "plan.json", (FILE,), _writers, order=15)
