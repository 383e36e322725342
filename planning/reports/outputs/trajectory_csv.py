"""``trajectory.csv``: one cycle on the evaluation's uniform grid (1 ms): the crank, the slide and, with a drive,
the motor and the power chain."""

from __future__ import annotations

import numpy as np

from planning.reports.folder import write_table
from planning.reports.outputs import Output, Writer, Written


def _writers(w: Written) -> dict[str, Writer]:
    from planning.reports.report import trajectory_columns

    table = np.column_stack(list(w.columns.values()))
    return {"trajectory.csv": lambda p: write_table(p, table, trajectory_columns(w.case))}


OUTPUT = Output("trajectory.csv", "trajectory.csv", ("trajectory.csv",), _writers, order=20, page=True)
