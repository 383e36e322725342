"""Speed of the published case; writes benchmarks/RESULTS.md.

Measures (a) the in-process solve after a warm-up (the NLP already built; taking turns with the
drive cases' solves, whose times it divides), a cold ``pressplan solve``
process beside a process that only imports casadi, numpy, matplotlib and yaml, and the NLP build
alone; (b) a 41-point transfer-time sweep with 1 and 2 workers (whole process, points per second);
(c) a 7-point trade-off (``pressplan tradeoff``) on both drive cases with 2 workers; (d) the SPM of
every motion law and its share of the certified upper bound and the grid bound, with each law's NLP build
and solve time
(``pressplan laws``). Medians; run with ``python benchmarks/bench_solve.py`` from the project root
where pressplan is installed.
"""

from __future__ import annotations

import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "wang2023-side-panel.yaml"
DRIVE_CASE = ROOT / "cases" / "wang2023-side-panel-drive.yaml"
CUP_DRIVE_CASE = ROOT / "cases" / "cup-2000kN-drive.yaml"
# one drive case per mechanism, the crank-slider's first (the others' times are compared with it)
MECHANISM_CASES = [
    DRIVE_CASE,
    ROOT / "cases" / "link-drive-side-panel.yaml",
    ROOT / "cases" / "knuckle-joint-coining.yaml",
]
MECHANISM_COLD_RUNS = 3
TRADEOFF_RUNS = 3
COLD_RUNS = 5
WARM_RUNS = 7


def timed(cmd: list[str]) -> float:
    t = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t


def main() -> None:
    import casadi

    from planning.model.case_file import read_case
    from planning.solver.halves_nlp import fresh_build
    from planning.solver.optimize import solve

    case = read_case(CASE)
    t = time.perf_counter()
    fresh_build(case)
    build = time.perf_counter() - t
    first = solve(case)  # warm-up: builds the cached NLP
    drive_case = read_case(DRIVE_CASE)
    strong = drive_case.model_dump(exclude_none=True)  # the same press with motors ten times as strong
    for key in ("peak_torque_Nm", "rated_torque_Nm"):
        strong["drive"]["motor"][key] *= 10
    from planning.model.case_file import case_from_data

    linkages = [read_case(path) for path in MECHANISM_CASES[1:]]
    (warm, sol), (drive_warm, drive_sol), (strong_warm, _), *linkage_warm = _interleaved(
        [case, drive_case, case_from_data(strong), *linkages], solve
    )
    assert sol.verification.passed and abs(sol.plan.spm - first.plan.spm) < 1e-9

    exe = Path(sys.executable).with_name("pressplan")
    imports, cold, cold_plots = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(COLD_RUNS):
            imports.append(timed([sys.executable, "-c", "import casadi, numpy, matplotlib, yaml"]))
            cold.append(timed([str(exe), "solve", str(CASE), "--out", tmp, "--no-plots"]))
            cold_plots.append(timed([str(exe), "solve", str(CASE), "--out", tmp]))
    sweep_rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for workers in (1, 2):
            wall = timed(
                [
                    str(exe),
                    "sweep",
                    str(CASE),
                    "--vary",
                    "process.transfer_time_s=1.0:3.0:41",
                    "--workers",
                    str(workers),
                    "--out",
                    f"{tmp}/w{workers}",
                ]
            )
            sweep_rows.append((workers, wall))
    tradeoff_rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for drive_path, start in ((DRIVE_CASE, 5.0), (CUP_DRIVE_CASE, 20.0)):
            walls = [
                timed(
                    [str(exe), "tradeoff", str(drive_path), "--spm", f"{start:g}:max:7", "--workers", "2"]
                    + ["--out", f"{tmp}/t{k}"]
                )
                for k in range(TRADEOFF_RUNS)
            ]
            tradeoff_rows.append((drive_path.name, start, statistics.median(walls)))
    optimal_rows = _optimal(case, exe, imports)
    law_rows = _laws(case)
    mechanism_rows = _mechanisms(exe, [(drive_warm, drive_sol), *linkage_warm], [drive_case, *linkages])
    med = statistics.median
    rows = [
        ("NLP build (once per process)", build),
        (f"in-process solve, warm (median of {WARM_RUNS}, taking turns with the two drive solves below)", med(warm)),
        (f"import casadi, numpy, matplotlib, yaml (median of {COLD_RUNS})", med(imports)),
        (f"cold `pressplan solve --no-plots` process (median of {COLD_RUNS})", med(cold)),
        ("cold solve beyond the imports (no figures)", med(cold) - med(imports)),
        (f"cold `pressplan solve` process with its two figures (median of {COLD_RUNS})", med(cold_plots)),
        ("cold solve with figures beyond the imports", med(cold_plots) - med(imports)),
    ]
    rows.append(
        (f"in-process solve of `{DRIVE_CASE.name}` (motor RMS binds), warm (median of {WARM_RUNS})", med(drive_warm))
    )
    rows.append(("  drive solve / kinematic solve [ratio]", med(drive_warm) / med(warm)))
    rows.append((f"the same with motors 10x as strong (nothing binds), warm (median of {WARM_RUNS})", med(strong_warm)))
    rows.append(("  drive solve / kinematic solve [ratio]", med(strong_warm) / med(warm)))
    for workers, wall in sweep_rows:
        rows.append((f"41-point transfer-time sweep, {workers} worker(s), whole `pressplan sweep` process", wall))
        rows.append((f"  sweep throughput, {workers} worker(s) [points/s]", 41 / wall))
    rows += optimal_rows
    for name, start, wall in tradeoff_rows:
        rows.append(
            (
                f"7-point `pressplan tradeoff {name} --spm {start:g}:max:7`, 2 workers, whole process "
                f"(median of {TRADEOFF_RUNS}; target 10 s)",
                wall,
            )
        )
    lines = [
        "# Benchmarks",
        "",
        "Written by `python benchmarks/bench_solve.py` (do not edit by hand).",
        "",
        f"Machine: {os.cpu_count()} cores, {platform.machine()}, Python {platform.python_version()}, "
        f"CasADi {casadi.__version__}; {datetime.now(timezone.utc):%Y-%m-%d}.",
        "",
        f"Default solve of `{CASE.relative_to(ROOT)}`: {sol.plan.spm:.3f} SPM, "
        f"{sol.plan.solver.iterations} IPOPT iterations over {sol.plan.solver.starts} starts. With its drive "
        f"(`{DRIVE_CASE.name}`): {drive_sol.plan.spm:.3f} SPM, {drive_sol.plan.solver.iterations} iterations.",
        "",
        "| measurement | wall time [s] |",
        "|---|---:|",
        *[f"| {name} | {value:.3f} |" for name, value in rows],
        "",
        "Motion laws on the same case (free placement), against the certified upper bound "
        f"({law_rows[0]['upper']:.3f} SPM on `bound --certified`'s default grid, {law_rows[0]['upper_time']:.2f} s "
        f"to compute; on `laws`' grid {law_rows[0]['laws_upper']:.3f} SPM, {law_rows[0]['laws_upper_time']:.2f} s) "
        f"and the time-optimal grid bound ({law_rows[0]['bound']:.3f} SPM, {law_rows[0]['bound_time']:.2f} s):",
        "",
        "| law | SPM | % of the certified upper bound | % of the grid bound | NLP build [s] | solve [s] |",
        "|---|---:|---:|---:|---:|---:|",
        *[
            f"| {r['law']} | {r['spm']:.3f} | {r['upper_share']:.1f} | {r['share']:.1f} | {r['build']:.2f} | "
            f"{r['solve']:.2f} |"
            for r in law_rows
        ],
        "",
        "Every mechanism's drive case (improved S-curve, free placement): a cold `pressplan solve --no-plots` "
        f"process (median of {MECHANISM_COLD_RUNS}, the cases taking turns), an in-process solve with the NLPs "
        f"built (median of {WARM_RUNS}, taking turns with the solves above) and a re-solve from the plan before "
        f"(a sweep's or the page's warm start; median of {WARM_RUNS}); the ratios divide by the crank-slider's "
        "(target: at most 2):",
        "",
        "| mechanism | case | SPM | IPOPT iterations | cold [s] | ratio | warm [s] | ratio | from the plan before [s] "
        "| ratio |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        *mechanism_rows,
        "",
    ]
    out = ROOT / "benchmarks" / "RESULTS.md"
    old = out.read_text(encoding="utf-8") if out.exists() else ""
    web = old[old.index("<!-- web:begin -->") :] if "<!-- web:begin -->" in old else ""  # bench_web.py's
    out.write_text("\n".join(lines) + ("\n" + web if web else ""))
    print("\n".join(lines))


def _optimal(case, exe: Path, imports: list[float]) -> list[tuple[str, float]]:
    """The optimal law on the published case at the improved S-curve's own peak crank jerk: a cold
    process, an in-process re-solve (NLPs built), and a re-solve from the plan before (a sweep's, a web
    edit's warm start)."""
    import yaml

    from planning.model.case_file import case_from_data
    from planning.model.profile import max_abs_jerk
    from planning.solver.optimize import solve

    jerk = max_abs_jerk(solve(case).plan.profile)
    data = case.model_dump(exclude_none=True)
    data["limits"]["crank_jerk_rad_s3"] = jerk
    data["planner"]["motion_law"] = "optimal"
    limited = case_from_data(data)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "optimal.yaml"
        path.write_text(yaml.safe_dump(data), encoding="utf-8")
        cold = [timed([str(exe), "solve", str(path), "--out", f"{tmp}/o", "--no-plots"]) for _ in range(3)]
    first = solve(limited)
    warm, follow = [], []
    for _ in range(WARM_RUNS):
        t = time.perf_counter()
        solve(limited)
        warm.append(time.perf_counter() - t)
        t = time.perf_counter()
        solve(limited, neighbour=first.plan)
        follow.append(time.perf_counter() - t)
    med = statistics.median
    label = f"`--law optimal`, published case, crank jerk limit {jerk:.2f} rad/s^3 ({first.plan.spm:.3f} SPM)"
    return [
        (
            f"{label}: cold `pressplan solve --no-plots` beyond the imports (median of 3; target 2 s)",
            med(cold) - med(imports),
        ),
        (f"{label}: in-process, NLPs built (median of {WARM_RUNS}; target 0.5 s)", med(warm)),
        (f"{label}: in-process from the plan before (median of {WARM_RUNS})", med(follow)),
    ]


def _mechanisms(exe: Path, warm: list[tuple[list[float], object]], cases: list) -> list[str]:
    """The rows of the mechanisms' table: cold processes taking turns, the warm solves measured with the
    others (``warm``), re-solves from the plan before taking turns."""
    from planning.solver.optimize import solve

    cold: list[list[float]] = [[] for _ in cases]
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(MECHANISM_COLD_RUNS):
            for k, path in enumerate(MECHANISM_CASES):
                cold[k].append(timed([str(exe), "solve", str(path), "--out", f"{tmp}/m{k}", "--no-plots"]))
    follow: list[list[float]] = [[] for _ in cases]
    for _ in range(WARM_RUNS):
        for k, (case, (_, solution)) in enumerate(zip(cases, warm, strict=True)):
            t = time.perf_counter()
            solve(case, neighbour=solution.plan, follow=True)  # as a sweep's and the page's re-solves
            follow[k].append(time.perf_counter() - t)
    med = statistics.median
    base = (med(cold[0]), med(warm[0][0]), med(follow[0]))
    rows = []
    for k, case in enumerate(cases):
        solution = warm[k][1]
        times = (med(cold[k]), med(warm[k][0]), med(follow[k]))
        cells = " | ".join(f"{t:.3f} | {t / b:.2f}" for t, b in zip(times, base, strict=True))
        rows.append(
            f"| {case.machine.kind} | `{MECHANISM_CASES[k].name}` | {solution.plan.spm:.3f} | "
            f"{solution.plan.solver.iterations} | {cells} |"
        )
    return rows


def _interleaved(cases: list, solve) -> list[tuple[list[float], object]]:
    """Warm in-process solve times of each case (after one solve that builds its NLPs) and its last
    solution. The cases take turns, ``WARM_RUNS`` rounds, so a drift of the machine's speed (up to 1.7x
    within a day here) falls on all of them alike and their ratios compare like with like."""
    for case in cases:
        solve(case)
    times: list[list[float]] = [[] for _ in cases]
    solutions: list[object] = [None] * len(cases)
    for _ in range(WARM_RUNS):
        for k, case in enumerate(cases):
            t = time.perf_counter()
            solutions[k] = solve(case)
            times[k].append(time.perf_counter() - t)
    return list(zip(times, solutions, strict=True))


def _laws(case) -> list[dict]:
    """(c): every law's SPM, share of the bound, NLP build time and (warm) solve time."""
    from planning.model.laws import SHAPED_LAWS
    from planning.reports.law_comparison import LAWS_UPPER_PIECES, LAWS_UPPER_POINTS
    from planning.solver.bound import time_optimal_bound
    from planning.solver.halves_nlp import fresh_build
    from planning.solver.optimize import solve
    from planning.solver.upper_bound import upper_bound

    t = time.perf_counter()
    bound = time_optimal_bound(case)
    bound_time = time.perf_counter() - t
    t = time.perf_counter()
    upper = upper_bound(case)
    upper_time = time.perf_counter() - t
    t = time.perf_counter()
    laws_upper = upper_bound(case, LAWS_UPPER_POINTS, LAWS_UPPER_PIECES)
    laws_upper_time = time.perf_counter() - t
    rows = []
    for law in SHAPED_LAWS:  # the optimal law has rows of its own (it needs a jerk limit)
        variant = case.with_law(law)
        t = time.perf_counter()
        fresh_build(variant)
        build = time.perf_counter() - t
        t = time.perf_counter()
        sol = solve(variant)
        elapsed = time.perf_counter() - t
        assert sol.verification.passed
        rows.append(
            {
                "law": law,
                "spm": sol.plan.spm,
                "share": 100 * sol.plan.spm / bound.spm,
                "upper_share": 100 * sol.plan.spm / upper.spm,
                "upper": upper.spm,
                "upper_time": upper_time,
                "laws_upper": laws_upper.spm,
                "laws_upper_time": laws_upper_time,
                "build": build,
                "solve": elapsed,
                "bound": bound.spm,
                "bound_time": bound_time,
            }
        )
    return rows


if __name__ == "__main__":
    main()
