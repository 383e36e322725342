"""The press line (issue 43; docs/line.md): ``pressplan line`` on small lines (fast) and the shipped tandem
line (slow), its rate against each press alone, the bottleneck named, and the written offsets and robot
timings replayed by a check of this file's own (the slide from the crank angle by the crank-slider's closed
form, each robot's trapezoid move from its written start, the interference curves by ``np.interp``), not the
planner's verification."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from planning.cli import main

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).parent / "data" / "line"
SHIPPED = ROOT / "cases" / "tandem-line" / "line.yaml"
REPLAY_TOL_MM = 1e-3  # [mm] the replayed clearance may dip this far below 0 (the samples' round-off)
REPLAY_TOL_S = 1e-6  # [s] a robot's gap between two presses may fall this short of its transfer move


def _run(line: Path, out: Path, *more: str) -> dict:
    code = main(["line", str(line), "--out", str(out), "--no-plots", *more])
    assert code == 0
    return json.loads((out / "line_result.json").read_text())


@pytest.fixture(scope="module")
def fast(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    """The fast line through the Python API (the slow one through the CLI)."""
    from planning import read_line, solve_line, write_line_outputs

    out = tmp_path_factory.mktemp("fast")
    write_line_outputs(solve_line(read_line(DATA / "fast.yaml")), out, figures=False)
    return json.loads((out / "line_result.json").read_text()), out


@pytest.fixture(scope="module")
def slow(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    out = tmp_path_factory.mktemp("slow")
    return _run(DATA / "slow.yaml", out), out
@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes


def test_fast_transfers_leave_the_line_at_its_slowest_press(fast: tuple[dict, Path]) -> None:
    result, _ = fast
    alone = [s["spm_alone"] for s in result["stations"]]
    assert result["status"] == "verified"
    assert result["spm"] == pytest.approx(min(alone), rel=1e-9)
    assert result["bottleneck"]["kind"] == "press"
    assert result["bottleneck"]["name"] == result["stations"][int(np.argmin(alone))]["name"]
@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes


def test_a_slow_transfer_binds_the_line_and_the_summary_names_it(slow: tuple[dict, Path]) -> None:
    result, out = slow
    assert result["status"] == "verified"
    assert all(result["spm"] < s["spm_alone"] for s in result["stations"])
    assert result["bottleneck"] == {**result["bottleneck"], "kind": "robot", "name": "first->second"}
    robot = next(r for r in result["robots"] if r["name"] == "first->second")
    occupancy = 2 * _trapezoid_time(400, 3000, 30000) + 0.05  # each press's robot: in, dwell, out
    assert robot["loop_s"] == pytest.approx(2 * occupancy + 2 * 2.0, rel=1e-12)
    assert result["period_s"] == pytest.approx(robot["loop_s"], rel=1e-12)
    summary = (out / "line_summary.txt").read_text()
    loop = "unload first 0.517 + to second 2.000 + load second 0.517"
    assert f"bottleneck: robot first->second's loop = {loop}" in summary


@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes
@pytest.mark.parametrize("name", ["fast", "slow"])
def test_written_timings_replayed_hold_every_clearance(name: str, request: pytest.FixtureRequest) -> None:
    result, out = request.getfixturevalue(name)
    clearance, gap, both = _replay(result, out, DATA / f"{name}.yaml")
    assert clearance >= -REPLAY_TOL_MM
    assert gap >= -REPLAY_TOL_S
    assert not both
@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes


def test_the_replay_finds_a_loader_started_late(fast: tuple[dict, Path]) -> None:
    """The replay can fail: the bottleneck press's loader 20 ms late meets the slide coming down."""
    result, out = fast
    moved = json.loads(json.dumps(result))
    moved["stations"][0]["robot_starts_s"]["loader"] += 0.02
    clearance, _, _ = _replay(moved, out, DATA / "fast.yaml")
    assert clearance < -1.0
@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes


def test_the_replay_finds_a_press_shifted_on_the_master(slow: tuple[dict, Path]) -> None:
    """The replay can fail: the second press (and its robots) 50 ms late leaves the slow transfer no time."""
    result, out = slow
    moved = json.loads(json.dumps(result))
    for role in ("unloader", "loader"):
        moved["stations"][1]["robot_starts_s"][role] += 0.05
    _, gap, _ = _replay(moved, out, DATA / "slow.yaml")
    assert gap < -0.01
@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes


def test_the_line_verification_fails_a_press_off_its_offset(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """The line's own checks can fail: with the slow transfer binding (no spare time), the second press 50 ms
    off its offset leaves the robot less than its transfer move: unverified, exit 3, naming the robot's wait."""
    from planning.model import line as model

    offsets = model.phase_offsets_s
    monkeypatch.setattr("planning.solver.line.phase_offsets_s", lambda *a: offsets(*a) + np.array([0.0, 0.05]))
    assert main(["line", str(DATA / "slow.yaml"), "--out", str(tmp_path), "--no-plots"]) == 3
    assert "unverified" in (err := capsys.readouterr().err) and "first->second: wait" in err, err
    assert not (tmp_path / "line_result.json").exists()


A = str(DATA / "press_a.yaml")
B = str(DATA / "press_b.yaml")
GOOD = {
    "name": "bad",
    "stations": [{"name": "first", "case": A}, {"name": "second", "case": B}],
    "transfers": [{"unloads": "first", "loads": "second", "time_s": 0.1}],
}
BAD_LINES = [  # (what changes in GOOD, the field the line names, words of the problem)
    (
        {"stations": [{"name": "first", "case": A}, {"name": "second", "case": "nowhere.yaml"}]},
        "stations.1.case",
        "no such file",
    ),
    (
        {"transfers": [{"unloads": "second", "loads": "first", "time_s": 0.1}]},
        "transfers.0.loads",
        "not the station after",
    ),
    ({"transfers": []}, "transfers", "none unloads 'first'"),
    ({"transfers": [{"unloads": "first", "loads": "third", "time_s": 0.1}]}, "transfers.0.loads", "no station 'third'"),
    (
        {"transfers": [{"unloads": "first", "loads": "second", "time_s": 1, "path_mm": 100}]},
        "transfers.0.path_mm",
        "not both",
    ),
    ({"transfers": [{"unloads": "first", "loads": "second", "path_mm": 100}]}, "transfers.0.speed_mm_s", "missing"),
    (
        {"stations": [{"name": "first", "case": A}, {"name": "first", "case": B}]},
        "stations.1.name",
        "names two stations",
    ),
    ({"stations": [{"name": "first", "case": A}]}, "stations", "at least 2"),
    ({"feeder": {"time_s": -1}}, "feeder.time_s", "greater than or equal to 0"),
    ({"transfer": []}, "transfer", "did you mean 'transfers'"),
    (
        {"stations": [{"name": "first", "case": A}, {"name": "second", "case": str(DATA / "loader_only.yaml")}]},
        "stations.1.case (second)",
        "has no robots.unloader",
    ),
    (
        {
            "stations": [
                {"name": "first", "case": A},
                {"name": "second", "case": str(ROOT / "cases" / "wang2023-side-panel.yaml")},
            ]
        },
        "stations.1.case (second)",
        "has no robots: section",
    ),
    (
        {"stations": [{"name": "first", "case": A}, {"name": "second", "case": str(DATA / "broken.yaml")}]},
        "stations.1.case (second)",
        "broken.yaml: limits.slider_accel_mm_s2: input should be a valid number",
    ),
    ({"stations": [{"name": "first", "case": A}, {"name": "second", "case": "."}]}, "stations.1.case", "not a file"),
    ({"stations": [{"name": "first", "case": A}, {"name": "exit", "case": B}]}, "stations.1.name", "a line file's key"),
    ({"transfers": [{"unloads": "first", "loads": "second", "time_s": 0}]}, "transfers.0.time_s", "greater than 0"),
    ({"stations": 5}, "stations", "valid list"),
    ({"stations": [{"name": "op.10", "case": A}, {"name": "second", "case": B}]}, "stations.0.name", "pattern"),
]


@pytest.mark.parametrize(("change", "field", "words"), BAD_LINES, ids=[b[1] + ":" + b[2] for b in BAD_LINES])
def test_a_bad_line_file_is_one_line_naming_the_field(
    change: dict, field: str, words: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    path = tmp_path / "line.yaml"
    path.write_text(yaml.safe_dump({**GOOD, **change}))
    assert main(["line", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and str(path) in err and f"{field}:" in err and words in err, err
    assert not (tmp_path / "out").exists()


def test_a_line_slower_than_a_press_can_turn_is_infeasible_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """A transfer of 10 s asks a 20 s cycle of a press whose minimum crank speed allows 12 s: exit 3."""
    case = yaml.safe_load((DATA / "press_b.yaml").read_text())
    case["limits"]["min_crank_speed_rpm"] = 5
    (tmp_path / "turning.yaml").write_text(yaml.safe_dump(case))
    line = {**GOOD, "stations": [{"name": "first", "case": A}, {"name": "second", "case": "turning.yaml"}]}
    line["transfers"] = [{"unloads": "first", "loads": "second", "time_s": 10.0}]
    path = tmp_path / "line.yaml"
    path.write_text(yaml.safe_dump(line))
    assert main(["line", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 3
    err = capsys.readouterr().err
    assert "robot first->second" in err and "station second" in err and "min_crank_speed_rpm" in err, err
@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes


def test_a_sweep_over_a_transfer_speed(tmp_path: Path) -> None:
    """A slow transfer binds the line, a fast one leaves it to the first press; each row a verified line."""
    args = ["line", str(DATA / "fast.yaml"), "--out", str(tmp_path), "--workers", "1"]
    assert main([*args, "--vary", "transfers.0.speed_mm_s=1000:6000:2"]) == 0
    rows = list(csv.DictReader((tmp_path / "line_sweep.csv").open()))
    assert [r["status"] for r in rows] == ["verified", "verified"]
    assert rows[0]["bottleneck"] == "robot first->second" and rows[1]["bottleneck"] == "press first"
    assert float(rows[0]["spm"]) < float(rows[1]["spm"])
    assert (tmp_path / "line_sweep.png").is_file()


@pytest.mark.parametrize(
    ("option", "words"),
    [
        (["--vary", "transfers.0.sped_mm_s=1:2:2"], "did you mean 'transfers.0.speed_mm_s'"),
        (["--set", "transfers.3.speed_mm_s=100"], "transfers.3.speed_mm_s: no 3 there"),
        (["--set", "second.limits.die_height_mm=-1"], "limits.die_height_mm"),
        (["--set", "third.limits.die_height_mm=1"], "neither a line field nor a station's case field"),
        (
            ["--set", "transfers.0.time_s=1"],
            "transfers.0.path_mm: give time_s or the path and its limits, not both (from --set)",
        ),
        (
            ["--vary", "feeder.time_s=-1:1:3"],
            "feeder.time_s: input should be greater than or equal to 0 (got -1.0) (from --vary",
        ),
    ],
)
def test_a_bad_set_or_vary_is_one_line(
    option: list[str], words: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    assert main(["line", str(DATA / "fast.yaml"), "--out", str(tmp_path / "out"), *option]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and words in err, err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_a_station_field_set_for_a_run_slows_the_line(tmp_path: Path, fast: tuple[dict, Path]) -> None:
    """The first press's slide acceleration halved: it alone is slower, and so is the line, still at it."""
    result = _run(DATA / "fast.yaml", tmp_path, "--set", "first.limits.slider_accel_mm_s2=10000")
    assert result["spm"] < fast[0]["spm"]
    assert result["spm"] == pytest.approx(min(s["spm_alone"] for s in result["stations"]), rel=1e-9)


@pytest.mark.slow
def test_a_press_with_its_drive_runs_at_the_lines_period(tmp_path: Path) -> None:
    """A slow transfer sets the line's cycle; the press with its drive (and an objective at a rate, not read in a
    line) runs at it through the drive's NLP, verified; the replay's gaps hold."""
    result = _run(DATA / "drive.yaml", tmp_path)
    assert result["bottleneck"]["kind"] == "robot"
    cup = next(s for s in result["stations"] if s["name"] == "cup")
    assert cup["verified"] and cup["spm_alone"] > result["spm"]
    _, gap, both = _replay(result, tmp_path, DATA / "drive.yaml")
    assert gap >= -REPLAY_TOL_S and not both


@pytest.mark.slow
def test_the_shipped_tandem_line(tmp_path: Path) -> None:
    """Four presses (crank-slider, link drive, offset crank), verified; the line at most its slowest press
    alone, equal to it here (the transfers do not couple the presses); the timings replayed."""
    result = _run(SHIPPED, tmp_path)
    alone = [s["spm_alone"] for s in result["stations"]]
    assert len(alone) == 4 and {s["mechanism"] for s in result["stations"]} == {"crank-slider", "link-drive"}
    assert result["spm"] == pytest.approx(min(alone), rel=1e-9)
    clearance, gap, both = _replay(result, tmp_path, SHIPPED)
    assert clearance >= -REPLAY_TOL_MM and gap >= -REPLAY_TOL_S and not both


def _trapezoid_time(length: float, speed: float, accel: float) -> float:
    if length >= speed * speed / accel:
        return length / speed + speed / accel
    return 2 * math.sqrt(length / accel)


def _travelled(tau: np.ndarray, length: float, speed: float, accel: float) -> np.ndarray:
    """Distance along a rest-to-rest trapezoid (or triangle) move at times ``tau`` from its start."""
    top = min(speed, math.sqrt(length * accel))
    ramp = top / accel
    total = _trapezoid_time(length, speed, accel)
    t = np.clip(tau, 0.0, total)
    up = 0.5 * accel * np.minimum(t, ramp) ** 2
    cruise = top * np.clip(t - ramp, 0.0, total - 2 * ramp)
    down_t = np.clip(t - (total - ramp), 0.0, ramp)
    down = top * down_t - 0.5 * accel * down_t**2
    return up + cruise + down


def _position(robot: dict, t: np.ndarray, start: float, period: float) -> np.ndarray:
    """The robot's distance from the die centre at line times ``t``: in, dwell, out from ``start``, then waiting."""
    length, speed, accel = robot["path_mm"], robot["speed_mm_s"], robot["accel_mm_s2"]
    assert robot.get("jerk_mm_s3") is None  # the replay's moves are trapezoids
    move = _trapezoid_time(length, speed, accel)
    tau = np.mod(t - start, period)
    inward = length - _travelled(tau, length, speed, accel)
    outward = _travelled(tau - move - robot.get("dwell_s", 0.0), length, speed, accel)
    return np.where(tau < move + robot.get("dwell_s", 0.0), inward, outward)


def _slide(case: dict, crank_deg: np.ndarray, path: Path) -> np.ndarray:
    """The slide's height above BDC: an in-line crank-slider's closed form; other presses by their mechanism."""
    press = case["press"]
    if press.get("mechanism", "crank-slider") == "crank-slider" and not press.get("offset_mm"):
        r, rod = press["crank_radius_mm"], press["rod_length_mm"]
        th = np.radians(crank_deg)
        return r * (1 + np.cos(th)) + rod - np.sqrt(rod**2 - (r * np.sin(th)) ** 2)  # the slide hangs below
    from planning.model.case_file import read_case  # an offset crank or a linkage: its geometry's own model

    return read_case(path).machine.height(np.radians(crank_deg))


def _replay(result: dict, out: Path, line_file: Path) -> tuple[float, float, bool]:
    """``(least clearance [mm], least gap [s] between a robot's stay in one press and the next beyond its
    transfer move, whether a robot is ever inside two presses at once)`` from the written files alone."""
    table = np.genfromtxt(out / "line_trajectory.csv", delimiter=",", names=True)
    line = yaml.safe_load(line_file.read_text())
    period, t = result["period_s"], table["time_s"]
    inside: dict[str, list[np.ndarray]] = {}
    least = math.inf
    for station, entry in zip(result["stations"], line["stations"], strict=True):
        case_path = line_file.parent / entry["case"]
        case = yaml.safe_load(case_path.read_text())
        slide = _slide(case, table[f"{station['name']}_crank_angle_deg"], case_path)
        needs = []
        for role in ("unloader", "loader"):
            robot = case["robots"][role]
            x = _position(robot, t, station["robot_starts_s"][role], period)
            curve = np.array(robot["interference_mm"], dtype=float)
            needs.append(np.interp(x, curve[:, 0], curve[:, 1], right=0.0))
            name = _robot_of(result, station["name"], role)
            inside.setdefault(name, []).append(x < robot["path_mm"] - REPLAY_TOL_MM)
        least = min(least, float(np.min(slide - np.max(needs, axis=0))))
    both = any(np.any(np.logical_and(*flags)) for flags in inside.values() if len(flags) == 2)
    return least, _least_gap(result, line, line_file), both


def _robot_of(result: dict, station: str, role: str) -> str:
    key = "unloads" if role == "unloader" else "loads"
    return next(r["name"] for r in result["robots"] if r[key] == station)


def _least_gap(result: dict, line: dict, line_file: Path) -> float:
    """Each transfer robot: from leaving one press to entering the next and back, less its move each way."""
    period, least = result["period_s"], math.inf
    by_name = {s["name"]: s for s in result["stations"]}
    cases = {
        s["name"]: yaml.safe_load((line_file.parent / e["case"]).read_text())
        for s, e in zip(result["stations"], line["stations"], strict=True)
    }
    for transfer in line.get("transfers", []):
        first, second = by_name[transfer["unloads"]], by_name[transfer["loads"]]
        unloader = cases[first["name"]]["robots"]["unloader"]
        loader = cases[second["name"]]["robots"]["loader"]
        occupancy = {
            k: 2 * _trapezoid_time(r["path_mm"], r["speed_mm_s"], r["accel_mm_s2"]) + r.get("dwell_s", 0.0)
            for k, r in (("u", unloader), ("l", loader))
        }
        move = transfer.get("time_s")
        if move is None:
            move = _trapezoid_time(transfer["path_mm"], transfer["speed_mm_s"], transfer["accel_mm_s2"])
        left = first["robot_starts_s"]["unloader"] + occupancy["u"]
        enters = second["robot_starts_s"]["loader"]
        there = np.mod(enters - left, period)
        back = period - occupancy["u"] - there - occupancy["l"]
        least = min(least, there - move, back - move)
    return least
@pytest.mark.slow  # a line solve: about 7 s


def test_a_press_with_a_hold_keeps_it_at_the_lines_period(tmp_path: Path) -> None:
    """The slow line with a 0.2 s hold at BDC on its first press (docs/modes.md): the press runs at the line's
    period (the robot's loop, far slower than it alone) and its slide, by the crank-slider's closed form from
    the written crank angle, stands within 1 um of BDC for at least 0.2 s on end."""
    sets = ["first.process.hold_time_s=0.2", "first.key_points.draw_end_deg=172"]
    result = _run(DATA / "slow.yaml", tmp_path / "out", *[a for s in sets for a in ("--set", s)])
    assert result["status"] == "verified" and result["bottleneck"]["kind"] == "robot"
    with open(tmp_path / "out" / "line_trajectory.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    t = np.array([float(r["time_s"]) for r in rows])
    theta = np.radians([float(r["first_crank_angle_deg"]) for r in rows])
    R, L = 50.0, 250.0  # tests/data/line/press_a.yaml
    h = R * (1 + np.cos(theta)) + L - np.sqrt(L**2 - (R * np.sin(theta)) ** 2)
    still = np.abs(h) <= 1e-3
    runs = np.split(t[still], np.flatnonzero(np.diff(np.flatnonzero(still)) > 1) + 1)
    assert max(run[-1] - run[0] for run in runs if run.size) >= 0.2 - 1e-3  # the 1 ms grid's last step


@pytest.fixture(scope="module")
def swinging(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    """The slow line with its second press in pendulum strokes (docs/line.md)."""
    out = tmp_path_factory.mktemp("swinging")
    return _run(DATA / "slow.yaml", out, "--set", "second.planner.mode=pendulum"), out
@pytest.mark.slow  # a line with a swinging press: about 10 s


def test_a_pendulum_press_swings_once_a_master_cycle_its_robots_every_cycle(swinging: tuple[dict, Path]) -> None:
    """A pendulum press in a line makes one swing a master cycle (a part a cycle), forward in one and back in
    the next: the written trajectory runs two master cycles, the crank turning one way in the first and the
    other in the second, and the replay (each robot at its line start every cycle, the slide by the closed
    form from the written crank angle) finds every clearance and transfer gap held in both."""
    result, out = swinging
    assert result["status"] == "verified"
    period = result["period_s"]
    assert result["horizon_s"] == pytest.approx(2 * period, rel=1e-12)
    assert result["stations"][1]["mode"] == "pendulum"
    table = np.genfromtxt(out / "line_trajectory.csv", delimiter=",", names=True)
    assert table["time_s"][-1] == pytest.approx(2 * period, abs=2e-3)
    local = np.mod(table["time_s"] - result["stations"][1]["phase_offset_s"], 2 * period)  # the press's own time
    order = np.argsort(local)
    theta = np.radians(table["second_crank_angle_deg"])[order]
    turn = int(np.argmax(theta))  # the turn at theta_e: forward up to it, back after it
    assert np.all(np.diff(theta[: turn + 1]) >= -1e-9) and np.all(np.diff(theta[turn:]) <= 1e-9)
    assert np.ptp(theta[: turn + 1]) > 1.0 and np.ptp(theta[turn:]) > 1.0
    assert np.all(theta < 2 * np.pi) and np.all(theta > 0)  # never past TDC
    clearance, gap, both = _replay(result, out, DATA / "slow.yaml")
    assert clearance >= -REPLAY_TOL_MM and gap >= -REPLAY_TOL_S and not both
    shifts = [c for c in result["checks"] if "after its start at theta_e" in c["name"]]
    assert len(shifts) == 2 and all(c["value"] == pytest.approx(period, abs=1e-9) for c in shifts)
@pytest.mark.slow  # a line solve: about 10 s


def test_the_line_verification_fails_a_swing_whose_robots_drift_off_the_master(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """The line's checks can fail for a pendulum press: its robots' starts in the window at theta_s 2 ms off a
    master cycle after those at theta_e (the press's own check still passes): unverified, exit 3, nothing
    written."""
    from dataclasses import replace

    from planning.solver import pendulum_line

    at_period = pendulum_line.swings_at_period

    def drifted(*args):  # noqa: ANN002, ANN202
        solution = at_period(*args)
        starts = {r: {**by, "at theta_s": by["at theta_s"] + 0.002} for r, by in solution.plan.robot_starts_s.items()}
        return replace(solution, plan=replace(solution.plan, robot_starts_s=starts))

    monkeypatch.setattr("planning.solver.line.swings_at_period", drifted)
    args = ["line", str(DATA / "slow.yaml"), "--set", "second.planner.mode=pendulum", "--out", str(tmp_path)]
    assert main([*args, "--no-plots"]) == 3
    err = capsys.readouterr().err
    assert "unverified" in err and "start at theta_s after its start at theta_e" in err, err
    assert not (tmp_path / "line_result.json").exists()


@pytest.mark.slow
def test_an_asymmetric_pendulum_press_in_the_shipped_line_serves_its_robots_every_cycle(tmp_path: Path) -> None:
    """The shipped line with its link-drive trim press in pendulum strokes (the swings differ): verified, the
    robots' starts a master cycle apart in its two windows, the replay holding every clearance over both."""
    sets = ["trim.planner.mode=pendulum", "trim.process.draw_speed_rpm=10"]
    result = _run(SHIPPED, tmp_path, *[a for s in sets for a in ("--set", s)])
    assert result["status"] == "verified"
    own = result["stations"][1]["robot_starts_own_s"]
    assert own["unloader"]["at theta_s"] - own["unloader"]["at theta_e"] == pytest.approx(result["period_s"], abs=1e-9)
    clearance, gap, both = _replay(result, tmp_path, SHIPPED)
    assert clearance >= -REPLAY_TOL_MM and gap >= -REPLAY_TOL_S and not both


@pytest.mark.slow  # the optimal law with robots, alone and at the line's period: about 2 minutes
def test_a_press_drawing_at_a_slide_speed_keeps_it_at_the_lines_period(tmp_path: Path) -> None:
    """The slow line with its first press drawing at 60 mm/s slide speed (the optimal law): verified at the
    robot's loop, the replay holding every clearance, and the slide, by the closed form from the written crank
    angle, never faster than 60 mm/s in the draw and at it (within 0.1 %) over a third of the draw's samples."""
    sets = [
        "first.planner.motion_law=optimal",
        "first.limits.crank_jerk_rad_s3=3000",
        "first.limits.crank_accel_rad_s2=60",
        "first.process.draw_slide_speed_mm_s=60",
    ]
    result = _run(DATA / "slow.yaml", tmp_path, *[a for s in sets for a in ("--set", s)])
    assert result["status"] == "verified" and result["bottleneck"]["kind"] == "robot"
    clearance, gap, both = _replay(result, tmp_path, DATA / "slow.yaml")
    assert clearance >= -REPLAY_TOL_MM and gap >= -REPLAY_TOL_S and not both
    table = np.genfromtxt(tmp_path / "line_trajectory.csv", delimiter=",", names=True)
    theta = np.radians(table["first_crank_angle_deg"])
    R, L = 50.0, 250.0  # tests/data/line/press_a.yaml
    h = R * (1 + np.cos(theta)) + L - np.sqrt(L**2 - (R * np.sin(theta)) ** 2)
    speed = np.abs(np.gradient(h, table["time_s"]))
    drawing = (np.degrees(theta) > 145.5) & (np.degrees(theta) < 184.5)  # theta2 .. theta3, the ends left out
    assert np.max(speed[drawing]) <= 60.0 * (1 + 1e-3)  # (finite differences of the 1 ms grid)
    assert np.mean(np.abs(speed[drawing] - 60.0) <= 0.06) > 1 / 3


def _stand_in_alone(monkeypatch: pytest.MonkeyPatch, fails: bool = False) -> list[str]:
    """``planning.solver.line``'s station solve and key on stand-ins (a station's key its case's name); the names
    of the stations solved."""
    from types import SimpleNamespace

    from planning.solver import line as line_module

    solved: list[str] = []

    def alone(station):  # noqa: ANN001, ANN202
        solved.append(station.name)
        if fails:
            raise ValueError(f"station {station.name}")
        line_module._keep(station.case, SimpleNamespace(name=f"plan of {station.case}"))
        return SimpleNamespace(name=f"plan of {station.case}")

    monkeypatch.setattr(line_module, "_alone", alone)
    monkeypatch.setattr(line_module, "_key", lambda station: station.case)
    monkeypatch.setattr(line_module, "_ALONE", {})
    return solved


def test_a_line_keeps_each_press_alone_once_and_a_full_store_loses_none_of_this_lines(monkeypatch):
    """The presses' plans alone are kept (at most ALONE_KEPT): a line whose new plans push its own known ones
    out of the store still has them all (a line sweep varying one press over many points once met a KeyError)."""
    from types import SimpleNamespace

    from planning.solver import ahead
    from planning.solver import line as line_module

    solved = _stand_in_alone(monkeypatch)
    monkeypatch.setattr(line_module, "ALONE_KEPT", 2)
    stations = [SimpleNamespace(name=n, case=c) for n, c in (("draw", "a"), ("trim", "b"), ("flange", "a"))]
    line_module._ALONE.update({"a": SimpleNamespace(name="plan of a"), "z": SimpleNamespace(name="old")})
    for _ in range(2):
        plans = line_module._alone_all(tuple(stations), ahead.in_turn)
        assert [p.name for p in plans] == ["plan of a", "plan of b", "plan of a"]
    # b solved once (a known); b pushed a out of the store, so the next line solved a again (its first station)
    assert solved == ["trim", "draw"]


def test_of_presses_sharing_a_case_the_first_is_named_when_it_fails(monkeypatch):
    from types import SimpleNamespace

    from planning.solver import ahead
    from planning.solver import line as line_module

    _stand_in_alone(monkeypatch, fails=True)
    stations = (SimpleNamespace(name="trim", case="trim.yaml"), SimpleNamespace(name="flange", case="trim.yaml"))
    with pytest.raises(ValueError, match="station trim$"):
        line_module._alone_all(stations, ahead.in_turn)
