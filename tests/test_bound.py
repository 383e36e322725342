"""The time-optimal bound: its value for the published case, convergence, and that it bounds every plan."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from planning.cli import main
from planning.model.case import RPM
from planning.model.case_file import case_from_data, read_case
from planning.model.laws import LAWS
from planning.model.outcome import Outcome
from planning.solver.bound import time_optimal_bound
from planning.solver.optimize import solve

from .conftest import PUBLISHED_CASE

# issue 5: "For the published case we computed ~13.06 SPM without a jerk limit"; accepted 13.0-13.12
BOUND_RANGE = (13.0, 13.12)


@pytest.fixture(scope="module")
def bounds(case):
    return {n: time_optimal_bound(case, n) for n in (360, 720, 1440, 2880)}


def test_published_case_bound(bounds):
    assert BOUND_RANGE[0] <= bounds[1440].spm <= BOUND_RANGE[1]


def test_bound_converges_under_grid_refinement(bounds):
    spm = [bounds[n].spm for n in (360, 720, 1440, 2880)]
    steps = [abs(b - a) for a, b in zip(spm, spm[1:], strict=False)]
    assert steps[-1] < steps[0] and steps[-1] < 0.005  # settles to a few thousandths of a stroke


def test_bound_is_above_every_plan(bounds, free_solution, published_solution):
    finest = min(b.spm for b in bounds.values())
    assert finest >= free_solution.plan.spm >= published_solution.plan.spm


def test_bound_command(capsys):
    assert main(["bound", str(PUBLISHED_CASE), "--json", "--points", "720"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert BOUND_RANGE[0] <= data["spm"] <= BOUND_RANGE[1] and data["points"] >= 700


SERVO_CASE = PUBLISHED_CASE.parent / "side-panel-servo-limits.yaml"


@pytest.fixture(scope="module")
def servo_case():
    from planning.model.case_file import read_case

    return read_case(SERVO_CASE)


def test_jerk_limited_bound_converges_and_tightens(servo_case):
    """With the case's crank-jerk limit the bound converges under refinement (steps halve: first order)
    and lies below the bound without it."""
    spm = [time_optimal_bound(servo_case, n).spm for n in (360, 720, 1440)]
    steps = [abs(b - a) for a, b in zip(spm, spm[1:], strict=False)]
    assert steps[1] < 0.6 * steps[0] and steps[1] < 0.015
    free = servo_case.model_copy(update={"limits": servo_case.limits.model_copy(update={"crank_jerk_rad_s3": None})})
    assert time_optimal_bound(free, 1440).spm > spm[-1] + 0.1


@pytest.mark.slow  # every law and the jerk-limited bound: 24 s
def test_laws_against_the_jerk_limited_bound(servo_case):
    """Issue 5: with a crank-jerk limit the best law reaches >= 95 % of the jerk-limited bound, and
    no law exceeds the bound."""
    from planning.reports.law_comparison import compare_laws

    data, _ = compare_laws(servo_case)
    shares = [r["share_of_bound_pct"] for r in data["laws"] if r["status"] == Outcome.VERIFIED]
    assert len(shares) == len(LAWS) and data["jerk_limited_bound"]
    assert max(shares) >= 95.0 and max(shares) <= 100.0


# ---- TOPP-RA as an independent oracle --------------------------------------------------------------------

CASES = Path(__file__).resolve().parent.parent / "cases"
# relative: two discretisations of one problem (collocation in TOPP-RA, intervals here), on the coarse
# (1440 intervals, 1001 TOPP-RA points) and the fine grid (2880, 2001); the gap is first order in the step
ORACLE_AGREE = {1440: 6e-3, 2880: 2e-3}


def _toppra_arc_time(case, start: float, end: float, w_start: float, w_end: float, gridpoints: int) -> float:
    """TOPP-RA's (``toppra``, reachability analysis) least time [s] over the crank arc ``start .. end``
    [rad] from crank speed ``w_start`` to ``w_end`` [rad/s], the path being the slider height h(theta):
    |slider acceleration| <= the limit, |slider speed| <= the die speed where the slide is at or below the
    die height. An independent solver of the same arc problem as the bound."""
    import toppra.algorithm as algo
    import toppra.constraint as constraint
    from toppra.interpolator import AbstractGeometricPath

    m = case.machine

    class SlidePath(AbstractGeometricPath):
        def __call__(self, s, order=0):  # noqa: ANN001, ANN204 - toppra's interface
            s = np.atleast_1d(np.asarray(s, dtype=float))
            value = m.height(s) if order == 0 else m.derivatives(s)[order - 1]
            return np.asarray(value).reshape(-1, 1)

        @property
        def dof(self) -> int:
            return 1

        @property
        def path_interval(self) -> np.ndarray:
            return np.array([start, end])

        @property
        def waypoints(self) -> None:
            return None

    lim = case.limits

    def die_speed(s):  # noqa: ANN001, ANN202
        v = lim.die_speed_mm_s if float(m.height(float(s))) <= lim.die_height_mm else 1e9
        return np.array([[-v, v]])

    limits = [
        constraint.JointAccelerationConstraint(np.array([[-lim.slider_accel_mm_s2, lim.slider_accel_mm_s2]])),
        constraint.JointVelocityConstraintVarying(die_speed),
    ]
    grid = np.linspace(start, end, gridpoints)
    solver = algo.TOPPRA(limits, SlidePath(), gridpoints=grid, parametrizer="ParametrizeConstAccel")
    _, sd, _ = solver.compute_parameterization(w_start, w_end)
    return float(np.sum(2 * np.diff(grid) / (sd[:-1] + sd[1:])))


def _bound_arc(bound, start: float, end: float) -> tuple[float, float, float]:
    """The bound's own time over ``start .. end`` and its speeds at both ends."""
    th, w = np.radians(bound.angle_deg), bound.crank_speed_rpm * RPM
    i0, i1 = int(np.argmin(abs(th - start))), int(np.argmin(abs(th - end)))
    assert abs(th[i0] - start) < 1e-9 and abs(th[i1] - end) < 1e-9  # the key angles are nodes
    t = float(np.sum(2 * np.diff(th[i0 : i1 + 1]) / (w[i0:i1] + w[i0 + 1 : i1 + 1])))
    return t, float(w[i0]), float(w[i1])


@pytest.mark.parametrize("name", ["wang2023-side-panel", "small-fast-cup", "heavy-slow-body-side"])
def test_toppra_agrees_with_the_bound_on_its_acceleration_limited_arcs(name: str) -> None:
    """The return (theta3 -> theta4) and the feed (theta1 -> theta2) of the bound's profile are
    time-optimal for their end speeds (any better arc would shorten the cycle; the robot window lies
    outside them): TOPP-RA, given the same end speeds and limits, finds the same time within
    ORACLE_AGREE (0.2 % on the fine grids), and the two come closer as both grids refine."""
    pytest.importorskip("toppra")
    case = read_case(CASES / f"{name}.yaml")
    th1, th2, th3, th4 = (float(a) for a in case.key_angles)
    gaps = []
    for points, gridpoints in ((1440, 1001), (2880, 2001)):
        bound = time_optimal_bound(case, points)
        level = []
        for start, end in ((th3, th4), (th1, th2)):
            t_bound, w_start, w_end = _bound_arc(bound, start, end)
            t_oracle = _toppra_arc_time(case, start, end, w_start, w_end, gridpoints)
            assert abs(t_oracle - t_bound) <= ORACLE_AGREE[points] * t_bound, (name, points, start, t_bound, t_oracle)
            level.append(abs(t_oracle - t_bound) / t_bound)
        gaps.append(level)
    assert gaps[1][0] < gaps[0][0]  # the return arc: the finer grids agree better


# ---- the certified upper bound (planning.solver.upper_bound) ----

# The fastest cycles of the published case found by an independent computation (multiple shooting with
# exact piecewise-constant-jerk propagation, four free-time phases, IPOPT, converged over N = 100 ... 800
# intervals per phase, every optimum re-simulated at 1 ms; issue 28): reference values, not pressplan's.
INDEPENDENT_OPTIMUM_SPM = {32.63: 12.40178, 97.9: 12.76810, 326.3: 12.94824, 3263: 13.03607}
INDEPENDENT_VERIFIED_NO_JERK_SPM = 13.0405  # a motion meeting every limit, no jerk limit (same source)


def test_the_certified_bound_is_above_a_motion_that_meets_every_limit_and_close_to_it(case):
    """The published case at the default grid: at least the independent verified 13.0405, at most 13.05
    (0.06 % above it); the grid bound (a restriction) is below that motion."""
    from planning.solver.upper_bound import upper_bound

    upper = upper_bound(case)
    assert INDEPENDENT_VERIFIED_NO_JERK_SPM <= upper.spm <= 13.05, upper.spm
    assert time_optimal_bound(case).spm < INDEPENDENT_VERIFIED_NO_JERK_SPM  # why the certified one is needed
    assert upper.left_out == ()


@pytest.mark.parametrize("jerk", sorted(INDEPENDENT_OPTIMUM_SPM))
def test_the_certified_bound_is_above_the_independent_optimum_at_each_jerk_limit(case, jerk):
    """With a crank-jerk limit the relaxation keeps it (neighbouring mean accelerations within J times the
    two intervals' time); on a coarse grid (looser, still an upper bound) above each reference optimum."""
    from planning.solver.upper_bound import upper_bound

    data = case.model_dump(exclude_none=True)
    data["limits"]["crank_jerk_rad_s3"] = jerk
    upper = upper_bound(case_from_data(data), 360, 1)
    assert upper.spm >= INDEPENDENT_OPTIMUM_SPM[jerk]
    assert upper.spm <= upper_bound(case, 360, 1).spm + 1e-9  # a jerk limit only lowers it


# issue 28's targets for the optimal law on the published case: within 0.1 % of the independent optimum at
# 3263 rad/s^3, and no lower than before at 32.63 rad/s^3
OPTIMAL_LAW_AT_LEAST_SPM = {32.63: 12.397, 3263: 13.023}
@pytest.mark.slow  # about 3 s


def test_the_optimal_law_comes_up_to_the_independent_optimum_at_any_jerk_limit(case):
    """At a high jerk limit the first layout of equal segments cannot follow the arcs where the slider
    acceleration sits at its limit (it used 832 of 3263 rad/s^3 and made 12.994): the plan is solved again on
    the finer layout, whose peak jerk reaches the limit; at a low limit the jerk binds and nothing changes.
    Each plan verified, below the certified upper bound's coarse grid."""
    from planning.model.profile import max_abs_jerk
    from planning.solver.upper_bound import upper_bound

    for jerk, at_least in OPTIMAL_LAW_AT_LEAST_SPM.items():
        data = case.model_dump(exclude_none=True)
        data["limits"]["crank_jerk_rad_s3"] = jerk
        data["planner"]["motion_law"] = "optimal"
        limited = case_from_data(data)
        sol = solve(limited)
        assert at_least <= sol.plan.spm <= INDEPENDENT_OPTIMUM_SPM[jerk], sol.plan.spm
        assert max_abs_jerk(sol.plan.profile) >= 0.99 * jerk  # the limit is used where the optimum needs it
        assert sol.plan.spm <= upper_bound(limited, 180, 2).spm


def test_the_certified_bound_falls_as_the_grid_refines_towards_the_optimum(case):
    """A finer grid tightens the relaxation (each value above every motion within the limits)."""
    from planning.solver.upper_bound import upper_bound

    values = [upper_bound(case, n, 1).spm for n in (96, 360, 1440)]
    assert values[0] > values[1] > values[2] > INDEPENDENT_VERIFIED_NO_JERK_SPM


@pytest.mark.slow  # 4-7 s a case: the normal run keeps under 5 minutes (CI runs the slow tier)
def test_the_bracket_of_the_published_case_is_within_its_tolerance(case):
    """Issue 28's bracket: a motion that passes the dense verification below a certified upper bound in
    [13.0405, 13.05], their gap within the default 0.05 % (the optimal law refined to 6 x its first layout
    under the jerk allowance: the case sets no jerk limit); the printed lines say it."""
    from planning.cli import bracket_text
    from planning.solver.bracket import BRACKET_TOL_PCT, bracket
    from planning.solver.verify import verify

    result = bracket(case)
    plan = result.verified.plan
    assert INDEPENDENT_VERIFIED_NO_JERK_SPM <= result.upper.spm <= 13.05, result.upper.spm
    assert plan.spm <= result.upper.spm and verify(plan, case).passed
    assert result.met and 0 < 100 * (result.upper.spm / plan.spm - 1) <= BRACKET_TOL_PCT, result.rounds
    assert result.rounds[0].gap_pct > BRACKET_TOL_PCT  # refined: the first layout alone does not reach it
    assert result.jerk_allowance_rad_s3 is not None and case.limits.crank_jerk_rad_s3 is None
    text = bracket_text(result)
    assert f"{plan.spm:.4f} SPM verified" in text and "within the tolerance 0.05 %" in text


def test_the_bracket_refuses_a_tolerance_that_is_no_percentage(capsys):
    assert main(["bound", str(PUBLISHED_CASE), "--tolerance", "-1"]) == 2
    assert "--tolerance -1.0: the gap must be a positive percentage" in capsys.readouterr().err


ROW_REL_TOL = 1e-6  # a verified plan meets its limits to this share (the dense verification's REL_TOL)


def _own_point(relaxed, plan):
    """The plan's own point of the relaxed problem: its speed squared at the nodes, its time on each piece."""
    prof, period = plan.profile, plan.period
    t1 = prof.time_at_angle(float(relaxed.theta[0]) % (2 * np.pi))

    def time_at(angle: float) -> float:
        return (
            period
            if angle >= relaxed.theta[0] + 2 * np.pi - 1e-12
            else (prof.time_at_angle(angle % (2 * np.pi)) - t1) % period
        )

    def speed_at(angles):
        return prof.at_time(np.array([prof.time_at_angle(float(a) % (2 * np.pi)) for a in angles]))[1]

    return relaxed.point_of(speed_at, time_at)


def _violations(relaxed, x) -> int:
    """Rows and bounds the point breaks by more than :data:`ROW_REL_TOL` of their size."""
    g = relaxed.rows_at(x)
    out = 0
    for value, lo, hi in ((g, relaxed.lbg, relaxed.ubg), (x, relaxed.lbx, relaxed.ubx)):
        room = (
            ROW_REL_TOL
            * (np.abs(value) + np.where(np.isfinite(lo), np.abs(lo), 0) + np.where(np.isfinite(hi), np.abs(hi), 0))
            + 1e-12
        )
        out += int(np.sum((value - hi > room) | (lo - value > room)))
    return out


@pytest.mark.parametrize("name", ["wang2023-side-panel", "side-panel-servo-limits", "knuckle-joint-coining"])
def test_a_verified_plan_is_a_point_of_the_relaxation(name):
    """The certificate itself: a verified plan's own values (speed squared at the nodes, time on each piece)
    meet every row and bound of the relaxed problem, so its optimum cannot be below the plan (the crank
    speed, acceleration and jerk limits of the servo case; the knuckle joint's dips near BDC as nodes). The
    same plan made 1 % faster breaks rows: the check can fail."""
    from planning.solver.upper_bound import relaxation

    case = read_case(CASES / f"{name}.yaml")
    plan = solve(case).plan
    relaxed = relaxation(case, 360, 2)
    x = _own_point(relaxed, plan)
    assert np.sum(x[relaxed.theta.size - 1 :]) == pytest.approx(plan.period, rel=1e-9)
    assert _violations(relaxed, x) == 0
    n = relaxed.theta.size - 1
    faster = np.concatenate([x[:n] / 0.99**2, x[n:] * 0.99])
    assert _violations(relaxed, faster) > 0


@pytest.mark.slow
def test_the_bracket_of_a_case_planned_at_the_lines_rate_is_for_the_most_strokes():
    """A case whose objective is at the line's rate is bracketed for the most strokes (its motion is not held
    to the rate's cycle time, which it would fail)."""
    from planning.solver.bracket import bracket

    case = read_case(CASES / "wang2023-side-panel-drive.yaml").with_objective("min-rms-torque", 5.0)
    result = bracket(case, math.inf)
    assert result.verified.plan.spm > 5.0 * 1.5 and result.verified.plan.spm <= result.upper.spm
