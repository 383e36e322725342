"""The motion: what a script needs, in one place.

    from planning import read_case, solve, write_outputs
    case = read_case("cases/wang2023-side-panel.yaml")
    solution = solve(case)
    write_outputs(solution, case, "out/demo")

The names are loaded on first use, so ``import planning`` stays light (CasADi is loaded only with the
solver). The packages below show the layers: ``planning.model`` (the case, the motion laws, the
cycle, the plan), ``planning.solver`` (the NLPs, the IPOPT wrapper, the orchestrator, the
verification, the bound), ``planning.reports`` (everything written or printed); ``planning.sweep`` and
``planning.cli`` sit on top.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "read_case": ("planning.model.case_file", "read_case"),
    "CaseFileError": ("planning.model.case_file", "CaseFileError"),
    "Case": ("planning.model.case", "Case"),
    "LAWS": ("planning.model.laws", "LAWS"),
    "solve": ("planning.solver.optimize", "solve"),
    "Solution": ("planning.solver.solution", "Solution"),
    "bound": ("planning.solver.bound", "time_optimal_bound"),
    "verify": ("planning.solver.verify", "verify"),
    "PlanningError": ("planning.solver.outcomes", "PlanningError"),
    "Infeasible": ("planning.solver.outcomes", "Infeasible"),
    "NoPlanFound": ("planning.solver.outcomes", "NoPlanFound"),
    "Unverified": ("planning.solver.outcomes", "Unverified"),
    "result_dict": ("planning.reports.report", "result_dict"),
    "trajectory": ("planning.reports.report", "trajectory"),
    "write_outputs": ("planning.reports.outputs", "write_outputs"),
    "compare_laws": ("planning.reports.law_comparison", "compare_laws"),
    "read_line": ("planning.model.line_file", "read_line"),
    "solve_line": ("planning.solver.line", "solve_line"),
    "write_line_outputs": ("planning.reports.line", "write_line_outputs"),
}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name not in _EXPORTS:
        raise AttributeError(f"module 'planning' has no attribute {name!r}")
    module, attr = _EXPORTS[name]
    value = getattr(importlib.import_module(module), attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return __all__
