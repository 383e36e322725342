"""``published_profile.csv``: the source's own solution, rebuilt (a case with ``published.solution``), on a 1 ms
grid with the trajectory's kinematic columns."""

from __future__ import annotations

from planning.reports.folder import write_table
from planning.reports.outputs import Output, Writer, Written


def _writers(w: Written) -> dict[str, Writer]:
    from planning.reports.report import TRAJECTORY_COLUMNS

    table = w.published
    if table is None:
        return {}
    return {"published_profile.csv": lambda p: write_table(p, table, TRAJECTORY_COLUMNS)}


OUTPUT = Output("published_profile.csv", "published_profile.csv", ("published_profile.csv",), _writers, order=50)
