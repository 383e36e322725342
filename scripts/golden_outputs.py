"""Write every command's outputs on every case to a folder, or compare two such folders.

Used to show that a structural change leaves the outputs identical, timing fields aside:

    python scripts/golden_outputs.py write BEFORE_DIR      # on the old commit
    python scripts/golden_outputs.py write AFTER_DIR       # on the new commit
    python scripts/golden_outputs.py diff BEFORE_DIR AFTER_DIR

Covers ``solve`` (both placements), ``compare``, ``laws``, ``bound --json`` and a small ``sweep`` on
every case in ``cases/``. Timing fields (wall times, solve times) are dropped before comparing.
"""

from __future__ import annotations

import csv
import io
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIMING_KEYS = {"wall_time_s", "solve_time_s"}


def _run(args: list[str], stdout_file: Path | None = None) -> None:
    cmd = [sys.executable, "-m", "planning.cli", *args]
    res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if stdout_file is not None:
        stdout_file.write_text(res.stdout)
    print(f"exit {res.returncode}: {' '.join(args)}", flush=True)
    if res.returncode not in (0, 3):
        print(res.stderr, file=sys.stderr)


def write(folder: Path) -> None:
    folder = folder.resolve()
    folder.mkdir(parents=True, exist_ok=True)
    for case in sorted((ROOT / "cases").glob("*.yaml")):
        name = case.stem
        for placement in ("free", "published"):
            _run(["solve", str(case), "--placement", placement, "--out", str(folder / name / f"solve-{placement}")])
        _run(["bound", str(case), "--json"], folder / name / "bound.json")
        _run(["laws", str(case), "--out", str(folder / name / "laws")])
        _run(["compare", str(case), "--out", str(folder / name / "compare")])
    case = ROOT / "cases" / "wang2023-side-panel.yaml"
    _run(["sweep", str(case), "--vary", "process.transfer_time_s=1.2:1.8:4", "--out", str(folder / "sweep")])


def _strip(obj):
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items() if k not in TIMING_KEYS}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


def _normalised(path: Path) -> bytes | object:
    data = path.read_bytes()
    if path.suffix == ".json":
        try:
            return _strip(json.loads(data))
        except json.JSONDecodeError:
            return data
    if path.suffix == ".csv" and path.name == "sweep.csv":
        rows = list(csv.DictReader(io.StringIO(data.decode())))
        return [_strip(r) for r in rows]
    if path.name == "summary.txt":  # the summary prints the solve time
        return [ln for ln in data.decode().splitlines() if not ln.strip().startswith("solver:")]
    return data


def diff(a: Path, b: Path) -> int:
    files_a = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    files_b = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    bad = 0
    for rel in sorted(files_a ^ files_b):
        print(f"only in one: {rel}")
        bad += 1
    for rel in sorted(files_a & files_b):
        if _normalised(a / rel) != _normalised(b / rel):
            print(f"differs: {rel}")
            bad += 1
    print(f"{len(files_a & files_b)} files compared, {bad} differ")
    return 1 if bad else 0


if __name__ == "__main__":
    if sys.argv[1] == "write":
        write(Path(sys.argv[2]))
    else:
        sys.exit(diff(Path(sys.argv[2]), Path(sys.argv[3])))
