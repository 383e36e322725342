"""What a newcomer meets first: prechecks that refuse the impossible before solving, the CLI's small
conveniences (``--version``, ``--set``, ``pressplan new``), messages that name what the user typed."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from planning.cli import main

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
KEYS = ("closing_deg", "draw_start_deg", "draw_end_deg", "opening_deg")


# Key angles whose robot window (theta4 -> TDC -> theta1) passes BDC: no motion keeps the slide above
# the safety height there. The first is the radians mistake (1.05 rad meant 60 deg) on a 300/1000 press.
# name -> (shipped case, key angles as typed [deg], changed fields); benchmarks/bench_refusal.py times them.
WINDOWS_THROUGH_BDC = {
    "radians": (
        "wang2023-side-panel.yaml",
        (1.05, 2.44, 3.32, 5.24),
        {"process.safety_height_mm": 400, "press.crank_radius_mm": 300, "press.rod_length_mm": 1000},
    ),
    "crank-slider, all before BDC": (
        "wang2023-side-panel.yaml",
        (20, 40, 60, 80),
        {"process.safety_height_mm": 300, "limits.die_height_mm": 5},
    ),
    "link drive, all after BDC": (
        "link-drive-side-panel.yaml",
        (300, 310, 320, 330),
        {"process.safety_height_mm": 300, "limits.die_height_mm": 5},
    ),
    "knuckle joint, all before BDC": (
        "knuckle-joint-coining.yaml",
        (20, 40, 60, 80),
        {"process.safety_height_mm": 30, "limits.die_height_mm": 1},
    ),
}


def window_case(folder: Path, name: str) -> Path:
    """The case file of :data:`WINDOWS_THROUGH_BDC` entry ``name``, written in ``folder``."""
    from planning.model.case_file import with_fields

    case, angles, fields = WINDOWS_THROUGH_BDC[name]
    data = yaml.safe_load((CASES / case).read_text())
    data.pop("published", None)
    data = with_fields(data, {**{f"key_points.{k}": a for k, a in zip(KEYS, angles, strict=True)}, **fields})
    path = folder / f"{Path(case).stem}-{len(list(folder.iterdir()))}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("name", WINDOWS_THROUGH_BDC)
def test_a_window_through_bdc_is_refused_before_solving(name, tmp_path, capsys, monkeypatch):
    """Refused by ``check`` and ``solve`` before any NLP is built (IPOPT's constructor fails the test), with
    one line naming the key angles; the time it takes is measured in ``benchmarks/``."""
    import casadi

    def no_nlp(*args, **kwargs):
        raise AssertionError("an NLP was built for a case the prechecks should refuse")

    monkeypatch.setattr(casadi, "nlpsol", no_nlp)
    angles = WINDOWS_THROUGH_BDC[name][1]
    path = window_case(tmp_path, name)
    assert main(["check", str(path)]) == 3
    out = capsys.readouterr().out
    fail = [line for line in out.splitlines() if line.strip().startswith("FAIL")]
    assert len(fail) == 1 and f"opening {angles[3]:g} deg" in fail[0] and f"closing {angles[0]:g} deg" in fail[0]
    assert main(["solve", str(path), "--out", str(tmp_path / "out")]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "infeasible" in err[0]
    assert f"key_points.opening_deg = {angles[3]:g}" in err[0] and f"key_points.closing_deg = {angles[0]:g}" in err[0]
    assert ("look like radians" in err[0]) == (name == "radians")
    assert ("look like radians" in out) == (name == "radians")
    assert not (tmp_path / "out").exists()


def test_the_window_check_is_over_the_whole_arc_on_every_shipped_case(capsys):
    """The shipped cases keep their windows above the safety height: the arc check passes where the ends do
    (a case with robots has no window: their interference curves replace it)."""
    for path in sorted(CASES.glob("*.yaml")):
        assert main(["check", str(path), "--json"]) in (0, 3)
        report = yaml.safe_load(capsys.readouterr().out)
        if "robots:" in path.read_text(encoding="utf-8"):
            assert not any("through TDC" in c["name"] for c in report["checks"])
            continue
        window = [c for c in report["checks"] if "through TDC" in c["name"]]
        assert len(window) == 1 and window[0]["passed"], path.name


# ---- pressplan new ----


@pytest.mark.parametrize("mechanism", ("crank-slider", "link-drive", "knuckle-joint"))
@pytest.mark.parametrize("drive", (False, True), ids=("kinematic", "drive"))
def test_a_new_case_passes_check_and_solves(mechanism, drive, tmp_path, capsys):
    path = tmp_path / "my-press.yaml"
    assert main(["new", str(path), "--mechanism", mechanism, *(["--drive"] if drive else [])]) == 0
    text = path.read_text()
    assert capsys.readouterr().out.startswith(f"{path}: a {mechanism} case")
    assert f"mechanism: {mechanism}" in text and ("\ndrive:" in text) == drive and "name: my-press" in text
    assert main(["check", str(path), "--json"]) == 0
    report = yaml.safe_load(capsys.readouterr().out)
    assert report["press"]["mechanism"] == mechanism and report["warnings"] == []
    out = tmp_path / "out"
    assert main(["solve", str(path), "--out", str(out), "--no-plots", "--json"]) == 0
    result = yaml.safe_load(capsys.readouterr().out)
    assert result["verification"]["passed"] and result["spm"] > 0
    assert ("drive" in result) == drive


def test_new_never_writes_over_a_file(tmp_path, capsys):
    path = tmp_path / "mine.yaml"
    path.write_text("my own case")
    assert main(["new", str(path)]) == 2
    assert path.read_text() == "my own case" and "exists already" in capsys.readouterr().err


# ---- the CLI ----


def test_version_prints_the_package_version(capsys):
    from importlib.metadata import version

    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"pressplan {version('pressplan')}"


PUBLISHED = str(CASES / "wang2023-side-panel.yaml")
DRIVE_CASE = str(CASES / "wang2023-side-panel-drive.yaml")


@pytest.mark.parametrize("command", ("check", "bound", "solve", "laws"))
def test_set_replaces_a_field_for_one_run(command, tmp_path, capsys, monkeypatch):
    """``--set`` reaches the case every command reads, checked as if the file held it: a safety height
    above the slide at theta1 is refused (exit 2, naming the key point and the field); a valid one runs."""
    monkeypatch.chdir(tmp_path)
    assert main([command, PUBLISHED, "--set", "process.safety_height_mm=800"]) == 2
    err = capsys.readouterr().err
    assert "key_points.closing_deg" in err and "process.safety_height_mm = 800" in err
    if command in ("check", "bound"):  # a valid --set runs (solve: test_infeasibility_names_the_full_dotted_field)
        valid = ["--set", "process.safety_height_mm=650", "--set", "limits.die_speed_mm_s=80"]
        assert main([command, PUBLISHED, *valid]) == 0


def test_set_changes_the_answer(capsys):
    assert main(["bound", PUBLISHED, "--json"]) == 0
    base = yaml.safe_load(capsys.readouterr().out)["spm"]
    assert main(["bound", PUBLISHED, "--json", "--set", "process.transfer_time_s=1.5"]) == 0
    assert yaml.safe_load(capsys.readouterr().out)["spm"] > base + 0.1


def test_set_makes_the_optimal_law_possible_without_editing_the_case(tmp_path, capsys):
    out = str(tmp_path / "out")
    assert main(["solve", DRIVE_CASE, "--law", "optimal", "--out", out]) == 2
    err = capsys.readouterr().err
    assert "--law optimal" in err and "--set limits.crank_jerk_rad_s3=VALUE" in err
    assert main(["bound", PUBLISHED, "--set", "limits.crank_jerk_rad_s3=200", "--json"]) == 0
    assert yaml.safe_load(capsys.readouterr().out)["crank_jerk_limit_rad_s3"] == 200


@pytest.mark.parametrize(
    ("setting", "expect"),
    (
        ("process.transfer_time=1.5", "process.transfer_time: unknown key; did you mean 'transfer_time_s'?"),
        ("process.safety_height_mm=-5", "process.safety_height_mm: input should be greater than 0 (got -5)"),
        ("process.safety_height_mm.x=1", "process.safety_height_mm: is a value, not a section"),
    ),
)
def test_a_bad_set_is_one_line_naming_the_field(setting, expect, capsys):
    assert main(["check", PUBLISHED, "--set", setting]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expect in err and PUBLISHED in err and err.endswith("(from --set)")


def test_a_set_without_a_value_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["check", PUBLISHED, "--set", "process.safety_height_mm"])
    assert stop.value.code == 2 and "expected FIELD=VALUE" in capsys.readouterr().err


def test_an_objective_without_a_rate_names_the_option(tmp_path, capsys):
    assert main(["solve", DRIVE_CASE, "--objective", "min-energy", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "--objective min-energy" in err and "--spm" in err and "planner.target_spm" not in err


def test_the_optimal_law_at_a_rate_names_the_jerk_limit_it_lacks(tmp_path, capsys):
    """The optimal law plans at a rate too; a case without a crank-jerk limit is told which ``--set`` adds it."""
    args = ["solve", DRIVE_CASE, "--law", "optimal", "--objective", "min-energy", "--spm", "8", "--out", str(tmp_path)]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--law optimal: limits.crank_jerk_rad_s3" in err
    assert "(add it: --set limits.crank_jerk_rad_s3=VALUE)" in err


def test_an_objective_without_a_drive_names_the_option(tmp_path, capsys):
    assert main(["solve", PUBLISHED, "--objective", "min-energy", "--spm", "8", "--out", str(tmp_path)]) == 2
    assert "--objective min-energy: needs a drive: section" in capsys.readouterr().err


def test_infeasibility_names_the_full_dotted_field(capsys):
    assert main(["solve", PUBLISHED, "--set", "process.transfer_time_s=1200", "--out", "unused"]) == 3
    err = capsys.readouterr().err
    assert "process.transfer_time_s = 1200" in err and "limits.min_crank_speed_rpm" in err


@pytest.mark.parametrize("points", (1440, 500, 97))
def test_bound_uses_the_intervals_asked(points, capsys):
    assert main(["bound", PUBLISHED, "--points", str(points), "--json"]) == 0
    assert yaml.safe_load(capsys.readouterr().out)["points"] == points


def test_bound_says_when_it_needs_more_intervals_than_asked(capsys):
    assert main(["bound", PUBLISHED, "--points", "2"]) == 0
    out = capsys.readouterr().out
    assert "more than the 2 asked" in out and "idle time in the robot's window" in out


def test_compare_help_says_what_it_needs(capsys):
    with pytest.raises(SystemExit):
        main(["compare", "--help"])
    assert "published.solution" in capsys.readouterr().out


def test_the_stage_names_are_in_words(free_solution):
    from planning.model.plan import segment_in_words

    assert segment_in_words("feed:accel4") == "feed, 4th acceleration sub-segment"
    assert segment_in_words("return:decel2") == "return, 2nd deceleration sub-segment"
    assert segment_in_words("feed:accel") == "feed, acceleration"
    assert segment_in_words("transfer:dwell") == "dwell, constant speed"  # the dwell, not the robot's window
    assert segment_in_words("transfer:24") == "window, interval 24"  # the optimal law's phase theta4 -> theta1
    structure = free_solution.plan.structure
    assert all(":" not in where and where.endswith("% in") for where in structure.values()), structure


def test_the_api_exports_what_the_readme_imports():
    import planning
    from planning.model.case_file import CaseFileError

    assert planning.CaseFileError is CaseFileError
    for name in ("read_case", "solve", "write_outputs", "trajectory", "CaseFileError", "PlanningError"):
        assert name in planning.__all__


def test_trajectory_has_named_columns(case, free_solution):
    from planning import trajectory
    from planning.reports.report import trajectory_columns

    table = trajectory(free_solution, case)
    assert tuple(table) == trajectory_columns(case)
    assert table["crank_angle_deg"][-1] - table["crank_angle_deg"][0] == pytest.approx(360.0)
    assert max(abs(table["slider_accel_mm_s2"])) <= case.limits.slider_accel_mm_s2 * (1 + 1e-6)


def test_compare_says_undecided_where_the_printed_digits_decide_nothing():
    """The angle swept by the rebuilt published profile can be off by 168 deg within the printed digits:
    that check decides nothing and says so, instead of 'ok'."""
    from planning.model.case_file import read_case
    from planning.reports.source_solution import consistency

    checks = {c.name: c for c in consistency(read_case(CASES / "wang2023-side-panel.yaml"))}
    swept = checks["angle swept by the rebuilt profile"]
    assert swept.consistent and swept.allowance > 90 and swept.verdict == "undecided"
    assert checks["T9 (draw time)"].verdict == "consistent"
    assert checks["x3 (return peak)"].verdict == "inconsistent"


def test_the_help_texts_and_messages_say_what_they_mean(tmp_path, capsys):
    """Issue 37's words: the top-level help names every mechanism, `bound --help` does not call the grid bound an
    upper bound, `check` labels a crank speed limit "crank speed" (a motor's limit "motor speed (on the crank)"),
    `safety_height_mm` put under `limits:` is told where it belongs, and docs/reference.md has the glossary."""
    for argv, words in ((["--help"], ("link drive", "knuckle joint")), (["bound", "--help"], ("no upper bound",))):
        with pytest.raises(SystemExit):
            main(argv)
        out = " ".join(capsys.readouterr().out.split())
        assert all(w in out for w in words), (argv, out)
    assert main(["check", str(ROOT / "tests" / "data" / "cases" / "link2500.yaml")]) == 0
    highest = next(x for x in capsys.readouterr().out.splitlines() if "highest draw speed" in x)
    assert "crank speed 45.0000" in highest and "motor speed" not in highest
    data = yaml.safe_load((ROOT / "cases" / "wang2023-side-panel.yaml").read_text(encoding="utf-8"))
    data["limits"]["safety_height_mm"] = data["process"].pop("safety_height_mm")
    path = tmp_path / "misplaced.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "limits.safety_height_mm" in err and "belongs under process:" in err
    glossary = (ROOT / "docs" / "reference.md").read_text(encoding="utf-8").split("## Glossary")[1]
    assert all(w in glossary for w in ("θ1", "θ4", "robot window", "dwell", "feed", "draw", "return"))


def test_the_summary_says_whose_the_draw_speed_is():
    """Issue 37's draw speed words: given by the case, the highest the limits allow (link2500, cold), or the
    planner's choice below that highest, which it then names with digits that `--set` takes back."""
    from planning.reports.report import result_dict, summary_text

    from .conftest import shipped, solved

    link = ROOT / "tests" / "data" / "cases" / "link2500.yaml"
    free = summary_text(result_dict(solved(link), shipped(link))).splitlines()[2]
    assert "draw 14.266 rpm (the highest the limits allow)" in free, free
    published = ROOT / "cases" / "wang2023-side-panel.yaml"
    assert "draw 6.700 rpm (given)" in summary_text(result_dict(solved(published), shipped(published)))
    r = result_dict(solved(link), shipped(link)) | {"draw_speed_rpm": 9.0}
    words = summary_text(r).splitlines()[2]
    assert "(the planner's choice; the limits allow up to 14.2664)" in words, words
