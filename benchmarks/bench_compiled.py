"""The NLPs compiled (``pressplan compile``) against interpreted: the same solves, taking turns.

Compiles the NLPs of the published case, its drive case and the link drive's (lifted) into a fresh cache (timing the
compiler), then measures each of these with the cache (``PRESSPLAN_CACHE`` at it) and without (``off``), the two
taking turns so that a drift of the machine's speed falls on both: the warm in-process solve (a process builds the
NLP, solves once, then ``WARM_RUNS`` times: their median; ``PAIRS`` processes each way), a cold ``pressplan solve
--no-plots`` process (``COLD_RUNS`` each way) of the published case and a 41-point transfer-time sweep of it on 2
workers (one whole process each way, interpreted first). The warm solves' plans and iterations are checked equal.
Writes its section of benchmarks/RESULTS.md. Run: ``python benchmarks/bench_compiled.py`` (about 10 minutes).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from results_section import write_section  # benchmarks/ is the script's folder

ROOT = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- compiled:begin -->", "<!-- compiled:end -->"
CASES = ("cases/wang2023-side-panel.yaml", "cases/wang2023-side-panel-drive.yaml", "cases/link-drive-side-panel.yaml")
PAIRS, WARM_RUNS, COLD_RUNS = 3, 7, 5
WARM = """
import statistics, sys, time
from planning.model.case_file import read_case
from planning.solver.optimize import solve
case = read_case(sys.argv[1])
first = solve(case)
times = []
for _ in range({runs}):
    t = time.perf_counter(); solution = solve(case); times.append(time.perf_counter() - t)
print(statistics.median(times), repr(solution.plan.spm), solution.plan.solver.iterations)
"""


def _run(cmd: list[str], cache: str) -> tuple[float, str]:
    """``cmd`` from the project root with ``PRESSPLAN_CACHE=cache``: its wall time [s] and its output."""
    t = time.perf_counter()
    out = subprocess.run(
        cmd, cwd=ROOT, env={**os.environ, "PRESSPLAN_CACHE": cache}, check=True, capture_output=True, text=True
    )
    return time.perf_counter() - t, out.stdout


def main() -> None:
    exe = str(Path(sys.executable).with_name("pressplan"))
    rows, lines = [], []
    with tempfile.TemporaryDirectory() as tmp:
        cache = f"{tmp}/cache"
        for case in CASES:
            wall, out = _run([exe, "compile", case], cache)
            done = out.strip().split(": ", 1)[1].split(" in ")[0]
            lines.append(f"`pressplan compile {case}`: {wall:.1f} s ({done}).")
        for case in CASES:
            warm = {"off": [], cache: []}
            for _ in range(PAIRS):
                answers = set()
                for setting in warm:
                    _, out = _run([sys.executable, "-c", WARM.format(runs=WARM_RUNS), case], setting)
                    median, spm, iterations = out.split()
                    warm[setting].append(float(median))
                    answers.add((spm, iterations))
                assert len(answers) == 1, answers  # the same plan, the same iterations
            rows.append((f"warm in-process solve of `{case}` (median of {WARM_RUNS}, {PAIRS} processes)", warm, cache))
        cold = {"off": [], cache: []}
        for _ in range(COLD_RUNS):
            for setting in cold:
                cold[setting].append(_run([exe, "solve", CASES[0], "--no-plots", "--out", f"{tmp}/o"], setting)[0])
        rows.append((f"cold `pressplan solve --no-plots {CASES[0]}` process (median of {COLD_RUNS})", cold, cache))
        sweep = {"off": [], cache: []}
        for setting in sweep:
            vary = ["--vary", "process.transfer_time_s=1.0:3.0:41", "--workers", "2", "--out", f"{tmp}/s{len(setting)}"]
            sweep[setting].append(_run([exe, "sweep", CASES[0], *vary], setting)[0])
        rows.append(("41-point transfer-time sweep, 2 workers, whole process", sweep, cache))
    body = [
        "## Compiled NLPs (`python benchmarks/bench_compiled.py`)",
        "",
        *lines,
        "",
        "The same solves interpreted (`PRESSPLAN_CACHE=off`) and with the compiled cache, taking turns; the same",
        "plans and iterations.",
        "",
        "| measurement | interpreted [s] | compiled [s] | ratio |",
        "|---|---:|---:|---:|",
    ]
    for label, times, key in rows:
        slow, fast = statistics.median(times["off"]), statistics.median(times[key])
        body.append(f"| {label} | {slow:.3f} | {fast:.3f} | {fast / slow:.2f} |")
    sweep_fast = statistics.median(rows[-1][1][rows[-1][2]])
    body.append("")
    body.append(f"The sweep compiled: {41 / sweep_fast:.1f} points/s.")
    write_section(BEGIN, END, "\n".join(body))
    print("\n".join(body))


if __name__ == "__main__":
    main()
