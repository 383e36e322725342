"""Case files: the published case loads; every file of the bad-input corpus gives one line, exit 2."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from planning.cli import main
from planning.model.case_file import CaseFileError, read_case

BAD = sorted((Path(__file__).parent / "data" / "bad").glob("*.yaml"))
SPECIAL = {"empty.yaml": "empty", "binary.yaml": "binary"}


def expected(path: Path) -> str:
    if path.name in SPECIAL:
        return SPECIAL[path.name]
    first = path.read_text(encoding="utf-8").splitlines()[0]
    m = re.match(r"# expect: (.+)", first)
    assert m, f"{path.name} lacks an '# expect:' line"
    return m.group(1).strip()


def test_published_case_loads(case):
    assert case.press.crank_radius_mm == 450
    assert case.planner.placement == "free"
    assert case.published.spm == 11.7


@pytest.mark.parametrize("path", BAD, ids=lambda p: p.name)
def test_bad_case_file_gives_one_line_and_exit_2(path, capsys):
    with pytest.raises(CaseFileError):
        read_case(path)
    for command in (["check", str(path)], ["solve", str(path), "--out", str(path.parent / "never")]):
        code = main(command)
        out, err = capsys.readouterr()
        assert code == 2
        assert out == ""
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        assert str(path) in lines[0]
        assert expected(path) in lines[0]
        assert "Traceback" not in err
    assert not (path.parent / "never").exists()


def test_unknown_key_suggests_the_closest(capsys):
    code = main(["check", str(Path(__file__).parent / "data" / "bad" / "typo_key.yaml")])
    assert code == 2
    assert "did you mean 'crank_radius_mm'" in capsys.readouterr().err


def test_missing_file(tmp_path, capsys):
    code = main(["check", str(tmp_path / "nope.yaml")])
    assert code == 2
    assert "no such file" in capsys.readouterr().err


def test_folder_instead_of_file(tmp_path, capsys):
    code = main(["check", str(tmp_path)])
    assert code == 2
    assert "not a regular file" in capsys.readouterr().err


def test_bad_arguments_one_line(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["solve"])
    assert exc.value.code == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
    with pytest.raises(SystemExit) as exc:
        main(["solve", "x.yaml", "--placement", "nowhere"])
    assert exc.value.code == 2
