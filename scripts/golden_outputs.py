"""Write every command's outputs on every case to a folder, or compare two such folders.

Used to show that a structural change leaves the outputs identical, timing fields aside:

    python scripts/golden_outputs.py write BEFORE_DIR [CASE ...]     # on the old commit
    python scripts/golden_outputs.py write AFTER_DIR [CASE ...]      # on the new commit
    python scripts/golden_outputs.py diff BEFORE_DIR AFTER_DIR [--rename OLD=NEW ...]

Covers ``check --json``, ``solve`` (both placements), ``compare``, ``laws``, ``bound --json`` on every
case in ``cases/`` (or the CASE stems given), ``tradeoff`` on the cases with a drive, and a small
``sweep``. Timing fields (wall times, solve times, iteration and start counts) are dropped before
comparing; every other number must agree to :data:`REL_TOL` relative to the larger of the two or to the
scale of its key in the file (a value that is zero up to round-off). Lists of named things (the
verification's checks) compare by name; a point at a knot named as the end of one segment or the start
of the next is the same point. ``--rename PATH=NEW``: a key renamed on purpose (``PATH``, dotted from the
top of a JSON file or a CSV column, in the first folder reads as ``NEW``); ``--allow PATH``: a key added
or removed on purpose (``--allow '*.KEY'``: the key KEY wherever it is).
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIMING_KEYS = {"wall_time_s", "solve_time_s", "timeline"}  # a run's times (a sweep's timeline: all times)
REL_TOL = 1e-9  # relative agreement of every number
ABS_TOL = 1e-12  # absolute floor (numbers that are zero up to round-off)
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _run(args: list[str], stdout_file: Path | None = None) -> None:
    cmd = [sys.executable, "-m", "planning.cli", *args]
    res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if stdout_file is not None:
        stdout_file.parent.mkdir(parents=True, exist_ok=True)
        stdout_file.write_text(res.stdout + (f"\nexit {res.returncode}\n{res.stderr}" if res.returncode else ""))
    print(f"exit {res.returncode}: {' '.join(args)}", flush=True)
    if res.returncode not in (0, 3):
        print(res.stderr, file=sys.stderr)


def write(folder: Path, names: list[str]) -> None:
    folder = folder.resolve()
    folder.mkdir(parents=True, exist_ok=True)
    cases = sorted((ROOT / "cases").glob("*.yaml"))
    if names:
        cases = [c for c in cases if c.stem in names]
    for case in cases:
        name = case.stem
        _run(["check", str(case), "--json"], folder / name / "check.json")
        for placement in ("free", "published"):
            _run(["solve", str(case), "--placement", placement, "--out", str(folder / name / f"solve-{placement}")])
        _run(["bound", str(case), "--json"], folder / name / "bound.json")
        _run(["laws", str(case), "--out", str(folder / name / "laws")])
        _run(["compare", str(case), "--out", str(folder / name / "compare")])
        if "drive:" in case.read_text(encoding="utf-8"):
            _run(["tradeoff", str(case), "--spm", "5:max:3", "--out", str(folder / name / "tradeoff")])
    case = ROOT / "cases" / "wang2023-side-panel.yaml"
    _run(["sweep", str(case), "--vary", "process.transfer_time_s=1.2:1.8:4", "--out", str(folder / "sweep")])


SOLVER_KEYS = {"iterations", "starts"}  # how a solve got there, not what it found
# a knot named the old way ("feed:accel4 (100% in)") or in words ("feed, 4th acceleration sub-segment, 100 % in")
KNOT_IN_TEXT = re.compile(r"\S+ \((?:0|100)% in\)|\w+, (?:[\w -]+, )?(?:0|100) % in")
# a point at a knot: the end of one segment is the next one's start. Two such labels are taken as the same
# point; the key points' times are compared as numbers (result.json, the summary's table), so a label can
# differ only in which side of the knot names the same instant
KNOT = re.compile(r"^(\S+) \((0|100)% in\)$|^\w+, (?:[\w -]+, )?(0|100) % in$")


def _strip(obj, renames: dict[str, str], path: str = ""):  # noqa: ANN001, ANN202 - JSON data
    """``obj`` without timing and solver-count keys; a key whose dotted path from the root is renamed takes
    its new name (``--rename baseline.transfer_time_s=transfer_window_s``)."""
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            if k in TIMING_KEYS | SOLVER_KEYS:
                continue
            here = f"{path}.{k}" if path else k
            out[renames.get(here, k)] = _strip(v, renames, here)
        return out
    if isinstance(obj, list):
        names = [v.get("name") for v in obj if isinstance(v, dict)]
        if obj and len(names) == len(obj) and None not in names and len(set(names)) == len(names):
            return {str(v["name"]): _strip(v, renames, f"{path}[]") for v in obj}  # named things: by name
        return [_strip(v, renames, f"{path}[]") for v in obj]
    return obj


def _scales(obj, out: dict[str, float]) -> dict[str, float]:  # noqa: ANN001 - JSON data
    """The largest magnitude of every key's numbers anywhere in ``obj`` (a quantity's scale)."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
                out[k] = max(out.get(k, 0.0), abs(float(v)))
            else:
                _scales(v, out)
    elif isinstance(obj, list):
        for v in obj:
            _scales(v, out)
    return out


def _same(a, b, path: str, allowed: set[str], scales: dict[str, float]) -> list[str]:  # noqa: ANN001 - JSON data
    """Where ``a`` and ``b`` differ: numbers to :data:`REL_TOL` of the larger of the two or of their key's
    scale; ``allowed``: paths that may be in one of them only (keys added or removed on purpose)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for k in sorted(set(a) | set(b), key=str):
            here = f"{path}.{k}" if path else str(k)
            if (k not in a or k not in b) and (here in allowed or f"*.{k}" in allowed):
                continue
            if k not in a or k not in b:
                out.append(f"{here}: only in {'first' if k in a else 'second'}")
                continue
            out += _same(a[k], b[k], here, allowed, scales)
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: {len(a)} against {len(b)} items"]
        pairs = zip(a, b, strict=True)
        return [d for i, (x, y) in enumerate(pairs) for d in _same(x, y, f"{path}[{i}]", allowed, scales)]
    if isinstance(a, str) and isinstance(b, str):
        if a == b or (KNOT.match(a) and KNOT.match(b)):  # the same knot named from either side
            return []
        na, nb = NUMBER.findall(a), NUMBER.findall(b)
        if NUMBER.sub("#", a) == NUMBER.sub("#", b) and len(na) == len(nb):
            bad = [(x, y) for x, y in zip(na, nb, strict=True) if not _close(float(x), float(y), text=True)]
            return [f"{path}: {a!r} against {b!r}"] if bad else []
        return [f"{path}: {a!r} against {b!r}"]
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        scale = scales.get(path.rsplit(".", 1)[-1].split("[")[0], 0.0)
        return [] if _close(float(a), float(b), scale=scale) else [f"{path}: {a!r} against {b!r}"]
    return [] if a == b else [f"{path}: {a!r} against {b!r}"]


def _close(x: float, y: float, text: bool = False, scale: float = 0.0) -> bool:
    if math.isnan(x) and math.isnan(y):
        return True
    if x == y:
        return True
    tol = REL_TOL * max(abs(x), abs(y), scale) + ABS_TOL
    if text:  # a printed number agrees to its last printed digit
        tol = max(tol, 10 ** (math.floor(math.log10(max(abs(x), abs(y), 1e-300))) - 3))
    return abs(x - y) <= tol


def _load(path: Path, renames: dict[str, str]) -> object:
    data = path.read_bytes()
    if path.suffix == ".json":
        try:
            return _strip(json.loads(data), renames)
        except json.JSONDecodeError:
            return _text(data.decode(errors="replace"))
    if path.suffix == ".csv":
        lines = data.decode().splitlines(keepends=True)
        head = "".join(ln for ln in lines if ln.startswith("#"))
        rows = list(csv.DictReader(io.StringIO("".join(ln for ln in lines if not ln.startswith("#")))))
        rows = [{renames.get(k, k): _number(v) for k, v in r.items() if k not in TIMING_KEYS} for r in rows]
        return {"header": _text(head), "rows": rows}
    if path.suffix == ".png":
        import matplotlib.image as mpimg

        return mpimg.imread(path)
    if path.suffix in (".txt", ".md"):
        return _text(data.decode())
    return data


def _text(text: str) -> list[str]:
    """Lines, without the solver line (it prints times and counts), a point at a knot written as such (the
    end of one segment is the start of the next)."""
    lines = [ln for ln in text.splitlines() if not ln.strip().startswith("solver:")]
    return [KNOT_IN_TEXT.sub("<a knot>", ln) for ln in lines]


def _number(value: object) -> object:
    if not isinstance(value, str):
        return value
    try:
        return float(value)
    except ValueError:
        return value


def diff(a: Path, b: Path, renames: dict[str, str], allowed: set[str]) -> int:
    import numpy as np

    files_a = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    files_b = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    bad = 0
    for rel in sorted(files_a ^ files_b):
        print(f"only in {'first' if rel in files_a else 'second'}: {rel}")
        bad += 1
    for rel in sorted(files_a & files_b):
        x, y = _load(a / rel, renames), _load(b / rel, {})
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            same = isinstance(x, np.ndarray) and isinstance(y, np.ndarray) and x.shape == y.shape
            problems = [] if same and np.array_equal(x, y) else ["the pixels differ"]
        else:
            scales = _scales(y, _scales(x, {}))
            problems = _same(x, y, "", allowed, scales)
        if problems:
            print(f"differs: {rel}: " + "; ".join(problems[:4]) + (" ..." if len(problems) > 4 else ""))
            bad += 1
    print(f"{len(files_a & files_b)} files compared, {bad} differ")
    return 1 if bad else 0


def main() -> int:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    w = sub.add_parser("write")
    w.add_argument("folder", type=Path)
    w.add_argument("cases", nargs="*", help="case stems (default: every case)")
    d = sub.add_parser("diff")
    d.add_argument("first", type=Path)
    d.add_argument("second", type=Path)
    d.add_argument("--rename", action="append", default=[], metavar="PATH=NEW", help="a key renamed on purpose")
    d.add_argument("--allow", action="append", default=[], metavar="PATH", help="a key added or removed on purpose")
    args = ap.parse_args()
    if args.command == "write":
        write(args.folder, args.cases)
        return 0
    renames = dict(r.split("=", 1) for r in args.rename)
    return diff(args.first, args.second, renames, set(args.allow))


if __name__ == "__main__":
    sys.exit(main())
