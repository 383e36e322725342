"""Hostile input: the corpus of tests/data/hostile/ (written by scripts/hostile_corpus.py) through every
command, number forms an engineer writes, broken output and sweep folders."""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import pytest

from planning.cli import main
from planning.model.case_file import CaseFileError, read_case

from .conftest import PUBLISHED_CASE

DATA = Path(__file__).parent / "data"
HOSTILE = sorted((DATA / "hostile").glob("*.yaml"))
NUMBER_FORMS = sorted((DATA / "number_forms").glob("*.yaml"))
PARSE_SECONDS = 5.0  # [s] a generous ceiling: the alias bomb cost 78 s before the reader refused aliases


def expected(path: Path) -> str:
    return path.with_suffix(".expect").read_text(encoding="utf-8").strip()


def commands(path: Path, out: Path) -> list[list[str]]:
    return [
        ["check", str(path)],
        ["solve", str(path), "--out", str(out / "solve")],
        ["bound", str(path)],
        ["laws", str(path), "--out", str(out / "laws")],
        ["sweep", str(path), "--vary", "process.transfer_time_s=1:2:2", "--out", str(out / "sweep")],
        ["plot", str(path)],  # a case file where an output folder belongs
    ]


def test_corpus_covers_every_kind():
    assert len(HOSTILE) >= 80
    names = {p.stem for p in HOSTILE}
    for kind in ("alias_bomb", "nested_brackets", "duplicate_nested_key", "radius_1e200", "lengths_1e308"):
        assert kind in names
    assert len(NUMBER_FORMS) >= 8


@pytest.mark.parametrize("path", HOSTILE, ids=lambda p: p.stem)
def test_hostile_file_one_line_exit_2_everywhere(path, tmp_path, capsys):
    before = path.read_bytes()
    t = time.perf_counter()
    with pytest.raises(CaseFileError):
        read_case(path)
    assert time.perf_counter() - t < PARSE_SECONDS
    for command in commands(path, tmp_path):
        code = main(command)
        out, err = capsys.readouterr()
        assert code == 2, (command, err)
        assert out == ""
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        assert str(path) in lines[0], lines[0]
        assert command[0] == "plot" or expected(path) in lines[0], lines[0]
        assert "Traceback" not in err
    assert path.read_bytes() == before
    assert not any(tmp_path.iterdir())  # nothing written, not even an empty folder


@pytest.mark.parametrize("path", NUMBER_FORMS, ids=lambda p: p.stem)
def test_every_number_form_is_the_number_it_says(path):
    """3.5e3, 20e-1, .1e2, 450., 3_500, +1200 ... read as the numbers of the published case."""
    base = read_case(PUBLISHED_CASE).model_dump(exclude={"published"})
    assert read_case(path).model_dump(exclude={"published"}) == base


@pytest.fixture(scope="module")
def solved_folder(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("solved") / "out"
    assert main(["solve", str(PUBLISHED_CASE), "--out", str(out)]) == 0
    return out


BROKEN_FOLDERS = {
    "empty_result": lambda d: (d / "result.json").write_text(""),
    "result_is_a_list": lambda d: (d / "result.json").write_text("[]"),
    "result_missing_keys": lambda d: (d / "result.json").write_text('{"spm": 1}'),
    "result_not_json": lambda d: (d / "result.json").write_text("{spm: "),
    "result_is_a_folder": lambda d: ((d / "result.json").unlink(), (d / "result.json").mkdir()),
    "header_only_trajectory": lambda d: (d / "trajectory.csv").write_text("time_s,crank_angle_deg\n"),
    "empty_trajectory": lambda d: (d / "trajectory.csv").write_text(""),
    "binary_trajectory": lambda d: (d / "trajectory.csv").write_bytes(bytes(range(256))),
    "text_in_trajectory": lambda d: (d / "trajectory.csv").write_text(
        (d / "trajectory.csv").read_text().replace("0,", "x,", 3)
    ),
    "no_trajectory": lambda d: (d / "trajectory.csv").unlink(),
    "trajectory_is_a_folder": lambda d: ((d / "trajectory.csv").unlink(), (d / "trajectory.csv").mkdir()),
    "figure_is_a_folder": lambda d: ((d / "motion_vs_time.png").unlink(), (d / "motion_vs_time.png").mkdir()),
}


@pytest.mark.parametrize("name", sorted(BROKEN_FOLDERS))
def test_plot_on_a_broken_folder_is_one_line_exit_2(name, solved_folder, tmp_path, capsys):
    folder = tmp_path / name
    shutil.copytree(solved_folder, folder)
    BROKEN_FOLDERS[name](folder)
    code = main(["plot", str(folder)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and str(folder) in err and "Traceback" not in err


SWEEP = ["--vary", "process.transfer_time_s=1.5:2.0:2"]
BROKEN_SWEEPS = {
    "corrupt_spec": lambda d: (d / "sweep.json").write_text("{not json"),
    "spec_is_a_folder": lambda d: (d / "sweep.json").mkdir(),
    "table_is_a_folder": lambda d: (d / "sweep.csv").mkdir(),
    "foreign_index": lambda d: (d / "sweep.csv").write_text("index,spm,status\n99,12,verified\n"),
    "text_index": lambda d: (d / "sweep.csv").write_text("index,spm,status\nfirst,12,verified\n"),
    "negative_index": lambda d: (d / "sweep.csv").write_text("index,spm,status\n-1,12,verified\n"),
    "binary_table": lambda d: (d / "sweep.csv").write_bytes(b"index,status\n\x00\xff\xfe,1\n"),
    "figure_is_a_folder": lambda d: (d / "sweep_spm.png").mkdir(),
}


@pytest.mark.parametrize("name", sorted(BROKEN_SWEEPS))
def test_sweep_on_a_broken_folder_is_one_line_exit_2(name, tmp_path, capsys):
    folder = tmp_path / name
    folder.mkdir()
    BROKEN_SWEEPS[name](folder)
    code = main(["sweep", str(PUBLISHED_CASE), *SWEEP, "--workers", "1", "--out", str(folder)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and str(folder) in err and "Traceback" not in err


@pytest.mark.parametrize("name", ["summary.txt", "result.json", "cam_table.csv"])
def test_the_case_file_is_never_written(name, tmp_path, capsys):
    """A case that lies in the output folder under a name solve writes is refused before solving."""
    out = tmp_path / "out"
    out.mkdir()
    case = out / name
    shutil.copy(PUBLISHED_CASE, case)
    before = case.read_bytes()
    assert main(["solve", str(case), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "holds the case file" in err and len(err.strip().splitlines()) == 1
    assert case.read_bytes() == before and sorted(p.name for p in out.iterdir()) == [name]


def test_folder_replaced_as_a_whole_keeps_other_files_and_drops_stale_ones(solved_folder, tmp_path, capsys):
    out = tmp_path / "out"
    shutil.copytree(solved_folder, out)
    (out / "notes.txt").write_text("mine")
    shutil.copy(PUBLISHED_CASE, out / "case.yaml")
    assert main(["solve", str(out / "case.yaml"), "--out", str(out), "--no-plots"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert "motion_vs_time.png" not in names  # the earlier run's figures are gone with --no-plots
    assert {"notes.txt", "case.yaml", "result.json", "trajectory.csv"} <= set(names)
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "case.yaml").read_bytes() == PUBLISHED_CASE.read_bytes()
    assert not [p for p in out.parent.iterdir() if ".pressplan-" in p.name]  # no temporary folder left


def test_a_file_that_cannot_be_replaced_leaves_the_folder_entirely_old(solved_folder, tmp_path, capsys):
    out = tmp_path / "out"
    shutil.copytree(solved_folder, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    (out / "cam_table.csv").unlink()
    (out / "cam_table.csv").mkdir()  # solve writes a file here: it cannot
    before.pop("cam_table.csv")
    assert main(["solve", str(PUBLISHED_CASE), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "cam_table.csv" in err
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before


def test_leftovers_of_an_interrupted_run_are_cleaned(solved_folder, tmp_path, capsys):
    out = tmp_path / "out"
    shutil.copytree(solved_folder, out)
    dead = tmp_path / ".out.pressplan-999999999-new-0123abcd"  # a pid that cannot exist
    dead.mkdir()
    (dead / "result.json").write_text("{}")
    legacy = out / ".pressplan-abc123"  # an earlier version's temporary folder
    legacy.mkdir()
    assert main(["solve", str(PUBLISHED_CASE), "--out", str(out), "--no-plots"]) == 0
    assert not dead.exists() and not legacy.exists()
    json.loads((out / "result.json").read_text())


def test_a_transfer_time_of_1000_s_solves():
    """No time variable is capped: the bounds scale with the slowest cycle the minimum crank speed allows."""
    from planning.model.case_file import case_from_data, load_yaml
    from planning.solver.optimize import solve

    data = load_yaml(PUBLISHED_CASE.read_text())
    data["process"]["transfer_time_s"] = 1000.0
    data["limits"]["min_crank_speed_rpm"] = 0.01  # 132 deg at 0.01 rpm take 2200 s: 1000 s can be met
    sol = solve(case_from_data(data))  # raises without a verified plan
    assert sol.plan.transfer_window() >= 1000.0 - 1e-6


def test_check_passes_its_own_highest_draw_speed():
    """At the highest draw speed the limits allow, every draw check sits on its limit: round-off is no failure."""
    from planning.model.case_file import case_from_data
    from planning.reports.check import check_case

    from .random_cases import seeded_case

    for seed in range(150):
        data = seeded_case(seed)
        data["process"].pop("draw_speed_rpm", None)
        try:
            case = case_from_data(data)
        except CaseFileError:
            continue
        report = check_case(case)
        failed = [c["name"] for c in report["checks"] if not c["passed"] and "safety" not in c["name"]]
        assert not failed, (seed, failed)
