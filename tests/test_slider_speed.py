"""The maximum slider speed, ``limits.slider_speed_mm_s``: it binds where it should, in the plan, the bound,
the verification and ``check``; a draw speed above it is refused; without it nothing changes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from planning.cli import main
from planning.model.case_file import case_from_data, load_yaml
from planning.reports.report import trajectory
from planning.solver.bound import time_optimal_bound
from planning.solver.optimize import solve

from .conftest import PUBLISHED_CASE

FREE_PLAN_PEAK_MM_S = 1440.9  # the published case's free plan peaks at this slider speed without the limit


def with_slider_speed(limit: float | None, **process) -> dict:
    data = load_yaml(PUBLISHED_CASE.read_text(encoding="utf-8"))
    if limit is not None:
        data["limits"]["slider_speed_mm_s"] = limit
    data["process"].update(process)
    return data


@pytest.mark.parametrize("limit", [1200.0, 900.0])
def test_it_binds_below_the_free_plans_peak(limit):
    """Below the 1441 mm/s the published case's plan reaches, the limit holds on the dense grid, is named
    binding, and costs strokes; the bound, with the limit too, still lies above the plan."""
    free = solve(case_from_data(with_slider_speed(None)))
    case = case_from_data(with_slider_speed(limit))
    sol = solve(case)
    check = sol.verification.check("slider_speed")
    assert check is not None and check.binds
    assert np.max(np.abs(trajectory(sol, case)["slider_speed_mm_s"])) <= limit * (1 + 1e-6)  # the 1 ms trajectory
    assert "slider_speed" in [c.id for c in sol.verification.binding()]
    assert sol.plan.spm < free.plan.spm
    bound = time_optimal_bound(case).spm
    assert sol.plan.spm <= bound < time_optimal_bound(case_from_data(with_slider_speed(None))).spm


def test_above_the_peak_it_changes_nothing():
    free = solve(case_from_data(with_slider_speed(None)))
    loose = solve(case_from_data(with_slider_speed(2 * FREE_PLAN_PEAK_MM_S)))
    assert loose.plan.spm == pytest.approx(free.plan.spm, rel=1e-9)
    assert not loose.verification.check("slider_speed").binds
    assert free.verification.check("slider_speed") is None  # a case without the key has no such check


def test_check_lists_it_and_a_draw_speed_above_it_is_infeasible(tmp_path: Path, capsys):
    path = tmp_path / "fast_draw.yaml"
    path.write_text(json.dumps(with_slider_speed(250.0, draw_speed_rpm=6.7)))  # the draw reaches 297.7 mm/s
    assert main(["check", str(path)]) == 3
    expect = "FAIL  |slider speed| during the draw <= limits.slider_speed_mm_s: 297.7 mm/s (limit 250"
    assert expect in capsys.readouterr().out
    assert main(["solve", str(path), "--out", str(tmp_path / "out")]) == 3
    err = capsys.readouterr().err.strip()
    assert "infeasible: at the draw speed 6.7 rpm the slider moves at up to 297.7 mm/s" in err
    assert "slider_speed_mm_s = 250" in err and "\n" not in err
    assert not (tmp_path / "out").exists()


def test_the_optimal_law_holds_it():
    data = with_slider_speed(900.0)
    data["limits"]["crank_jerk_rad_s3"] = 326.3
    data["planner"]["motion_law"] = "optimal"
    sol = solve(case_from_data(data))
    assert sol.verification.check("slider_speed").value <= 900.0 * (1 + 1e-6)
