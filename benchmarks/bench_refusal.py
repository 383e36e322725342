"""How fast an impossible case is refused: key angles typed in radians (closing 1.05, draw start 2.44, draw
end 3.32, opening 5.24 on a 300/1000 mm press), and three other robot windows through BDC. Whole
``pressplan check`` and ``pressplan solve`` processes, median of 5 each; target: under 1 s. Writes the
``refusal`` block of benchmarks/RESULTS.md.

    python benchmarks/bench_refusal.py
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
RUNS = 5
TARGET_S = 1.0
WINDOWS = {  # case, key angles [deg as typed], changed fields
    "radians, crank-slider 300/1000": (
        "wang2023-side-panel.yaml",
        (1.05, 2.44, 3.32, 5.24),
        {"process": {"safety_height_mm": 400}, "press": {"crank_radius_mm": 300, "rod_length_mm": 1000}},
    ),
    "crank-slider, all before BDC": (
        "wang2023-side-panel.yaml",
        (20, 40, 60, 80),
        {"process": {"safety_height_mm": 300}, "limits": {"die_height_mm": 5}},
    ),
    "link drive, all after BDC": (
        "link-drive-side-panel.yaml",
        (300, 310, 320, 330),
        {"process": {"safety_height_mm": 300}, "limits": {"die_height_mm": 5}},
    ),
    "knuckle joint, all before BDC": (
        "knuckle-joint-coining.yaml",
        (20, 40, 60, 80),
        {"process": {"safety_height_mm": 30}, "limits": {"die_height_mm": 1}},
    ),
}


def case_file(folder: Path, name: str) -> Path:
    source, angles, changes = WINDOWS[name]
    data = yaml.safe_load((ROOT / "cases" / source).read_text(encoding="utf-8"))
    data.pop("published", None)
    keys = ("closing_deg", "draw_start_deg", "draw_end_deg", "opening_deg")
    data["key_points"] = dict(zip(keys, angles, strict=True))
    for section, fields in changes.items():
        data[section].update(fields)
    path = folder / f"{len(list(folder.iterdir()))}.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def timed(cmd: list[str]) -> float:
    t = time.perf_counter()
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    if done.returncode != 3:
        raise SystemExit(f"{' '.join(cmd)}: exit {done.returncode}, expected 3 (refused)")
    return time.perf_counter() - t


def main() -> None:
    exe = str(Path(sys.executable).with_name("pressplan"))
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name in WINDOWS:
            path = case_file(Path(folder), name)
            check = statistics.median(timed([exe, "check", str(path)]) for _ in range(RUNS))
            solve = statistics.median(
                timed([exe, "solve", str(path), "--out", str(Path(folder) / "out")]) for _ in range(RUNS)
            )
            rows.append(f"| {name} | {check:.3f} | {solve:.3f} |")
    block = "\n".join(
        [
            f"Refused before solving (exit 3), whole processes, median of {RUNS}; target {TARGET_S:g} s "
            "(`python benchmarks/bench_refusal.py`):",
            "",
            "| robot window through BDC | `pressplan check` [s] | `pressplan solve` [s] |",
            "|---|---:|---:|",
            *rows,
            "",
        ]
    )
    results = ROOT / "benchmarks" / "RESULTS.md"
    text = results.read_text(encoding="utf-8")
    begin, end = "<!-- refusal:begin -->", "<!-- refusal:end -->"
    if begin not in text:
        text = text.rstrip("\n") + f"\n\n{begin}\n{end}\n"
    head, rest = text.split(begin)
    _, tail = rest.split(end)
    results.write_text(f"{head}{begin}\n{block}{end}{tail}", encoding="utf-8")
    print(block)


if __name__ == "__main__":
    main()
