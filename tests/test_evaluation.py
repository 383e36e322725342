"""One evaluation per plan: the dense re-simulation of a plan against a case is made once, by its
verification, and every output reads it (``planning.solver.verify.Evaluation``). Each test counts the
re-simulations (``verify.simulate``) of the answer's plan against its case, through ``solve`` and its
files, a sweep point, a page answer and a download."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest

import planning.solver.verify as verify
from planning.cli import main
from planning.model.case_file import read_case

ROOT = Path(__file__).resolve().parents[1]
PUBLISHED = ROOT / "cases" / "wang2023-side-panel.yaml"
DRIVE = ROOT / "cases" / "cup-2000kN-drive.yaml"


@pytest.fixture
def simulations(monkeypatch):
    """Every dense re-simulation, counted by (the plan's profile, the case's name and content)."""
    counts: Counter = Counter()
    plans: dict[int, object] = {}
    real = verify.simulate

    def counted(plan, case):  # noqa: ANN001, ANN202
        plans[id(plan.profile)] = plan.profile  # kept: an id is not reused while counted
        counts[(id(plan.profile), case.model_dump_json())] += 1
        return real(plan, case)

    monkeypatch.setattr(verify, "simulate", counted)
    return counts


def _of(counts: Counter, profile, case) -> int:  # noqa: ANN001
    return counts[(id(profile), case.model_dump_json())]


@pytest.mark.parametrize("path", [PUBLISHED, DRIVE], ids=["published", "drive"])
def test_solve_and_its_files_evaluate_the_answer_once(path, simulations, tmp_path, monkeypatch):
    """``pressplan solve`` with its figures: the answer's plan is re-simulated once (by the search that
    verified it), not again for result.json, the trajectory, the stage table or the figures."""
    from planning.solver import optimize

    answers = []
    real_solve = optimize.solve

    def kept(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        answers.append(real_solve(*args, **kwargs))
        return answers[-1]

    import planning.solver.optimize

    monkeypatch.setattr(planning.solver.optimize, "solve", kept)
    assert main(["solve", str(path), "--out", str(tmp_path)]) == 0
    (answer,) = answers
    case = read_case(path)
    assert _of(simulations, answer.plan.profile, case) == 1
    assert json.loads((tmp_path / "result.json").read_text())["spm"] == pytest.approx(answer.plan.spm, rel=1e-12)


def test_a_sweep_point_evaluates_its_answer_once(simulations):
    """A sweep's block solved in order (each point from its neighbour's plan), then its second pass (each
    point against its neighbours' plans): each point's answer was re-simulated once against its case."""
    from planning.sweep import parse_vary, points_of, repair, solve_block

    base = read_case(PUBLISHED).model_dump(exclude_none=True)
    vary = parse_vary("process.transfer_time_s=1.0:2.0:5")
    points = points_of([vary])
    rows = {row["index"]: row for row in solve_block(base, [vary.field], list(enumerate(points)), None, "sweep")}
    repair(base, [vary.field], points, (vary.count,), rows, None, "sweep")
    assert all(row.get("plan") is not None for row in rows.values())
    for row in rows.values():
        assert _of(simulations, row["plan"].profile, row["case"]) == 1, row["index"]


def test_a_page_answer_and_its_downloads_evaluate_the_plan_once(simulations):
    """The page's confirmed answer (its charts) and then three downloads of its files: one re-simulation."""
    pytest.importorskip("flask")
    from planning.web.server import create_app

    app = create_app(ROOT / "cases")
    client = app.test_client()
    data = client.get(f"/api/case/{PUBLISHED.name}").get_json()["case"]
    answer = client.post("/api/solve", json={"session": "s", "seq": 1, "case": data, "confirm": True}).get_json()
    assert answer["confirmed"]
    for name in ("result.json", "trajectory.csv", "cam_table.csv"):
        got = client.post(f"/api/download/{name}", json={"session": "s", "case": data})
        assert got.status_code == 200, got.get_json()
    shown = app.extensions["pressplan_sessions"].get("s").shown
    _, case, solution = shown
    assert _of(simulations, solution.plan.profile, case) == 1
