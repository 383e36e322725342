"""The offset (desaxe) crank-slider case through every command: check prints its dead centres, solve verifies,
laws, bound, sweep and trade-off run, compare says what it lacks, the web page's API solves it; and an
offset of zero is the in-line press."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest

from planning.cli import main
from planning.model.case_file import case_from_data, load_yaml, read_case
from planning.model.outcome import Outcome
from planning.solver.bound import time_optimal_bound
from planning.solver.optimize import solve
from tests.conftest import solved

from .conftest import PUBLISHED_CASE, ROOT

OFFSET_CASE = ROOT / "cases" / "offset-crank-side-panel.yaml"


def data_of(path: Path) -> dict:
    return load_yaml(path.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def offset_solution():
    return read_case(OFFSET_CASE), solved(OFFSET_CASE)


def test_the_case_is_offset_by_5_to_10_percent_of_the_crank():
    press = read_case(OFFSET_CASE).press
    assert 0.05 <= press.offset_mm / press.crank_radius_mm <= 0.10


def test_check_prints_the_dead_centres(capsys):
    assert main(["check", str(OFFSET_CASE)]) == 0
    out = capsys.readouterr().out
    assert "stroke 900.583 mm; TDC at -3.06 deg, BDC at 178.61 deg of the crank's own angle" in out
    assert "goes down for 181.67 deg (50.5 % of the turn), up for 178.33 deg" in out
    assert main(["check", str(OFFSET_CASE), "--json"]) == 0
    press = json.loads(capsys.readouterr().out)["press"]
    assert press["bdc_deg"] == pytest.approx(181.668, abs=1e-3) and press["mechanism"] == "crank-slider"


def test_solve_verifies_with_the_drive_and_the_energy_balance(offset_solution, tmp_path):
    case, sol = offset_solution
    balance = sol.verification.check("energy_balance")
    assert balance is not None and balance.passed  # the forming force acts from theta2 to BDC at 181.67 deg
    assert sol.drive.forming_work_kJ == pytest.approx(sol.drive.crank_work_kJ, rel=1e-6)
    out = tmp_path / "solve"
    assert main(["solve", str(OFFSET_CASE), "--no-plots", "--out", str(out)]) == 0
    result = json.loads((out / "result.json").read_text())
    assert result["verified"] and result["spm"] == pytest.approx(sol.plan.spm, rel=1e-9)


def test_the_bound_lies_above_the_plan(offset_solution):
    case, sol = offset_solution
    assert time_optimal_bound(case).spm >= sol.plan.spm


@pytest.mark.slow  # 7-13 s: the normal run keeps under 5 minutes (its kind runs there too)
def test_laws_sweep_tradeoff_and_compare_run(tmp_path, capsys):
    assert main(["laws", str(OFFSET_CASE), "--out", str(tmp_path / "laws")]) == 0
    laws = json.loads((tmp_path / "laws" / "laws.json").read_text())
    assert all(row["status"] == Outcome.VERIFIED for row in laws["laws"])
    vary = "press.offset_mm=0:40:2"
    assert main(["sweep", str(OFFSET_CASE), "--vary", vary, "--workers", "1", "--out", str(tmp_path / "sw")]) == 0
    with open(tmp_path / "sw" / "sweep.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["status"] for r in rows] == ["verified", "verified"]
    assert main(["tradeoff", str(OFFSET_CASE), "--spm", "6:max:2", "--workers", "1", "--out", str(tmp_path / "t")]) == 0
    capsys.readouterr()
    assert main(["compare", str(OFFSET_CASE), "--out", str(tmp_path / "c")]) == 2
    assert "published.solution" in capsys.readouterr().err


def test_the_web_api_solves_it():
    pytest.importorskip("flask")
    from planning.web.server import create_app

    client = create_app(ROOT / "cases").test_client()
    loaded = client.get(f"/api/case/{OFFSET_CASE.name}").get_json()
    assert "case" in loaded and loaded["case"]["press"]["offset_mm"] == 40
    answer = client.post("/api/solve", json={"session": "s", "seq": 1, "case": loaded["case"]}).get_json()
    assert answer["status"] == Outcome.VERIFIED


def test_a_bad_offset_names_its_field(tmp_path, capsys):
    data = data_of(PUBLISHED_CASE)
    data["press"]["offset_mm"] = 800.0  # beyond rod length - crank radius = 750 mm: no TDC
    path = tmp_path / "far.yaml"
    path.write_text(json.dumps(data))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("press.offset_mm: must be less than rod length - crank radius = 750 mm (got 800.0)")


def test_a_zero_offset_is_the_in_line_press():
    """``offset_mm: 0`` written out gives the published case's plan (the default is the in-line press)."""
    data = data_of(PUBLISHED_CASE)
    data["press"]["offset_mm"] = 0.0
    given, default = solve(case_from_data(data)), solved(PUBLISHED_CASE)
    assert given.plan.spm == default.plan.spm


def test_the_offset_moves_bdc_and_the_window():
    """Kinematics only (no drive), the same heights at the key points: the offset press turns BDC 1.67 deg
    later, and its plan is verified like the in-line one's."""
    data = data_of(OFFSET_CASE)
    del data["drive"], data["process"]["forming_force_kN"]
    case = case_from_data(data)
    assert math.degrees(case.machine.bdc_angle) == pytest.approx(181.668, abs=1e-3)
    solve(case)  # raises without a verified plan
