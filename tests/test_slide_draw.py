"""A draw at constant slide speed (issue 40; docs/modes.md): the optimal law plans the crank's speed through the
draw so that the slide moves at its set speed, until near BDC the crank's limits cap it.

Checked from the written trajectory with the crank-slider's own closed form (the slide's speed from the written
crank angle and speed), the cap angle of ``check`` against the closed form's, bad inputs, the bounds, a cam."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from planning.cli import main
from planning.solver.verify import evaluate

from .conftest import ROOT, shipped, solved

CUP = ROOT / "cases" / "cup-slide-speed-draw.yaml"
BAND = 1e-3  # the 0.1 %
RPM = 2 * math.pi / 60
R, L = 50.0, 250.0  # the case's crank radius and rod [mm]


def _slope(theta: np.ndarray) -> np.ndarray:
    """dh/dtheta [mm/rad] of the in-line crank-slider, h = R (1 + cos) + L - sqrt(L^2 - R^2 sin^2)."""
    return -R * np.sin(theta) * (1 - R * np.cos(theta) / np.sqrt(L**2 - (R * np.sin(theta)) ** 2))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("slide") / "out"
    assert main(["solve", str(CUP), "--out", str(out), "--no-plots"]) == 0
    return out


def test_the_slide_keeps_its_speed_over_the_draw_until_the_crank_caps_it(written):
    """trajectory.csv: the slide's speed, by the closed form from the written crank angle and speed, within 0.1 %
    of 60 mm/s over the stretch the summary states (more than half of the draw), never above it in the draw; the
    summary names the crank's limits that cap it in the rest of the draw."""
    with open(written / "trajectory.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    angle = np.array([float(r["crank_angle_deg"]) for r in rows])
    omega = np.array([float(r["crank_speed_rpm"]) for r in rows]) * RPM
    speed = np.abs(_slope(np.radians(angle)) * omega)
    result = json.loads((written / "result.json").read_text())
    held = result["draw_slide_speed"]
    assert result["verified"] and held["held_share_pct"] > 50
    inside = (angle >= held["held_from_deg"]) & (angle <= held["held_to_deg"])
    assert inside.sum() > 100 and np.all(np.abs(speed[inside] - 60.0) <= BAND * 60.0)
    drawing = (angle >= 140.0) & (angle <= 178.0)
    assert np.max(speed[drawing]) <= 60.0 * (1 + 1e-6)
    assert set(held["capped_by"]) & {"limits.crank_accel_rad_s2", "limits.crank_jerk_rad_s3", "limits.crank_speed_rpm"}
    summary = (written / "summary.txt").read_text()
    assert f"within 0.1 % from {held['held_from_deg']:.2f} to {held['held_to_deg']:.2f} deg" in summary
    assert "cap it" in summary


def test_the_verification_fails_a_plan_past_the_set_speed():
    """The plan against the same case with the set speed 0.5 % lower: the slide is too fast in the draw."""
    plan = solved(CUP).plan
    slower = shipped(CUP, process__draw_slide_speed_mm_s=60.0 * 0.995)
    assert "draw_slide_speed" in [c.id for c in evaluate(plan, slower).verification.failures()]
    assert evaluate(plan, shipped(CUP)).verification.passed


def test_check_names_the_angle_from_which_the_crank_is_too_slow_for_the_slide(capsys):
    """``check``: the crank speed the slide's speed asks, 60 / |h'(theta)| mm/s, passes the crank's top speed
    (60 rpm) where the closed form says (bisection here), within the check's grid."""
    assert main(["check", str(CUP), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    lo, hi = math.radians(140.0), math.radians(178.0)
    for _ in range(60):  # v / |h'| rises towards BDC
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if 60.0 / abs(_slope(np.array(mid))) < 60 * RPM else (lo, mid)
    assert report["slide_draw"]["capped_from_deg"] == pytest.approx(math.degrees(lo), abs=0.5)
    assert report["slide_draw"]["crank_at_draw_start_rpm"] == pytest.approx(
        60.0 / abs(_slope(np.array(math.radians(140.0)))) / RPM, rel=1e-9
    )


@pytest.mark.parametrize(
    ("fields", "says"),
    [
        ({"planner.motion_law": "improved-s-curve"}, "planner.motion_law: a draw at constant slide speed is planned"),
        ({"process.draw_speed_rpm": 20.0}, "process.draw_speed_rpm: and process.draw_slide_speed_mm_s ask for two"),
        ({"process.draw_slide_speed_mm_s": 0.0}, "process.draw_slide_speed_mm_s: input should be greater"),
    ],
)
def test_a_slide_speed_draw_that_cannot_be_is_one_line_naming_the_field(fields, says, tmp_path, capsys):
    import yaml

    data = yaml.safe_load(CUP.read_text())
    for key, value in fields.items():
        section, name = key.split(".")
        data[section][name] = value
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["solve", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(path) in err and says in err, err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow  # the bounds: about 7 s
def test_the_bounds_stay_above_the_plan_and_the_cam_is_proved(tmp_path):
    """The grid bound (the slide's cap at the draw's nodes, no constant draw speed) and the certified bound
    (which leaves the cap out: looser, still an upper bound) above the verified plan; its cam proved."""
    from planning.solver.bound import time_optimal_bound
    from planning.solver.upper_bound import upper_bound

    spm = solved(CUP).plan.spm
    grid, upper = time_optimal_bound(shipped(CUP)), upper_bound(shipped(CUP))
    assert upper.spm >= grid.spm >= spm and "process.draw_slide_speed_mm_s" in upper.left_out
    assert main(["cam", str(CUP), "--out", str(tmp_path / "cam"), "--cam", "codesys"]) == 0


def test_a_draw_past_bdc_holds_its_speed_to_its_end(tmp_path):
    """A draw to 200 deg at 30 mm/s (an outside review found the slide 0.68 % too fast at theta3, verified): the
    slide's speed at theta3 within the set speed, and the stretch before BDC held within 0.1 % (the cap no
    longer lowered for the whole draw by a miss at its end)."""
    out = tmp_path / "out"
    assert main(["solve", str(ROOT / "tests" / "data" / "cases" / "slide-past-bdc.yaml"), "--out", str(out)]) == 0
    result = json.loads((out / "result.json").read_text())
    end = next(k for k in result["key_points"] if k["name"] == "draw_end")
    assert result["verified"] and end["slider_speed_mm_s"] <= 30.0 * (1 + 1e-6)
    held = result["draw_slide_speed"]
    assert held["held_to_deg"] < 180.0 and held["held_share_pct"] > 30


def test_a_slide_speed_below_what_the_least_crank_speed_gives_is_refused_before_solving(tmp_path, capsys):
    """At 5 rpm (the least crank speed) the slide moves 19.43 mm/s at theta2 (|h'| largest in the draw): 10 mm/s
    is refused before any NLP (exit 3), naming the field and that speed."""
    args = ["--set", "process.draw_slide_speed_mm_s=10", "--out", str(tmp_path / "o"), "--no-plots"]
    assert main(["solve", str(CUP), *args]) == 3
    err = capsys.readouterr().err.strip()
    slowest = 5 * RPM * abs(float(_slope(np.array(math.radians(140.0)))))
    assert "process.draw_slide_speed_mm_s = 10 is below" in err and f"{slowest:.4g} mm/s" in err


DRIVE_CUP = ROOT / "tests" / "data" / "cases" / "cup-slide-speed-drive.yaml"


def test_a_free_draws_forming_force_is_the_cases_at_its_samples():
    """With a drive the optimal law's draw samples move with the profile: the NLP reads the forming force at each
    from the case's force at the draw's fixed angles. At those angles it is the force of ``press.dynamics``
    (the case's table by the slide's height) to round-off; halfway between two of them it is their mean (linear in
    the share of the draw's angle); before the draw it is zero."""
    import casadi as ca

    from planning.solver.free_nlp import _free_draw_forming
    from planning.solver.nlp import nlp_limits
    from planning.solver.parameters import FORMING_SAMPLES, ParameterLayout
    from press.dynamics import forming_force

    case = shipped(DRIVE_CUP)
    layout = ParameterLayout(case.machine.formula, nlp_limits(case, True), True, False, ())
    p = ca.DM(layout.values(case))
    th2, th3 = (float(a) for a in case.key_angles[1:3])
    grid = np.linspace(th2, th3, FORMING_SAMPLES)
    between = 0.5 * (grid[:-1] + grid[1:])
    for angles in (grid, between):
        turned = np.concatenate([[0.3, 1.0, th2], angles]) + 2 * math.pi  # the free draw's angles are a turn on
        force = np.array(ca.evalf(_free_draw_forming(ca.DM(turned), angles.size + 1, layout, p, layout.symbols(p))))
        force = force.ravel()
        assert np.all(force[:2] == 0.0)
        exact = forming_force(angles, case.machine.height(angles), case.drive_model)
        if angles is grid:
            assert np.allclose(force[3:], exact, rtol=1e-12, atol=1e-6)
        else:
            at_grid = forming_force(grid, case.machine.height(grid), case.drive_model)
            assert np.allclose(force[3:], 0.5 * (at_grid[:-1] + at_grid[1:]), rtol=1e-12, atol=1e-6)


@pytest.mark.slow  # a solve of the optimal law with the drive's rows: about 7 s
def test_a_slide_speed_draw_with_a_drive_holds_its_speed_and_the_motor_limits_it(tmp_path):
    """The 2000 kN cup drawn at 300 mm/s with its drive: verified (the motor's checks and the energy balance on the
    case's own forming force), the motor's RMS torque binds, the slide's speed (the crank-slider's closed form from
    trajectory.csv) within 0.1 % of 300 mm/s over the stretch the summary states; the plan against the same press
    with 1 % less rated torque fails the motor's RMS torque only."""
    out = tmp_path / "out"
    assert main(["solve", str(DRIVE_CUP), "--out", str(out), "--no-plots"]) == 0
    result = json.loads((out / "result.json").read_text())
    assert result["verified"] and "motor RMS torque" in result["binding_constraints"], result["binding_constraints"]
    with open(out / "trajectory.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    theta = np.radians([float(r["crank_angle_deg"]) for r in rows])
    omega = np.array([float(r["crank_speed_rpm"]) for r in rows]) * RPM
    r, rod = 125.0, 600.0
    slope = -r * np.sin(theta) * (1 - r * np.cos(theta) / np.sqrt(rod**2 - (r * np.sin(theta)) ** 2))
    speed = np.abs(slope * omega)
    held = result["draw_slide_speed"]
    inside = (np.degrees(theta) >= held["held_from_deg"]) & (np.degrees(theta) <= held["held_to_deg"])
    assert held["held_share_pct"] > 30 and inside.sum() > 50
    assert np.all(np.abs(speed[inside] - 300.0) <= BAND * 300.0)
    plan = solved(DRIVE_CUP).plan
    weaker = shipped(DRIVE_CUP, drive__motor__rated_torque_Nm=3600 * 0.99)
    assert [c.id for c in evaluate(plan, weaker).verification.failures()] == ["motor_rms_torque"]


@pytest.mark.slow  # two solves of the optimal law: about 20 s
def test_a_plan_the_motor_can_drive_is_not_lost_to_the_drive_nlp():
    """The motor's limits only take plans away: at 400 mm/s the same press without its drive plans a cycle the
    motor can drive (its plan passes the drive case's verification); the drive case's answer makes at least as
    many strokes (an outside trial found 45.143 against that plan's 47.351 before the optimal law tried the
    kinematic optimum)."""
    import yaml

    from planning.model.case_file import case_from_data
    from planning.solver.optimize import solve

    drive = shipped(DRIVE_CUP, process__draw_slide_speed_mm_s=400.0)
    data = yaml.safe_load(DRIVE_CUP.read_text())
    del data["drive"]
    data["process"]["draw_slide_speed_mm_s"] = 400.0
    kinematic = solve(case_from_data(data))
    assert evaluate(kinematic.plan, drive).verification.passed
    answer = solve(drive)
    assert answer.verification.passed and answer.plan.spm >= kinematic.plan.spm * (1 - 1e-9)


@pytest.mark.slow  # the optimal law's NLP with the robots' rows: about 40 s
def test_robots_on_their_curves_with_a_slide_speed_draw(tmp_path):
    """``robots:`` with a draw at constant slide speed: the cup tended by an unloader and a loader on their
    interference curves, planned and verified (each clearance on the dense grid and at the curves' crossings),
    the slide's speed held over most of the draw as without robots."""
    import yaml

    data = yaml.safe_load(CUP.read_text())
    for field in ("safety_height_mm", "transfer_time_s"):
        data["process"].pop(field)
    tool = {"path_mm": 600, "speed_mm_s": 3000, "accel_mm_s2": 25000, "dwell_s": 0.06}
    data["robots"] = {"order": "overlapping"}
    for role in ("unloader", "loader"):  # (no YAML aliases: a case file refuses them)
        data["robots"][role] = {**tool, "interference_mm": [[0, 75], [250, 75], [350, 0]]}
    path = tmp_path / "robots.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["solve", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["verified"] and result["draw_slide_speed"]["held_share_pct"] > 50
    checks = {c["name"]: c for c in result["verification"]["checks"] if c["id"] == "robots"}
    assert checks and all(c["passed"] for c in checks.values())


def test_a_slide_speed_draw_then_a_hold(tmp_path):
    """A draw at constant slide speed to theta3, then the brake and a 0.3 s hold at BDC (the optimal law's
    layout with both): verified, the slide's speed held over more than half the draw, the hold's check met."""
    sets = ["process.hold_time_s=0.3", "process.hold_height_mm=0", "key_points.draw_end_deg=176"]
    out = tmp_path / "out"
    assert main(["solve", str(CUP), *[a for s in sets for a in ("--set", s)], "--out", str(out), "--no-plots"]) == 0
    result = json.loads((out / "result.json").read_text())
    assert result["verified"] and result["draw_slide_speed"]["held_share_pct"] > 50
    hold = next(c for c in result["verification"]["checks"] if c["id"] == "hold")
    assert hold["passed"] and hold["value"] == pytest.approx(0.3, abs=1e-9)


def test_what_caps_the_draw_names_the_motor_where_its_torque_meets_its_envelope():
    """``capping``: the limits within 0.1 % of their value in the draw outside the stretch held; with a drive the
    motor's torque against its envelope (``peak x base / speed`` above the base speed) and its top speed. On a
    made-up dense grid: the torque at 99.95 % of the envelope above the base speed inside the spans is named, at
    99.8 % it is not, and outside the spans never."""
    from types import SimpleNamespace

    from planning.reports.report import capping

    case = shipped(DRIVE_CUP)
    motor = case.drive.motor
    t = np.linspace(0.0, 1.0, 101)
    speed = np.full(t.size, 1.5 * motor.base_speed_rpm * RPM)  # above the base speed: the envelope is peak / 1.5
    zeros = np.zeros(t.size)

    def dense(share: float, at: int) -> SimpleNamespace:
        torque = zeros.copy()
        torque[at] = share * motor.peak_torque_Nm / 1.5
        state = {"motor_speed_rad_s": speed, "motor_torque_Nm": torque}
        return SimpleNamespace(t=t, omega=zeros, alpha=zeros, jerk=zeros, a=zeros, h=zeros + 50.0, v=zeros,
                               drive_state=state)

    spans = [(0.0, 0.2), (0.6, 1.0)]
    assert capping(dense(0.9995, 10), case, spans) == ["drive.motor.peak_torque_Nm"]
    assert capping(dense(0.998, 10), case, spans) == []
    assert capping(dense(0.9995, 40), case, spans) == []


def test_check_lets_a_slide_enter_a_draw_faster_than_its_start_limit_at_that_limit(capsys):
    """A set slide speed above ``limits.draw_start_speed_mm_s``: the slide enters the draw at that limit and speeds
    up (the plan does: an outside trial's 400 mm/s cup planned verified while ``check`` printed a FAIL); ``check``
    passes the draw start at the limit, says so, and gives the crank's speed at theta2 for it, ``350 / |h'|``."""
    assert main(["check", str(DRIVE_CUP), "--set", "process.draw_slide_speed_mm_s=400"]) == 0
    out = capsys.readouterr().out
    assert "PASS  slider speed at draw start <= limits.draw_start_speed_mm_s: 350.0 mm/s" in out
    assert "draw at 400 mm/s slide speed (the slide enters at the draw-start limit, 350 mm/s, and speeds up" in out
    case = shipped(DRIVE_CUP)
    slope = abs(float(case.machine.derivatives(case.key_angles[1])[0]))
    assert f"the crank at {350 / slope / RPM:.3f} rpm at theta2" in out


@pytest.mark.slow  # three solves of the optimal law with a drive: about 20 s
def test_at_a_rate_the_slide_keeps_its_set_speed_and_the_motor_saves(tmp_path):
    """A draw at constant slide speed at 35 strokes/min for the least RMS torque (the drive case, 45.0 at most):
    verified, the RMS torque below the baseline's, and the slide at its set speed over at least as much of the
    draw as at the most strokes (the draw's time weighed first: the heat is saved elsewhere, not in the draw)."""
    case = ROOT / "tests" / "data" / "cases" / "cup-slide-speed-drive.yaml"
    out = tmp_path / "out"
    at_rate = ["--objective", "min-rms-torque", "--spm", "35"]
    assert main(["solve", str(case), *at_rate, "--out", str(out), "--no-plots"]) == 0
    result = json.loads((out / "result.json").read_text())
    fastest = json.loads((_fastest_result(case, tmp_path)).read_text())
    assert result["verified"] and result["spm"] == pytest.approx(35.0, rel=1e-9)
    assert result["drive"]["rms_motor_torque_Nm"] < 0.9 * result["baseline"]["rms_motor_torque_Nm"]
    held, held_fastest = result["draw_slide_speed"], fastest["draw_slide_speed"]
    assert held["held_share_pct"] >= held_fastest["held_share_pct"] - 1.0 and held["capped_by"]


def _fastest_result(case, tmp_path):  # noqa: ANN001, ANN202
    assert main(["solve", str(case), "--out", str(tmp_path / "fastest"), "--no-plots"]) == 0
    return tmp_path / "fastest" / "result.json"


def test_compare_of_a_slide_speed_draw_says_the_paper_draws_at_a_crank_speed(tmp_path, capsys):
    """``compare`` sets the paper's plan beside ours: its draw is at one crank speed, so a case drawing at a slide
    speed is refused in one line naming the field (exit 2), nothing written."""
    import yaml

    data = yaml.safe_load((ROOT / "cases" / "wang2023-side-panel.yaml").read_text())
    data["process"].pop("draw_speed_rpm")
    data["process"]["draw_slide_speed_mm_s"] = 150
    data["planner"] = {"motion_law": "optimal"}
    data["limits"]["crank_jerk_rad_s3"] = 20
    path = tmp_path / "slide.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["compare", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"pressplan: {path}: process.draw_slide_speed_mm_s: the published solution draws at")
    assert len(err.splitlines()) == 1 and not (tmp_path / "out").exists()
