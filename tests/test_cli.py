"""The ``pressplan`` command end to end: check, solve, outputs, exit codes, safe writing."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest

from planning.cli import main
from planning.model.outcome import Outcome
from planning.reports.report import TRAJECTORY_COLUMNS

from .conftest import PUBLISHED_CASE

INFEASIBLE = sorted((Path(__file__).parent / "data" / "infeasible").glob("*.yaml"))


def test_check_prints_the_published_key_points(capsys):
    assert main(["check", str(PUBLISHED_CASE)]) == 0
    out = capsys.readouterr().out
    for number in ("705.64", "200.12", "9.38", "297.69", "75.12"):
        assert number in out
    assert "FAIL" not in out


def test_check_json(capsys):
    assert main(["check", str(PUBLISHED_CASE), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [k["name"] for k in data["key_points"]] == ["closing", "draw_start", "draw_end", "opening"]
    heights = [round(k["height_mm"], 1) for k in data["key_points"]]
    speeds = [round(k["slider_speed_mm_s"], 1) for k in data["key_points"]]
    assert heights[1:3] == [200.1, 9.4]
    assert heights[0] == heights[3] == 705.6  # the paper prints 705.7; see test_kinematics
    assert speeds[1:3] == [297.7, 75.1]
    assert 6.7 < data["max_draw_speed_rpm"] < 6.76
    assert all(c["passed"] for c in data["checks"])


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    out = tmp_path_factory.mktemp("solve") / "published"
    code = main(["solve", str(PUBLISHED_CASE), "--out", str(out), "--placement", "published"])
    assert code == 0
    return out


def test_solve_writes_result_json(solved):
    r = json.loads((solved / "result.json").read_text())
    for key in (
        "spm",
        "cycle_time_s",
        "status",
        "verified",
        "placement",
        "motion_law",
        "draw_speed_rpm",
        "transfer_window_s",
        "max_abs_slider_accel_mm_s2",
        "key_points",
        "segments",
        "paper_solution",
        "solver",
    ):
        assert key in r
    assert r["verified"] is True and r["status"] == Outcome.VERIFIED
    assert 11.6 <= r["spm"] <= 11.8
    assert r["cycle_time_s"] == pytest.approx(60 / r["spm"])
    assert set(r["solver"]) >= {"iterations", "wall_time_s"}
    assert {k["name"] for k in r["key_points"]} == {"closing", "draw_start", "draw_end", "opening"}
    for k in r["key_points"]:
        assert set(k) >= {"name", "angle_deg", "time_s", "height_mm", "slider_speed_mm_s", "crank_speed_rpm"}
    assert sum(s["duration_s"] for s in r["segments"]) == pytest.approx(r["cycle_time_s"], abs=1e-9)
    for s in r["segments"]:
        assert set(s) >= {"name", "duration_s", "start_angle_deg", "end_angle_deg", "jerk_rad_s3"}
    x = r["paper_solution"]
    assert list(x)[:13] == [
        "x1_s",
        "x2_s",
        "x3_s",
        "x4_s",
        "x5_s",
        "wm1_rpm",
        "wm2_rpm",
        "T1_s",
        "T5_s",
        "T9_s",
        "T10_s",
        "T14_s",
        "J_rpm_s2",
    ]
    assert x["x5_s"] == pytest.approx(r["cycle_time_s"])


def test_solve_writes_trajectory_csv(solved):
    r = json.loads((solved / "result.json").read_text())
    with open(solved / "trajectory.csv", newline="") as fh:
        header = next(csv.reader(fh))
    assert tuple(header) == TRAJECTORY_COLUMNS
    tab = np.loadtxt(solved / "trajectory.csv", delimiter=",", skiprows=1)
    dt = np.diff(tab[:, 0])
    assert dt.max() <= 1e-3 + 1e-12 and dt.max() - dt.min() < 1e-9  # uniform, <= 1 ms
    assert tab[-1, 0] - tab[0, 0] == pytest.approx(r["cycle_time_s"], abs=1e-9)
    assert tab[-1, 1] - tab[0, 1] == pytest.approx(360.0, abs=1e-7)
    assert np.all(np.diff(tab[:, 1]) > 0)
    assert np.all(np.isfinite(tab))


def test_solve_prints_the_summary(capsys, tmp_path):
    assert main(["solve", str(PUBLISHED_CASE), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"1[12]\.\d{3} strokes/min", out)
    assert "binding:" in out and "theta1 (closing) in" in out


@pytest.mark.parametrize("path", INFEASIBLE, ids=lambda p: p.name)
def test_infeasible_exit_3_names_the_limit_and_writes_nothing(path, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "result.json").write_text("earlier run")
    assert main(["solve", str(path), "--out", str(out)]) == 3
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "infeasible" in err
    expect = path.read_text().splitlines()[0].removeprefix("# expect: ")
    assert expect in err
    assert (out / "result.json").read_text() == "earlier run"  # replaced only on success
    assert sorted(p.name for p in out.iterdir()) == ["result.json"]


def test_unwritable_output_is_bad_input(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["solve", str(PUBLISHED_CASE), "--out", str(blocker / "sub")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_case_file_is_never_written(tmp_path):
    before = PUBLISHED_CASE.read_bytes()
    main(["check", str(PUBLISHED_CASE)])
    assert PUBLISHED_CASE.read_bytes() == before


@pytest.mark.slow  # 7-13 s: the normal run keeps under 5 minutes (its kind runs there too)
def test_solver_success_but_failed_verification_is_exit_3(monkeypatch, tmp_path, capsys):
    """No false successes: when every plan fails the dense check, nothing is written and exit is 3."""
    import planning.solver.verify as verify
    from planning.solver.verify import Check, Evaluation, Verification

    def failing(dense, uniform, cam=False):  # every evaluation of every plan (the search's, the fallbacks') fails
        check = Check("|slider acceleration|", 9999.0, 3500.0, "mm/s^2", "max", False, "slider_accel")
        return Evaluation(dense, uniform, Verification((check,), 1e-3, 10))

    monkeypatch.setattr(verify, "_judged", failing)
    out = tmp_path / "o"
    assert main(["solve", str(PUBLISHED_CASE), "--out", str(out)]) == 3
    err = capsys.readouterr().err
    assert "verification failed: |slider acceleration| = 9999" in err and len(err.strip().splitlines()) == 1
    assert not out.exists() or not any(out.iterdir())


def test_last_iterate_names_the_violated_constraint():
    import numpy as np

    from planning.model.case_file import read_case
    from planning.solver.halves_nlp import halves_nlp_for

    nlp = halves_nlp_for(read_case(PUBLISHED_CASE))
    lbg, ubg = nlp.bounds("free")
    g = np.where(np.isfinite(lbg), lbg, np.where(np.isfinite(ubg), ubg, 0.0))
    block = nlp.block_of("transfer_time")
    g[block.start] = -0.7  # 0.7 s short of the transfer time
    worst, amount = nlp.worst_block("free", g)
    assert (worst.name, worst.field, amount) == ("transfer time", "process.transfer_time_s", 0.7)


def test_check_warns_when_the_slide_is_below_the_die_height_at_theta3(capsys, tmp_path):
    """The published case ends its draw at 9.38 mm, under the 10 mm die height: check says where the
    slide leaves the die zone (the ascending crossing, from the exact geometry)."""
    import math

    from press.crank_slider import CrankSlider

    assert main(["check", str(PUBLISHED_CASE)]) == 0
    out = capsys.readouterr().out
    leave = math.degrees(float(CrankSlider(450, 1200).angles_at_height(10.0)[1]))
    assert "WARNING" in out and f"{leave:.2f} deg" in out
    early = tmp_path / "early.yaml"
    early.write_text(PUBLISHED_CASE.read_text().replace("draw_end_deg: 190 ", "draw_end_deg: 195 "))
    assert main(["check", str(early), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["warnings"] == []
