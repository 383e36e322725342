"""Every case in cases/ solves and verifies under both placements; free is never worse."""

from __future__ import annotations

from pathlib import Path

import pytest

from planning.model.case_file import read_case
from planning.reports.report import trajectory
from planning.solver.upper_bound import upper_bound
from tests.conftest import solved

CASES = sorted((Path(__file__).resolve().parents[1] / "cases").glob("*.yaml"))


@pytest.mark.parametrize("path", CASES, ids=lambda p: p.stem)
def test_case_solves_and_verifies(path):
    case = read_case(path)
    published, free = solved(path, "published"), solved(path, "free")
    assert free.plan.spm >= published.plan.spm - 1e-9
    tab = trajectory(free, case)
    assert abs(tab["slider_accel_mm_s2"]).max() <= case.limits.slider_accel_mm_s2 * (1 + 1e-6)
    if case.robots is None:
        assert free.plan.transfer_window() >= case.process.transfer_time_s - 1e-6
    else:  # the robots' clearance at every sample, from their own positions
        t = tab["time_s"]
        for robot in case.robots_on_path:
            need = robot.needed_height(t, free.plan.robot_starts_s[robot.name], free.plan.period)
            assert (tab["slider_height_mm"] - need)[need > 0].min() >= -1e-6 * need.max()
    assert upper_bound(case, 180, 2).spm >= free.plan.spm  # certified: no verified motion above it
