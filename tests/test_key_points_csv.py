"""``key_points.csv`` (an output of the registry, ``planning/reports/outputs/key_points_csv.py``): read back with
the csv module, its angles are the case's key angles, its heights the mechanism's closed form there, its times
and speeds those of the trajectory around them; ``solve`` writes it and the page offers it."""

from __future__ import annotations

import csv

import numpy as np

from planning.cli import main
from planning.model.case_file import read_case
from planning.reports.outputs import downloads, owned_files
from tests.conftest import PUBLISHED_CASE


def test_solve_writes_the_key_points_and_the_page_offers_them(tmp_path):
    assert main(["solve", str(PUBLISHED_CASE), "--out", str(tmp_path), "--no-plots"]) == 0
    with open(tmp_path / "key_points.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    case = read_case(PUBLISHED_CASE)
    assert [r["key_point"] for r in rows] == ["closing", "draw_start", "draw_end", "opening"]
    angles = np.array([float(r["angle_deg"]) for r in rows])
    assert np.allclose(np.radians(angles), case.key_angles, rtol=0, atol=1e-12)
    heights = np.array([float(r["slider_height_mm"]) for r in rows])
    assert np.allclose(heights, case.machine.height(np.radians(angles)), rtol=1e-9)
    assert min(heights[0], heights[3]) >= case.process.safety_height_mm  # the robot's window opens and closes there
    traj = np.genfromtxt(tmp_path / "trajectory.csv", delimiter=",", names=True)
    times = np.array([float(r["time_s"]) for r in rows])
    assert np.all(np.diff(times) > 0)
    for name, column in (("slider_speed_mm_s", "slider_speed_mm_s"), ("crank_speed_rpm", "crank_speed_rpm")):
        mine = np.array([float(r[name]) for r in rows])
        nearby = np.interp(times, traj["time_s"], traj[column])  # the 1 ms trajectory, interpolated
        assert np.allclose(mine, nearby, rtol=1e-3, atol=0.05), name
    assert float(rows[1]["slider_speed_mm_s"]) < 0 < float(rows[2]["slider_speed_mm_s"])  # down, then up
    assert "key_points.csv" in owned_files() and "key_points.csv" in {o.name for o in downloads()}
