"""The robots' first layer (press/robot.py): the fastest move against an independent package (ruckig, the
time-optimal trajectory generator) and the closed forms; the interference curve; a robot's cycle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from press.robot import InterferenceCurve, MoveLimits, Robot, fastest_move

ruckig = pytest.importorskip("ruckig")


def ruckig_move(length_mm: float, limits: MoveLimits):  # noqa: ANN201 - a ruckig Trajectory
    """ruckig's time-optimal rest-to-rest trajectory over ``length_mm`` (infinite jerk: acceleration-limited)."""
    given = ruckig.InputParameter(1)
    given.current_position, given.target_position = [0.0], [length_mm]
    given.max_velocity, given.max_acceleration = [limits.speed_mm_s], [limits.accel_mm_s2]
    given.max_jerk = [math.inf if limits.jerk_mm_s3 is None else limits.jerk_mm_s3]
    trajectory = ruckig.Trajectory(1)
    assert ruckig.Ruckig(1).calculate(given, trajectory) == ruckig.Result.Working
    return trajectory


def random_moves(count: int, jerk: bool) -> list[tuple[float, MoveLimits]]:
    rng = np.random.default_rng(39 + jerk)
    moves = []
    for _ in range(count):
        length = float(10 ** rng.uniform(0, 3.5))  # 1 mm .. 3 m: short moves (no top speed) and long ones
        limits = MoveLimits(
            float(rng.uniform(500, 5000)),
            float(rng.uniform(2000, 40000)),
            float(10 ** rng.uniform(4, 6.5)) if jerk else None,
        )
        moves.append((length, limits))
    return moves


@pytest.mark.parametrize("jerk", [False, True], ids=["trapezoid", "double-S"])
def test_the_fastest_move_is_ruckigs(jerk: bool) -> None:
    """60 random moves each: the duration equals ruckig's to 1e-9 relative, the position along the move to
    1e-6 mm at 200 instants, and speed, acceleration (and jerk) stay within the limits."""
    for length, limits in random_moves(60, jerk):
        move, reference = fastest_move(length, limits), ruckig_move(length, limits)
        assert move.duration_s == pytest.approx(reference.duration, rel=1e-9), (length, limits)
        times = np.linspace(0, move.duration_s, 200)
        s, v, a = move.state(times)
        expected = np.array([reference.at_time(float(t))[0][0] for t in times])
        assert np.max(np.abs(s - expected)) < 1e-6 * max(1.0, length), (length, limits)
        assert s[-1] == pytest.approx(length, rel=1e-12) and np.all(np.diff(s) >= -1e-9)
        assert np.max(np.abs(v)) <= limits.speed_mm_s * (1 + 1e-12)
        assert np.max(np.abs(a)) <= limits.accel_mm_s2 * (1 + 1e-12)
        if jerk:
            pieces = move.pieces
            assert max(abs(p[2]) for p in pieces) <= limits.jerk_mm_s3
            ends = [p[1] + p[2] * p[0] for p in pieces]  # the acceleration continuous from piece to piece
            gaps = [abs(end - after[1]) for end, after in zip(ends, pieces[1:], strict=False)]
            assert max(gaps, default=0.0) < 1e-9 * limits.accel_mm_s2


def test_the_trapezoid_and_the_triangle_in_closed_form() -> None:
    limits = MoveLimits(2000.0, 10000.0)
    assert fastest_move(800.0, limits).duration_s == pytest.approx(800 / 2000 + 2000 / 10000, rel=1e-15)
    assert fastest_move(100.0, limits).duration_s == pytest.approx(2 * math.sqrt(100 / 10000), rel=1e-15)
    s, v, _ = fastest_move(100.0, limits).state(np.array([0.1]))  # the triangle's middle: half the way, top speed
    assert s[0] == pytest.approx(50.0) and v[0] == pytest.approx(10000 * 0.1)


def test_the_interference_curve_is_linear_and_zero_beyond_its_last_point() -> None:
    curve = InterferenceCurve((0.0, 300.0, 600.0), (700.0, 700.0, 0.0))
    assert list(curve.need([0.0, 150.0, 450.0, 600.0, 601.0, 1500.0])) == [700.0, 700.0, 350.0, 0.0, 0.0, 0.0]


def test_a_robots_cycle_moves_in_dwells_moves_out_and_waits_periodically() -> None:
    robot = Robot("unloader", 1200.0, MoveLimits(3000.0, 15000.0), 0.25, InterferenceCurve((0.0, 800.0), (650.0, 0.0)))
    move_s = robot.move.duration_s
    assert move_s == pytest.approx(1200 / 3000 + 3000 / 15000) and robot.occupancy_s == pytest.approx(2 * move_s + 0.25)
    period, start = 5.0, 4.2  # the cycle wraps past the period's end
    times = np.array([start, start + move_s, start + move_s + 0.2, start + 2 * move_s + 0.25, start + 3.5]) % period
    x = robot.position(times, start, period)
    assert x[0] == pytest.approx(1200.0)
    assert x[1] == pytest.approx(0.0, abs=1e-9) and x[2] == pytest.approx(0.0, abs=1e-9)
    assert x[3] == pytest.approx(1200.0) and x[4] == pytest.approx(1200.0)
    need = robot.needed_height(times, start, period)
    assert need[1] == pytest.approx(650.0) and need[0] == 0.0
    dense = np.linspace(0, period, 5001)
    positions = robot.position(dense, start, period)
    assert positions.min() == pytest.approx(0.0, abs=1e-9) and positions.max() == pytest.approx(1200.0)


def test_a_robot_longer_than_the_cycle_is_refused() -> None:
    robot = Robot("loader", 1000.0, MoveLimits(1000.0, 5000.0), 0.5, InterferenceCurve((0.0, 500.0), (600.0, 0.0)))
    with pytest.raises(ValueError, match="longer than the cycle"):
        robot.position(np.array([0.0]), 0.0, robot.occupancy_s - 0.1)
