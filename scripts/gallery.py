"""Write docs/gallery.md and docs/gallery/: every figure of every shipped case, from a fresh run.

For each case in cases/: the figures of ``pressplan solve`` (motion against time and against crank
angle; with a drive the drive figure and the trade-off of ``pressplan tradeoff``) and the motion laws'
overlay of ``pressplan laws``; for the published case a sweep over one field and over two (the sweep's
figures). Look at them after a change to the plots.

    python scripts/gallery.py            # about 5 minutes on 2 cores
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GALLERY = ROOT / "docs" / "gallery"
SWEEPS = {  # the published case's sweeps: one field, two fields (some points without a plan)
    "sweep_1d": ["--vary", "process.transfer_time_s=1:28:10"],
    "sweep_2d": ["--vary", "process.transfer_time_s=2:26:5", "--vary", "limits.slider_accel_mm_s2=1000:4000:4"],
}
CAPTIONS = {
    "motion_vs_angle.png": "the motion against crank angle (`pressplan solve`)",
    "motion_vs_time.png": "the motion against time (`pressplan solve`)",
    "swing.png": "the swings against time and against crank angle (`pressplan solve`, a pendulum stroke)",
    "drive.png": "the drive (`pressplan solve`, a case with a drive)",
    "interference.png": "the robots on their interference curves (`pressplan solve`, a case with robots)",
    "laws_overlay.png": "every motion law (`pressplan laws`)",
    "tradeoff.png": "RMS torque and energy at the line's rate (`pressplan tradeoff --spm 5:max:5`)",
    "sweep_1d.png": "a sweep over the transfer time (`pressplan sweep`; beyond 22 s no plan: the window cannot "
    "take so long at 1 rpm)",
    "sweep_2d.png": "a sweep over the transfer time and the slide's acceleration limit (`pressplan sweep`)",
}


def _run(args: list[str]) -> None:
    from planning.cli import main

    code = main(args)
    if code != 0:
        raise SystemExit(f"pressplan {' '.join(args)}: exit {code}")


def case_figures(case: Path, scratch: Path) -> dict[str, Path]:
    """Every figure of ``case`` by its gallery file name, in ``scratch``."""
    found = {}
    _run(["solve", str(case), "--out", str(scratch / "solve")])
    found.update({p.name: p for p in (scratch / "solve").glob("*.png")})
    _run(["laws", str(case), "--out", str(scratch / "laws")])
    if (scratch / "laws" / "laws_overlay.png").exists():  # a pendulum case's laws are a table only
        found["laws_overlay.png"] = scratch / "laws" / "laws_overlay.png"
    if "\ndrive:" in case.read_text(encoding="utf-8"):
        _run(["tradeoff", str(case), "--spm", "5:max:5", "--out", str(scratch / "tradeoff")])
        found["tradeoff.png"] = scratch / "tradeoff" / "tradeoff.png"
    if case.stem == "wang2023-side-panel":
        for name, vary in SWEEPS.items():
            _run(["sweep", str(case), *vary, "--out", str(scratch / name)])
            found[f"{name}.png"] = scratch / name / "sweep_spm.png"
    return found


def _compact(source: Path, target: Path) -> None:
    """The figure with a 256-colour palette (a third of the bytes; the figures have few colours)."""
    from PIL import Image

    with Image.open(source) as image:
        image.convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(target, optimize=True)


def main() -> int:
    if GALLERY.exists():
        shutil.rmtree(GALLERY)
    lines = [
        "# Gallery",
        "",
        "Every figure of every shipped case, written by `scripts/gallery.py` from a fresh run.",
        "",
    ]
    for case in sorted((ROOT / "cases").glob("*.yaml")) + sorted((ROOT / "cases" / "pendulum").glob("*.yaml")):
        with tempfile.TemporaryDirectory() as folder:
            figures = case_figures(case, Path(folder))
            target = GALLERY / case.stem
            target.mkdir(parents=True)
            where = case.relative_to(ROOT).as_posix()
            lines += [f"## {case.stem}", "", f"[`{where}`](../{where})", ""]
            for name in CAPTIONS:
                if name in figures:
                    _compact(figures[name], target / name)
                    lines += [f"{CAPTIONS[name]}:", "", f"![{case.stem}: {name}](gallery/{case.stem}/{name})", ""]
        print(f"{case.stem}: {len(figures)} figures", file=sys.stderr)
    (ROOT / "docs" / "gallery.md").write_text("\n".join(lines), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
