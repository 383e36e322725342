"""``result.json``: every figure of the plan, every check with its id, value, limit, margin and where it peaked."""

from __future__ import annotations

from planning.reports.folder import write_json
from planning.reports.outputs import Output, Writer, Written


def _writers(w: Written) -> dict[str, Writer]:
    return {"result.json": lambda p: write_json(p, w.result)}


OUTPUT = Output("result.json", "result.json", ("result.json",), _writers, order=10, page=True)
