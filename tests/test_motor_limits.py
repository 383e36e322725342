"""The drive's limits on crank speed, acceleration and jerk: honoured by the optimizer, checked by the
verification, and taken into the bound."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from planning.model.case_file import read_case
from planning.solver.bound import time_optimal_bound
from tests.conftest import solved

CASE = Path(__file__).resolve().parents[1] / "cases" / "side-panel-servo-limits.yaml"


@pytest.fixture(scope="module")
def limited():
    return read_case(CASE), solved(CASE)


def test_motor_limits_hold_on_the_sample_times(limited):
    case, sol = limited
    lim = case.limits
    for limit_id in ("crank_speed", "crank_accel", "crank_jerk"):
        assert sol.verification.check(limit_id).passed
    t = np.linspace(0, sol.plan.period, 20001)
    _, om, al, je = sol.plan.profile.at_time(t)
    assert om.max() * 60 / (2 * np.pi) <= lim.crank_speed_rpm * (1 + 1e-6)
    assert np.abs(al).max() <= lim.crank_accel_rad_s2 * (1 + 1e-6)
    assert np.abs(je).max() <= lim.crank_jerk_rad_s3 * (1 + 1e-6)


def test_motor_limits_cost_strokes_and_bind(limited, free_solution):
    case, sol = limited
    assert sol.plan.spm < free_solution.plan.spm
    p = sol.plan.parameters
    top = case.limits.crank_speed_rpm * 2 * np.pi / 60
    assert max(float(p.feed_peak_speed), float(p.return_peak_speed)) == pytest.approx(top, rel=1e-6)


def test_bound_with_motor_limits(limited, case):
    limited_case, sol = limited
    bound = time_optimal_bound(limited_case, 720)
    free_bound = time_optimal_bound(case, 720)
    assert sol.plan.spm <= bound.spm <= free_bound.spm
    assert bound.crank_speed_rpm.max() <= limited_case.limits.crank_speed_rpm * (1 + 1e-6)
