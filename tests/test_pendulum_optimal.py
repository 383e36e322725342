"""The optimal law on pendulum swings (issue 40): a free jerk profile per swing (``planning.model.free_swing``).

Checked from the written trajectory by the crank-slider's closed form and finite differences (not the plan's own
derivatives), against every law with halves and the rotary stroke of the same case, against the certified bound (an
inequality every plan must meet), on a link drive whose two swings differ, and with plans changed just past a limit.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from planning.cli import main
from planning.model.case_file import read_case
from planning.model.free_swing import FEED_SEGMENTS, closed_part_jerks, part_segments
from planning.model.pendulum import profile_of
from planning.model.profile import knot_states
from planning.solver.pendulum import solve_pendulum
from planning.solver.pendulum_bound import pendulum_bound
from planning.solver.pendulum_check import evaluate_pendulum

from .conftest import ROOT
from .test_pendulum import LINK, SHALLOW, _check_written, _random_press

OPTIMAL = {"planner.motion_law": "optimal"}


@pytest.fixture(scope="module")
def shallow():
    case = read_case(SHALLOW, OPTIMAL)
    return case, solve_pendulum(case)


def test_optimal_swings_beat_the_laws_with_halves_and_stay_below_the_bound(shallow):
    """The jerk-limited optimum of each swing makes more strokes than the best law with halves (each of which its
    free profile can nearly follow), more than the rotary stroke, and no more than the certified bound."""
    case, solution = shallow
    assert solution.evaluation.verification.passed and solution.plan.motion_law == "optimal"
    halves = [solve_pendulum(case.with_law(law), compare=False).plan.spm for law in ("seven-segment", "cycloidal")]
    assert solution.plan.spm > max(halves)
    assert solution.rotary_spm is not None and solution.plan.spm > 1.2 * solution.rotary_spm
    bound = pendulum_bound(case)
    assert bound.spm >= solution.plan.spm
    for k, swing in enumerate(("forward", "backward")):
        t = solution.plan.key_times(swing)
        assert t[3] - t[0] >= bound.arc_times_s[k]
    jerk = max(max(p.peak_jerks()) for p in (solution.plan.parameters.forward, solution.plan.parameters.backward))
    assert jerk == pytest.approx(case.limits.crank_jerk_rad_s3, rel=1e-6)  # the jerk limit binds: the law's own


def test_written_optimal_swing_through_the_closed_form(tmp_path):
    """From trajectory.csv alone (``tests.test_pendulum._check_written``: the closed form, finite differences, one
    reversal inside the cycle, both windows); the result names the law."""
    case = read_case(SHALLOW, OPTIMAL)
    assert main(["solve", str(SHALLOW), "--set", "planner.motion_law=optimal", "--out", str(tmp_path)]) == 0
    _check_written(case, tmp_path)
    result = json.loads((tmp_path / "result.json").read_text())
    assert result["motion_law"] == "optimal" and result["status"] == "verified"
    assert (tmp_path / "swing.png").stat().st_size > 10_000


def test_optimal_crank_slider_swings_are_mirror_images(shallow, monkeypatch):
    """On the in-line crank-slider the answer is the faster of the NLP with the swings tied as mirror images and the
    untied one (each from the seven-segment start): here the tied one, faster than the untied NLP's own answer; its
    swings are mirror images in the plan's profile (the backward swing's angle 360 deg less the forward's)."""
    import planning.solver.pendulum as pendulum

    case, solution = shallow
    plan = solution.plan
    monkeypatch.setattr(pendulum, "mirror_symmetric", lambda machine: False)  # the untied NLP alone
    untied = pendulum.solve_pendulum(case, compare=False).plan
    assert plan.spm >= untied.spm
    f, b = plan.parameters.forward, plan.parameters.backward
    assert np.allclose(b.feed_jerks, f.feed_jerks, rtol=1e-5, atol=1e-5 * max(np.abs(f.feed_jerks)))
    (f0, f1), (b0, _) = plan.swing_spans().values()
    tau = np.linspace(0.0, f1 - f0, 400)
    forward = plan.profile.at_time(f0 + tau)[0]
    backward = plan.profile.at_time(b0 + tau)[0]
    assert np.max(np.abs(backward - (2 * math.pi - forward))) < 1e-6


@pytest.mark.slow  # about 30 s
def test_optimal_link_drive_swings_differ_both_verified():
    case = read_case(LINK, OPTIMAL)
    solution = solve_pendulum(case, compare=False)
    assert solution.evaluation.verification.passed
    f, b = solution.plan.parameters.forward, solution.plan.parameters.backward
    assert abs(f.duration - b.duration) > 0.01 * f.duration  # the slide comes down on the fast side going back
    assert abs(f.draw_speed - b.draw_speed) > 0.1 * f.draw_speed  # (its draw allows less: 0.90 against 1.49 rad/s)
    assert solution.plan.spm > solve_pendulum(case.with_law("seven-segment"), compare=False).plan.spm
    assert pendulum_bound(case).spm >= solution.plan.spm


def test_optimal_swing_fails_its_verification_just_past_a_limit(shallow):
    """The verified plan against limits set just below what it uses: each check fails alone; a feed's jerk moved
    by a millionth: the swing no longer lands on the draw (its draw's speed not constant, the cycle not closed)."""
    case, solution = shallow
    plan = solution.plan
    used = {c.id: c.value for c in solution.evaluation.verification.checks}
    lowered = {
        "crank_jerk": {"crank_jerk_rad_s3": used["crank_jerk"] * 0.999},
        "crank_accel": {"crank_accel_rad_s2": used["crank_accel"] * 0.999},
        "slider_accel": {"slider_accel_mm_s2": used["slider_accel"] * 0.999},
    }
    for check_id, update in lowered.items():
        changed = case.model_copy(update={"limits": case.limits.model_copy(update=update)})
        assert {c.id for c in evaluate_pendulum(plan, changed).verification.failures()} == {check_id}
    f = plan.parameters.forward
    jerks = list(f.feed_jerks)
    jerks[FEED_SEGMENTS // 2] *= 1 + 1e-6
    moved = replace(plan.parameters, forward=replace(f, feed_jerks=tuple(jerks)))
    wrong = replace(plan, parameters=moved, profile=profile_of(moved))
    failed = {c.id for c in evaluate_pendulum(wrong, case).verification.failures()}
    assert {"draw_constant_speed", "cycle_angle"} <= failed


def test_closed_part_jerks_meet_the_ends_by_the_least_change():
    """The least-norm correction against the segments' closed forms (``planning.model.profile``): the end state
    met to round-off, the change orthogonal to the null space of the three end rows (the least norm)."""
    rng = np.random.default_rng(3)
    step, jerks = 0.02, tuple(rng.uniform(-100, 100, 12))
    start, end = (1.0, 0.0, 0.0), (1.05, 0.5, 0.0)
    closed = closed_part_jerks(step, jerks, start, end)
    reached = knot_states(*start, part_segments("part", step, closed))[-1]
    assert np.allclose([float(x) for x in reached], end, atol=1e-12)
    delta = np.subtract(closed, jerks)
    probe = closed_part_jerks(step, tuple(np.add(closed, delta * 1e-3)), start, end)  # a move along the change
    assert np.allclose(probe, closed, atol=1e-9)  # is undone: the change lies in the rows' span


def test_optimal_swing_commands(tmp_path, capsys):
    """check, bound --bracket and cam take the optimal law's swings; a hold with it is refused in one line."""
    optimal = ["--set", "planner.motion_law=optimal"]
    assert main(["bound", str(SHALLOW), *optimal, "--bracket", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["mode"] == "pendulum" and data["upper_bound_spm"] >= data["bracket"]["lower_spm"] > 0
    out = tmp_path / "cam"
    assert main(["cam", str(SHALLOW), *optimal, "--out", str(out), "--cam", "csv"]) == 0
    assert json.loads((out / "cam_proof.json").read_text())["passed"]
    capsys.readouterr()
    path = ROOT / "cases" / "coining-hold.yaml"
    args = ["solve", str(path), "--set", "planner.mode=pendulum", *optimal, "--no-plots", "--out", str(tmp_path / "x")]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "process.hold_time_s" in err[0]


def test_optimal_swing_peaks_read_off_the_profile(shallow):
    """The summary's peaks (the knots and the speed's stationary points inside segments) against the profile
    sampled every 0.1 ms: the highest crank speed of each swing's feed and return, the highest acceleration."""
    _, solution = shallow
    plan = solution.plan
    f = plan.parameters.forward
    t = np.arange(0.0, float(f.feed_time), 1e-4)
    feed = np.abs(plan.profile.at_time(t)[1])
    t3 = float(f.feed_time + f.draw_time)
    back = np.arange(t3, t3 + float(f.return_time), 1e-4)
    ret = np.abs(plan.profile.at_time(back)[1])
    assert f.feed_peak_speed == pytest.approx(float(np.max(feed)), rel=1e-6)
    assert f.return_peak_speed == pytest.approx(float(np.max(ret)), rel=1e-6)
    alpha = np.abs(plan.profile.at_time(np.concatenate([t, back]))[2])
    assert max(f.peak_accelerations()) == pytest.approx(float(np.max(alpha)), rel=1e-4)


@pytest.mark.slow  # about 70 s
def test_random_optimal_swings_hold_every_limit_by_an_independent_check(tmp_path):
    """Random in-line crank-slider presses swinging under the optimal law: every plan ``solve`` calls verified holds
    every limit by ``_check_written`` (no false success); a press without a plan gets exit 3, never a traceback."""
    import yaml

    rng = np.random.default_rng(41)
    verified = 0
    for k in range(5):
        data = _random_press(rng)
        data["planner"]["motion_law"] = "optimal"
        path = tmp_path / f"press{k}.yaml"
        path.write_text(yaml.safe_dump(data), encoding="utf-8")
        code = main(["solve", str(path), "--out", str(tmp_path / f"out{k}"), "--no-plots"])
        assert code in (0, 3), path.read_text()
        if code == 0:
            _check_written(read_case(path), tmp_path / f"out{k}")
            verified += 1
    assert verified >= 4


def test_optimal_swings_start_from_another_law_where_the_seven_segment_finds_none(monkeypatch):
    """Where the seven-segment law finds no swings the cycloidal law's start the optimal ones (the same verified
    answer class: more strokes than the cycloidal's own); where no seed law finds any, the optimal law says so."""
    import planning.solver.pendulum as pendulum
    from planning.solver.outcomes import NoPlanFound

    solve = pendulum.solve_pendulum
    failing = {"seven-segment"}

    def seeds_fail(case, compare=True):  # noqa: ANN001, ANN202 - the solver's own signature
        if case.planner.motion_law in failing:
            raise NoPlanFound("no start converged (a test)")
        return solve(case, compare)

    monkeypatch.setattr(pendulum, "solve_pendulum", seeds_fail)
    case = read_case(SHALLOW, OPTIMAL)
    solution = solve(case, compare=False)
    assert solution.evaluation.verification.passed
    assert solution.plan.spm > solve(case.with_law("cycloidal"), compare=False).plan.spm
    failing.add("cycloidal")
    with pytest.raises(NoPlanFound, match="optimal law's swings start from"):
        solve(case, compare=False)
