"""Reading ``plan.json`` (``planning.reports.outputs.plan_json``) back: the case and the plan, rebuilt exactly and
verified again (a folder's plan is used only as a verified plan)."""

from __future__ import annotations

import json
import math
from pathlib import Path

from planning.model.case import Case
from planning.model.case_file import CaseFileError, case_from_data
from planning.model.plan import Plan, SolverInfo, plan_of
from planning.reports.outputs.plan_json import FILE, FORMAT
from planning.solver.outcomes import Unverified
from planning.solver.solution import Solution
from planning.solver.verify import evaluate
from planning.tolerances import SAME_PERIOD_S


class PlanFileError(ValueError):
    """A ``plan.json`` that cannot be read (one line naming the file and what is wrong: exit 2)."""


def _pendulum_folder(folder: Path) -> bool:
    """Whether ``folder`` holds a pendulum solve's outputs (its ``result.json`` says so)."""
    try:
        return json.loads((folder / "result.json").read_text(encoding="utf-8")).get("mode") == "pendulum"
    except (OSError, ValueError, AttributeError):
        return False


def read_plan(folder: str | Path) -> tuple[Case, Solution]:
    """The case and the verified plan written to ``folder/plan.json`` by ``pressplan solve``."""
    path = Path(folder) / FILE
    if not path.is_file():
        if _pendulum_folder(Path(folder)):
            raise PlanFileError(f"{folder}: a pendulum stroke's folder (no {FILE}): give its case file instead")
        raise PlanFileError(f"{folder}: no {FILE} here (solve the case with this version of pressplan first)")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise PlanFileError(f"{path}: not a plan file ({exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise PlanFileError(f"{path}: format: expected {FORMAT!r}")
    try:
        case = case_from_data(data.get("case"), f"{path}: case")
    except CaseFileError as exc:
        raise PlanFileError(str(exc)) from None
    plan = _plan(path, case, data)
    evaluation = evaluate(plan, case)
    if not evaluation.verification.passed:
        check = evaluation.verification.failures()[0]
        raise Unverified(f"{path}: the plan no longer verifies: {check.name} = {check.value:.6g}", check)
    return case, Solution(plan, evaluation)


def _plan(path: Path, case: Case, data: dict) -> Plan:
    """The plan of ``data``'s values, checked against its period."""
    try:
        values = {str(k): float(v) for k, v in data["nlp_values"].items()}
        layout = None if data.get("layout") is None else tuple((str(p), int(n)) for p, n in data["layout"])
        plan = plan_of(case, values, data["placement"], SolverInfo(0, 0.0, 0, "read from plan.json"), layout)
        period = float(data["period_s"])
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise PlanFileError(f"{path}: the plan's values cannot be read ({type(exc).__name__}: {exc})") from None
    if not math.isclose(plan.period, period, rel_tol=0.0, abs_tol=SAME_PERIOD_S):
        raise PlanFileError(f"{path}: the values give a period of {plan.period:.9f} s, the file says {period:.9f} s")
    return plan
