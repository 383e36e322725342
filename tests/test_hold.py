"""A hold at the bottom (issue 40): the crank brakes after the draw, stands at the hold's angle for the hold time,
and rises again; every limit holds through the stop and the restart.

Checked from the written outputs with the crank-slider's own closed form (the slide's height from the crank angle),
by finite differences of the written crank speed (not the plan's derivatives), and through a cam read back by an
independent Structured Text parser and interpolated by scipy as a controller would."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import replace

import numpy as np
import pytest

from planning.cli import main
from planning.model.cam_points import law_cam
from planning.model.case_file import read_case
from planning.model.plan import profile_from_tdc
from planning.solver.optimize import solve
from planning.solver.verify import evaluate

from .cam_clients import quintic_through, st_points
from .conftest import ROOT, shipped, solved

COINING = ROOT / "cases" / "coining-hold.yaml"
STILL_MM = 1e-3  # the micrometre
RPM = 2 * math.pi / 60


def _columns(path) -> dict[str, np.ndarray]:  # noqa: ANN001
    with open(path, encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def _longest_still_s(t: np.ndarray, still: np.ndarray) -> float:
    """The longest run of consecutive samples with ``still``, first to last [s]."""
    best, first = 0.0, None
    for i, flag in enumerate(np.append(still, False)):
        if flag and first is None:
            first = i
        elif not flag and first is not None:
            best, first = max(best, t[i - 1] - t[first]), None
    return best


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("hold") / "out"
    assert main(["solve", str(COINING), "--out", str(out), "--no-plots"]) == 0
    return out


def test_the_slide_stands_at_bdc_for_the_hold_time_in_the_written_trajectory(written):
    """trajectory.csv: the slide within 1 um of BDC for at least 0.3 s on end, by the crank-slider's closed form
    from the written crank angle; the crank stands still there (speed 0) and the summary says so."""
    case = shipped(COINING)
    cols = _columns(written / "trajectory.csv")
    t, theta = cols["time_s"], np.radians(cols["crank_angle_deg"])
    R, L = case.press.crank_radius_mm, case.press.rod_length_mm
    h = R * (1 + np.cos(theta)) + L - np.sqrt(L**2 - (R * np.sin(theta)) ** 2)  # 0 at BDC, 2R at TDC
    np.testing.assert_allclose(cols["slider_height_mm"], h, atol=1e-9)
    still = np.abs(h - case.process.hold_height_mm) <= STILL_MM
    assert _longest_still_s(t, still) >= 0.3
    stopped = np.abs(cols["crank_speed_rpm"]) <= 1e-9
    assert _longest_still_s(t, stopped) >= 0.3 - 1.1e-3  # the standstill itself (the 1 ms grid's knots)
    result = json.loads((written / "result.json").read_text())
    assert result["verified"] and result["hold"]["time_s"] == 0.3 and result["hold"]["angle_deg"] == 180.0
    assert "stands 0.3000 s" in (written / "summary.txt").read_text()


def test_every_limit_holds_through_the_stop_and_the_restart(written):
    """Finite differences of the written crank speed (the acceleration, the jerk) and of the slide's height (its
    speed, its acceleration) stay within the case's limits around the hold, as the verification says."""
    case = shipped(COINING)
    cols = _columns(written / "trajectory.csv")
    t = cols["time_s"]
    result = json.loads((written / "result.json").read_text())
    hold = result["hold"]
    t3 = next(k["time_s"] for k in result["key_points"] if k["name"] == "draw_end")
    around = (t >= t3 - 0.05) & (t <= t3 + hold["brake_s"] + hold["time_s"] + 0.3)
    omega = cols["crank_speed_rpm"] * RPM
    step = np.diff(t)
    alpha = np.diff(omega) / step
    jerk = np.diff(alpha) / (0.5 * (step[1:] + step[:-1]))
    lim = case.limits
    assert np.max(np.abs(alpha[around[1:]])) <= lim.crank_accel_rad_s2 * (1 + 1e-3)
    assert np.max(np.abs(jerk[around[2:]])) <= lim.crank_jerk_rad_s3 * (1 + 1e-2)
    h = cols["slider_height_mm"]
    v = np.gradient(h, t)
    a = np.gradient(v, t)
    assert np.max(np.abs(a[around])) <= lim.slider_accel_mm_s2
    below = around & (h <= lim.die_height_mm)
    assert np.max(np.abs(v[below])) <= lim.die_speed_mm_s * (1 + 1e-3)
    checks = {c["name"]: c for c in result["verification"]["checks"]}
    assert checks["crank standing, the slide at its hold height"]["passed"]
    assert checks["crank speed (forward, stopping only in the hold)"]["value"] >= lim.min_crank_speed_rpm
    assert checks["crank speed in the hold's stop (forward or standing)"]["passed"]


def test_a_hold_above_bdc_stands_at_its_height():
    """Held 2 mm above BDC: the crank stands where the closed form puts that height on the way down."""
    case = shipped(COINING, process__hold_height_mm=2.0, key_points__draw_end_deg=160.0)
    solution = solve(case)
    R, L = case.press.crank_radius_mm, case.press.rod_length_mm
    th = case.hold_angle
    assert R * (1 + math.cos(th)) + L - math.sqrt(L**2 - (R * math.sin(th)) ** 2) == pytest.approx(2.0, abs=1e-9)
    assert th < math.pi
    assert solution.verification.passed and solution.verification.check("hold").value == pytest.approx(0.3, abs=1e-9)


def test_the_verification_fails_a_hold_cut_short_and_a_hold_of_the_wrong_height():
    """The same plan with its standstill 10 ms short fails the hold's check; the plan against a case that asks
    for the hold 0.5 mm higher fails it too."""
    case, plan = shipped(COINING), solved(COINING).plan
    short = replace(plan.parameters, hold_time=plan.parameters.hold_time - 0.01)
    cut = replace(plan, parameters=short, profile=profile_from_tdc(short))
    failed = [c.id for c in evaluate(cut, case).verification.failures()]
    assert "hold" in failed
    higher = shipped(COINING, process__hold_height_mm=0.5)
    assert "hold" in [c.id for c in evaluate(plan, higher).verification.failures()]


def test_the_min_crank_speed_holds_everywhere_but_the_planned_stop():
    """Outside the stop the least crank speed holds; a plan whose dwell crawls below it fails."""
    case, plan = shipped(COINING), solved(COINING).plan
    check = evaluate(plan, case).verification.check("min_crank_speed")
    assert check.passed and check.value >= case.limits.min_crank_speed_rpm
    stricter = shipped(COINING, limits__min_crank_speed_rpm=check.value * 1.01)
    assert "min_crank_speed" in [c.id for c in evaluate(plan, stricter).verification.failures()]


@pytest.mark.slow  # the certified bounds: about 10 s each
def test_the_bounds_add_the_hold_and_stay_above_the_plan():
    """The time-optimal and the certified bound of the hold case, with a short and a long hold: above the
    verified plan (the hold's time added, the least crank speed left out)."""
    from planning.solver.bound import time_optimal_bound
    from planning.solver.upper_bound import upper_bound

    for hold_s in (0.3, 1.5):
        case = shipped(COINING, process__hold_time_s=hold_s)
        spm = solve(case).plan.spm
        upper, grid = upper_bound(case), time_optimal_bound(case)
        assert upper.spm >= grid.spm * (1 - 1e-6) and grid.spm > spm


def test_the_cam_of_a_hold_read_by_a_parser_holds_the_slide_still(tmp_path):
    """The CODESYS cam (blark parses it), interpolated by scipy's quintic as the controller does at the plan's
    master speed: the slide within 1 um of BDC for at least the hold time."""
    out = tmp_path / "cam"
    assert main(["cam", str(COINING), "--out", str(out), "--cam", "codesys"]) == 0
    case, plan = shipped(COINING), solved(COINING).plan
    points = st_points((out / "cam_codesys.st").read_text(), "Cam_coining_hold_Points")
    x, y, v, a = (np.array([float(p[k]) for p in points]) for k in ("dX", "dY", "dV", "dA"))
    assert x.size == law_cam(plan).points + 1
    t = np.arange(0.0, plan.period, 1e-4)
    cam = quintic_through(x, y, v, a)
    theta = np.radians(cam(360.0 * t / plan.period))
    speed = np.radians(cam.derivative()(360.0 * t / plan.period)) * 360.0 / plan.period  # [rad/s]
    h = case.machine.height(theta)
    assert _longest_still_s(t, (np.abs(h) <= STILL_MM) & (np.abs(speed) <= 1e-9)) >= 0.3 - 2e-4  # the grid's step


@pytest.mark.parametrize(
    ("fields", "says"),
    [
        ({"key_points.draw_end_deg": 190.0}, "key_points.draw_end_deg: must lie before the hold at 180.00 deg"),
        ({"process.hold_time_s": None, "process.hold_height_mm": 1.0}, "process.hold_height_mm: needs process.hold_"),
        ({"process.hold_height_mm": 100.0}, "process.hold_height_mm: must lie below the stroke's top"),
        ({"key_points.opening_deg": 179.0, "key_points.draw_end_deg": 170.0}, "key_points.opening_deg: must lie"),
    ],
)
def test_a_hold_that_cannot_be_is_one_line_naming_the_field(fields, says, tmp_path, capsys):
    import yaml

    data = yaml.safe_load(COINING.read_text())
    for key, value in fields.items():
        section, name = key.split(".")
        if value is None:
            data[section].pop(name, None)
        else:
            data[section][name] = value
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    assert main(["solve", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(path) in err and says in err, err
    assert not out.exists()


def test_a_sweep_of_the_hold_time_is_slower_the_longer_the_hold(tmp_path):
    """Five hold times, each verified; the strokes fall as the hold grows, by about the hold's time per cycle."""
    out = tmp_path / "sweep"
    assert main(["sweep", str(COINING), "--vary", "process.hold_time_s=0.1:0.5:5", "--out", str(out)]) == 0
    rows = list(csv.DictReader(open(out / "sweep.csv", encoding="utf-8")))
    spm = np.array([float(r["spm"]) for r in rows])
    assert all(r["status"] == "verified" for r in rows) and np.all(np.diff(spm) < 0)
    period = 60.0 / spm
    np.testing.assert_allclose(np.diff(period), 0.1, rtol=0.05)


def _with_hold(seed: int) -> dict:
    """A random in-line crank-slider (``tests/random_cases.py``) with a hold: at BDC or 0.1-1 % of the stroke above it,
    0.05-1 s, the draw ending halfway from theta2 to the hold, a crank jerk limit on every other one."""
    from .random_cases import seeded_case

    rng = np.random.default_rng(500 + seed)
    data = seeded_case(seed)
    from press.crank_slider import CrankSlider

    m = CrankSlider(data["press"]["crank_radius_mm"], data["press"]["rod_length_mm"], 0.0)
    height = 0.0 if seed % 2 else round(float(rng.uniform(0.001, 0.01)) * m.stroke, 3)
    hold_deg = math.degrees(float(m.bdc_angle) if height == 0 else float(m.angles_at_height(height)[0]))
    th2 = data["key_points"]["draw_start_deg"]
    data["key_points"]["draw_end_deg"] = round(th2 + 0.5 * (hold_deg - th2), 2)
    data["process"].pop("draw_speed_rpm", None)
    data["process"] |= {"hold_time_s": round(float(rng.uniform(0.05, 1.0)), 3), "hold_height_mm": height}
    if seed % 3 == 0:
        data["limits"]["crank_jerk_rad_s3"] = round(float(rng.uniform(5.0, 200.0)), 2)
    return data


@pytest.mark.slow  # twelve presses: the normal run keeps under 5 minutes
@pytest.mark.parametrize("seed", range(12))
def test_random_presses_with_a_hold_plan_it_or_say_why(seed):
    """Random crank-slider presses with a hold: a plan is verified and its re-sampled motion (every
    0.1 ms, the slide by the crank-slider's closed form from the crank angle) stands at the hold height for the
    hold time and keeps the slide's acceleration and die speed; or the solve says why, typed."""
    from planning.model.case_file import case_from_data
    from planning.solver.outcomes import PlanningError

    data = _with_hold(seed)
    case = case_from_data(data, f"hold-{seed}")
    try:
        solution = solve(case)
    except PlanningError as exc:
        assert str(exc), "a refusal says why"
        pytest.skip(f"no plan: {exc}")
    plan = solution.plan
    assert solution.verification.passed
    t = np.unique(np.concatenate([np.arange(0.0, plan.period, 1e-4), plan.profile.knot_times]))
    theta, omega, _ = plan.profile.at_time(t)[:3]
    R, L = case.press.crank_radius_mm, case.press.rod_length_mm
    h = R * (1 + np.cos(theta)) + L - np.sqrt(L**2 - (R * np.sin(theta)) ** 2)  # above BDC, theta from TDC
    still = (np.abs(h - case.process.hold_height_mm) <= STILL_MM) & (np.abs(omega) <= 1e-9)
    assert _longest_still_s(t, still) >= case.process.hold_time_s - 1e-6
    t = np.arange(0.0, plan.period, 1e-4)  # a uniform grid for the finite differences
    theta = plan.profile.at_time(t)[0]
    h = R * (1 + np.cos(theta)) + L - np.sqrt(L**2 - (R * np.sin(theta)) ** 2)
    v, a = np.gradient(h, t), np.gradient(np.gradient(h, t), t)
    inner = slice(2, -2)
    assert np.max(np.abs(a[inner])) <= case.limits.slider_accel_mm_s2 * (1 + 1e-2)
    below = h[inner] <= case.limits.die_height_mm
    assert np.max(np.abs(v[inner][below])) <= case.limits.die_speed_mm_s * (1 + 1e-3)


def test_a_draw_speed_the_crank_cannot_brake_from_is_refused_before_solving(tmp_path, capsys):
    """From 24 rpm to rest over the 8 deg from theta3 to BDC any motion needs |alpha| >= w^2 / (2 dtheta) =
    22.62 rad/s^2: a limit of 2 is refused before any NLP (exit 3), naming the limit and the number."""
    args = ["--set", "process.draw_speed_rpm=24", "--set", "limits.crank_accel_rad_s2=2"]
    assert main(["solve", str(COINING), *args, "--out", str(tmp_path / "o"), "--no-plots"]) == 3
    err = capsys.readouterr().err.strip()
    w = 24 * RPM
    needed = w**2 / (2 * math.radians(180 - 172))
    assert len(err.splitlines()) == 1 and "limits.crank_accel_rad_s2 = 2 cannot brake" in err
    assert f"{needed:.4g} rad/s^2" in err and needed == pytest.approx(22.62, abs=0.01)


def test_the_motor_holds_the_forming_force_through_the_crank_in_a_hold_above_bdc(tmp_path):
    """The cup press held 12 mm above BDC: at rest Lagrange's equation leaves T_c = -(F_form + F_cb - M g) h'
    (``press/dynamics.py``), with M the slide and the rod's slide-side share (m c / L), F_form the table at 12 mm
    and h' the crank-slider's closed-form slope: the written crank torque over the standstill is that."""
    cup = ROOT / "cases" / "cup-2000kN-drive.yaml"
    sets = ["process.hold_time_s=0.2", "process.hold_height_mm=12", "key_points.draw_end_deg=150"]
    out = tmp_path / "out"
    assert main(["solve", str(cup), *[a for s in sets for a in ("--set", s)], "--out", str(out), "--no-plots"]) == 0
    cols = _columns(out / "trajectory.csv")
    standing = np.abs(cols["crank_speed_rpm"]) <= 1e-9
    assert _longest_still_s(cols["time_s"], standing) >= 0.2 - 1.1e-3
    R, L = 0.125, 0.600  # [m]
    th = np.radians(cols["crank_angle_deg"][standing])
    slope = -R * np.sin(th) * (1 - R * np.cos(th) / np.sqrt(L**2 - (R * np.sin(th)) ** 2))  # dh/dtheta [m/rad]
    heights, forces = [0, 10, 12, 30, 60, 95, 100], [200, 200, 400, 650, 773, 450, 0]  # the case's table, ascending
    force = np.interp(1000 * (R * (1 + np.cos(th)) + L - np.sqrt(L**2 - (R * np.sin(th)) ** 2)), heights, forces)
    assert force == pytest.approx(400.0, rel=1e-6)
    M = 5000 + 400 * 0.240 / 0.600  # the slide and the rod's share at the slide [kg]
    expected = -(force * 1e3 + 45e3 - M * 9.80665) * slope
    np.testing.assert_allclose(cols["crank_torque_Nm"][standing], expected, rtol=1e-6)
    assert np.all(expected > 1e4)  # the motor holds the press open against the part: about 20 kN m at the crank


DATA = ROOT / "tests" / "data" / "cases"


def test_a_plan_with_a_hold_is_no_plan_of_a_case_without_one():
    """The coining plan (its crank stands 0.3 s) against the case without the hold fails the least crank
    speed (no stop was asked for), and against a 0.2 s hold it answers no neighbour's question."""
    from planning.solver.neighbour import can_answer

    plan = solved(COINING).plan
    data = json.loads(json.dumps(shipped(COINING).model_dump(exclude_none=True)))
    data["process"].pop("hold_time_s")
    data["process"].pop("hold_height_mm", None)
    from planning.model.case_file import case_from_data

    without = case_from_data(data, "no-hold")
    assert "min_crank_speed" in [c.id for c in evaluate(plan, without).verification.failures()]
    shorter = shipped(COINING, process__hold_time_s=0.2)
    assert not can_answer(plan, shorter, "free", (0.0, 1e3)) and can_answer(plan, shipped(COINING), "free", (0.0, 1e3))


def test_the_slide_entering_the_die_zone_while_braking_is_planned_there():
    """The draw ends above the die height, so the descending crossing lies in the brake to the hold at BDC: the
    die speed holds there (an outside trial's press, refused before the crossing was held in the brake)."""
    case = read_case(DATA / "hold-brake-in-die-zone.yaml")
    solution = solve(case)
    assert solution.verification.passed
    assert solution.verification.check("die_speed").value <= case.limits.die_speed_mm_s * (1 + 1e-6)


@pytest.mark.slow  # the certified bounds: about 10 s each
def test_with_robots_the_certified_bound_counts_the_standstill():
    """The robots' loop binds a press with a 1 s hold: the certified upper bound is at least the verified plan
    (it counts the standstill's time in the robots' rows and lets the crank stop; a code review found it 9 %
    below the plan before)."""
    from planning.solver.upper_bound import upper_bound

    case = read_case(DATA / "robots-hold.yaml")
    spm = solve(case).plan.spm
    assert upper_bound(case).spm >= spm * (1 - 1e-6)


def test_a_link_drive_with_a_hold_brakes_over_a_long_arc():
    """The link drive braking over 21 deg to its BDC (220.9 deg): a plan (its drive probe turned to the denser
    NLP, and the kinematic search took the probe's bounds: a traceback before)."""
    case = shipped(
        ROOT / "cases" / "link-drive-side-panel.yaml", process__hold_time_s=0.5, key_points__draw_end_deg=200
    )
    solution = solve(case)
    assert solution.verification.passed and solution.verification.check("hold").value == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize("law", ["cycloidal", "quintic"])
def test_a_cam_of_fewest_points_stands_still_in_the_hold(law):
    """A law that is no quintic in time takes the fewest XYVA points within 1 um; the standstill's ends are
    among them, so the cam's crank stands still there (before, its quintics spanned the standstill and moved)."""
    from planning.solver.cam_proof import CamSpec, cam_for

    case = shipped(COINING, law)
    proof = cam_for(solved(COINING, law=law).plan, case, CamSpec())
    assert proof.passed, proof.failure()
    assert proof.evaluation.verification.check("hold").value >= 0.3 - 1e-9


def test_the_highest_draw_speed_check_prints_can_be_typed_back(capsys):
    """Under 20 rad/s^2 the brake over 8 deg allows the improved S-curve sqrt(2 A dtheta / rate) with its rate
    18/11: check prints it as the highest draw speed, and solve takes it back."""
    sets = ["--set", "limits.crank_accel_rad_s2=20"]
    assert main(["check", str(COINING), *sets]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "highest draw speed" in x)
    highest = math.sqrt(2 * 20 * math.radians(8) / (18 / 11)) / RPM
    shown = line.split("allow: ")[1].split(" rpm")[0]
    assert float(shown) == pytest.approx(highest, abs=1e-4) and "braking to the hold" in line
    case = shipped(COINING, limits__crank_accel_rad_s2=20, process__draw_speed_rpm=float(shown))
    assert solve(case).verification.passed


def test_the_optimal_law_brakes_stands_and_rises_faster_than_a_law(tmp_path):
    """The optimal law plans the hold too (its brake to rest and its standstill phases of the free profile):
    in its written trajectory the slide, by the closed form from the written crank angle, stands within 1 um
    of BDC for at least 0.3 s; verified; more strokes than the improved S-curve's plan of the same case."""
    out = tmp_path / "out"
    assert main(["solve", str(COINING), "--law", "optimal", "--out", str(out), "--no-plots"]) == 0
    result = json.loads((out / "result.json").read_text())
    assert result["verified"] and result["motion_law"] == "optimal"
    cols = _columns(out / "trajectory.csv")
    theta = np.radians(cols["crank_angle_deg"])
    R, L = 50.0, 250.0
    h = R * (1 + np.cos(theta)) + L - np.sqrt(L**2 - (R * np.sin(theta)) ** 2)
    assert _longest_still_s(cols["time_s"], np.abs(h) <= STILL_MM) >= 0.3 - 1e-3  # the 1 ms grid's step
    assert result["hold"]["time_s"] == pytest.approx(0.3) and result["hold"]["angle_deg"] == pytest.approx(180.0)
    assert result["spm"] > solved(COINING).plan.spm * 1.1


def test_the_verification_fails_an_optimal_hold_cut_short():
    """The optimal law's plan with its standstill 5 ms short (the free profile's stand phase): the hold's check
    fails; the plan as solved passes."""
    from planning.model.plan import plan_of

    case = shipped(COINING, law="optimal")
    plan = solved(COINING, law="optimal").plan
    assert evaluate(plan, case).verification.passed
    values = {**plan.nlp_values, "stand_step": plan.nlp_values["stand_step"] - 0.005}
    cut = plan_of(case, values, "free", plan.solver, plan.parameters.layout)
    assert "hold" in [c.id for c in evaluate(cut, case).verification.failures()]


@pytest.mark.slow  # about a minute: the bracket's refinements
def test_the_bracket_of_a_hold_lies_between_the_optimal_hold_and_the_certified_bound(capsys):
    """``bound --bracket`` with a hold: the verified side the optimal law's plan with the hold, below the
    certified upper bound (which adds the hold's time and lets the crank stop at once: the gap is the stop's)."""
    assert main(["bound", str(COINING), "--bracket", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)["bracket"]
    assert data["verified_law"] == "optimal" and ["stand", 1] in data["verified_segments"]
    assert solved(COINING).plan.spm < data["verified_spm"] < data["upper_spm"]
