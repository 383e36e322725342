"""Robots on their interference curves in pendulum strokes (issue 40 with issue 39's robots): each robot goes in
and out once in each of the cycle's two windows between the draws.

The clearance is checked here from the plan's crank angle with the crank-slider's own closed form and the robot's
position from its move's equations (``press.robot``, checked against ruckig in tests/test_robots.py), not from the
planner's dense check; ``robot_cams.csv`` is read back with Python's csv module; the plans are changed just past
a limit to see the verification fail; the certified bound is an inequality every plan must meet."""

from __future__ import annotations

import csv
import math
from dataclasses import replace

import numpy as np
import pytest

from planning.cli import main
from planning.model.case_file import read_case
from planning.solver.pendulum import solve_pendulum
from planning.solver.pendulum_bound import pendulum_bound
from planning.solver.pendulum_check import evaluate_pendulum
from planning.solver.pendulum_nlp import refined
from planning.solver.pendulum_robots import NEED_FACTOR, WINDOWS

from .conftest import ROOT

CASE = ROOT / "cases" / "pendulum" / "shallow-pendulum-robots.yaml"
STEP_S = 1e-4  # the independent check's time step


@pytest.fixture(scope="module")
def shallow():
    case = read_case(CASE)
    return case, solve_pendulum(case, compare=False)


def _slide_mm(theta: np.ndarray, r: float, rod: float) -> np.ndarray:
    """The in-line crank-slider's slide height above BDC [mm], the slide below the crank (theta from TDC)."""
    return r * (1 + np.cos(theta)) + rod - np.sqrt(rod**2 - (r * np.sin(theta)) ** 2)


def _clearances(case, plan) -> dict[str, float]:  # noqa: ANN001 - a Case and a PendulumPlan
    """Each robot's least clearance [mm] where its tool needs height, over the cycle on a 0.1 ms grid."""
    t = np.arange(0.0, plan.period, STEP_S)
    h = _slide_mm(plan.profile.at_time(t)[0], 50.0, 250.0)
    out = {}
    for robot in case.robots_on_path:
        starts = tuple(plan.robot_starts_s[robot.name][w] for w in WINDOWS)
        need = robot.curve.need(robot.position_of_starts(t, starts, plan.period))
        out[robot.name] = float(np.min((h - need)[need > 0]))
    return out


def test_both_robots_clear_in_both_windows_by_an_independent_check(shallow):
    case, solution = shallow
    plan = solution.plan
    assert solution.evaluation.verification.passed
    least = _clearances(case, plan)
    assert min(least.values()) > -1e-3, least  # the slide at least where each tool needs it (to 1 um)
    assert min(least.values()) < 0.05, least  # and the clearance binds: the swing is no slower than it must be
    f, b = plan.key_times("forward"), plan.key_times("backward")
    windows = {WINDOWS[0]: (f[2], b[1]), WINDOWS[1]: (b[2], f[1] + plan.period)}
    for robot in case.robots_on_path:  # the unloader grips after theta3, the loader drops before theta2
        for w, (t3, t2) in windows.items():
            start = plan.robot_starts_s[robot.name][w]
            event = start + robot.move.duration_s + (robot.dwell_s if robot.name == "loader" else 0.0)
            since = (event - t3) % plan.period
            assert -1e-9 <= since <= t2 - t3 + 1e-9, (robot.name, w, since, t2 - t3)
    e, s = (plan.robot_starts_s["unloader"][w] for w in WINDOWS)
    assert min((s - e) % plan.period, (e - s) % plan.period) >= case.robots_on_path[0].occupancy_s - 1e-9


def test_the_bound_is_above_the_plan_and_the_robots_set_it(shallow):
    case, solution = shallow
    bound = pendulum_bound(case)
    assert bound.spm > solution.plan.spm
    assert "robots" in bound.sets_it
    assert bound.cycle_time_s > sum(bound.arc_times_s)  # the robots ask more than the key angles


def test_verification_fails_with_a_robot_moved_just_past_its_curve(shallow):
    """The unloader started 5 ms earlier at theta_e: its tool reaches the die zone before the slide is up; the loader
    5 ms earlier at theta_s: it reaches the die before the unloader is clear; each fails its own check only."""
    case, solution = shallow
    plan = solution.plan
    starts = {name: dict(by_window) for name, by_window in plan.robot_starts_s.items()}
    starts["unloader"][WINDOWS[0]] -= 0.005
    failed = evaluate_pendulum(replace(plan, robot_starts_s=starts), case).verification.failures()
    assert {c.id for c in failed} == {"robots"}
    assert all("unloader at theta_e" in c.name for c in failed)
    assert failed[0].refine_by is not None and failed[0].refine_by[0] == NEED_FACTOR
    starts = {name: dict(by_window) for name, by_window in plan.robot_starts_s.items()}
    starts["loader"][WINDOWS[1]] -= 0.005
    failed = evaluate_pendulum(replace(plan, robot_starts_s=starts), case).verification.failures()
    names = {c.name for c in failed}
    assert "the loader reaches the die at theta_s once the unloader is clear of it" in names
    assert {c.id for c in failed} <= {"robots", "robots_order"}


def test_a_failed_clearance_raises_the_needs_at_the_samples():
    class Failed:  # a check as the dense verification gives it: the needs raised by 3 %
        id, refine_by = "robots", (NEED_FACTOR, 1.03, math.inf)

    limits = {"slider_accel": 19000.0, NEED_FACTOR: 1.0}
    assert refined(limits, [Failed()]) == {"slider_accel": 19000.0, NEED_FACTOR: 1.03}


def test_solve_writes_both_occupancies_as_robot_cams(tmp_path, capsys):
    assert main(["solve", str(CASE), "--no-plots", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "unloader at theta_e" in out and "loader at theta_s" in out
    with open(tmp_path / "robot_cams.csv", newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(line for line in handle if not line.startswith("#")))
    master = np.array([float(r["master_deg"]) for r in rows])
    assert master[0] == 0.0 and master[-1] < 360.0
    for name in ("unloader", "loader"):
        away = np.array([float(r[f"{name}_position_mm"]) for r in rows]) < 600.0 - 1e-6
        leaves = np.count_nonzero(away & ~np.roll(away, 1))  # (cyclic: the master wraps)
        assert leaves == 2, name  # in and out once a swing, twice a cycle
        assert np.min([float(r[f"{name}_position_mm"]) for r in rows]) == pytest.approx(0.0, abs=1e-6)


def test_check_and_bound_name_what_the_robots_need(capsys):
    assert main(["check", str(CASE)]) == 0
    out = capsys.readouterr().out
    assert "the robots need a cycle of at least" in out and "FAIL" not in out
    assert "robots' shortest cycle" not in out  # (a rotary cycle's check: not a swing's)
    assert main(["bound", str(CASE), "--json"]) == 0
    assert '"set_by"' in capsys.readouterr().out


@pytest.mark.slow  # in the slow tier (CI runs it): the normal run stays under 5 minutes
def test_link_drive_swings_with_robots_differ_both_verified(tmp_path):
    """On a link drive the backward swing meets the key heights on the fast side: the two windows differ, and
    so do the robots' starts in them; both verified, the bound above."""
    case = read_case(ROOT / "tests" / "data" / "cases" / "link-pendulum-robots.yaml")
    solution = solve_pendulum(case, compare=False)
    plan = solution.plan
    assert solution.evaluation.verification.passed
    f, b = plan.parameters.forward, plan.parameters.backward
    assert abs(float(f.duration) - float(b.duration)) > 0.1
    spans = {}
    for w in WINDOWS:  # the unloader's start after its window's theta3 differs between the windows
        t3 = plan.key_times("forward" if w == WINDOWS[0] else "backward")[2]
        spans[w] = (plan.robot_starts_s["unloader"][w] - t3) % plan.period
    assert abs(spans[WINDOWS[0]] - spans[WINDOWS[1]]) > 1e-3
    assert pendulum_bound(case).spm > plan.spm
