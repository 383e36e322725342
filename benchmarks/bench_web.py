"""Edit-to-chart latency of ``pressplan serve`` in a real browser; rewrites the web section of RESULTS.md.

The published case is opened in headless Chromium (Debian's ``chromium`` through Playwright), then
θ2 is edited 20 times (131.6 ... 133.5 deg); each time is measured in the page, from the change event
to the charts redrawn with the new plan (the server's warm re-solve included). Then θ2 is typed 20 times
as a user types it (the field's text selected, the new value's keys 80 ms apart, no change event): from
the last key's input event to the first chart and to the confirmed chart, typing's pause included. Run with
``python benchmarks/bench_web.py`` from the project root with the test extra installed; with ``PRESSPLAN_CACHE`` at a
cache where ``pressplan compile`` put the published case's NLP, it measures the page with it (its own section); with
``--serve-compiles`` (and ``PRESSPLAN_CACHE`` at an empty cache) it first compiles the NLPs the page built as
``pressplan serve`` does in the background, then measures (the same section).
"""

from __future__ import annotations

import statistics
import sys
from pathlib import Path

from results_section import write_section  # benchmarks/ is the script's folder

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from planning.model.outcome import Outcome  # noqa: E402 - after the path

EDITS = 20
BEGIN, END = "<!-- web:begin -->", "<!-- web:end -->"
COMPILED_MARKS = ("<!-- web-compiled:begin -->", "<!-- web-compiled:end -->")  # the same with the NLPs compiled


KEY_DELAY_MS = 80  # between a typist's keys
BURST_SESSIONS = 20
QUIET_EDITS = 8
QUIET_PAUSE_S = 1.0  # the quiet session's user looks at the chart between edits


def _post(url: str, body: dict) -> dict:
    import json
    import urllib.request

    request = urllib.request.Request(url, json.dumps(body).encode(), {"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=120) as answer:
        return json.loads(answer.read())


def burst(url: str, sessions: int) -> tuple[list[float], list[float]]:
    """Per quiet edit: seconds to its fast answer and to its confirmed answer while ``sessions`` other
    sessions send confirmed solves of new cases without pause."""
    import itertools
    import threading
    import time

    import yaml

    from tests.web_page import CASES

    data = yaml.safe_load((CASES / "wang2023-side-panel.yaml").read_text(encoding="utf-8"))
    stop = threading.Event()
    counter = itertools.count()

    def busy(name: str) -> None:
        seq = 0
        while not stop.is_set():
            seq += 1
            # a new case each time (an answer kept by case would come without a solve)
            case = {**data, "process": {**data["process"], "transfer_time_s": 1.0 + 1e-4 * next(counter)}}
            _post(url + "api/solve", {"session": name, "seq": seq, "case": case, "confirm": True})

    threads = [threading.Thread(target=busy, args=(f"burst-{k}",), daemon=True) for k in range(sessions)]
    for t in threads:
        t.start()
    time.sleep(3.0)  # the burst under way
    fast, confirmed = [], []
    for k in range(QUIET_EDITS):
        case = {**data, "key_points": {**data["key_points"], "draw_start_deg": 131.6 + 0.1 * k + 0.01 * sessions}}
        t = time.perf_counter()
        body = {"session": f"quiet-{sessions}", "seq": 2 * k, "case": case, "confirm": False}
        answer = _post(url + "api/solve", body)
        fast.append(time.perf_counter() - t)
        if not answer.get("confirmed"):
            answer = _post(url + "api/solve", {**body, "seq": 2 * k + 1, "confirm": True})
        confirmed.append(time.perf_counter() - t)
        assert answer["status"] == Outcome.VERIFIED, answer
        time.sleep(QUIET_PAUSE_S)
    stop.set()
    for t in threads:
        t.join(120)
    return fast, confirmed


def _median_p95(values: list[float]) -> tuple[float, float]:
    ordered = sorted(values)
    return statistics.median(ordered), ordered[min(len(ordered) - 1, int(round(0.95 * (len(ordered) - 1))))]


def _burst_text(bursts: dict[int, tuple[list[float], list[float]]]) -> str:
    parts = []
    for n, (fast, confirmed) in bursts.items():
        parts.append(
            f"while {n} other session{'s' if n > 1 else ''} send{'' if n > 1 else 's'} cold solves without "
            f"pause, a quiet session's edits ({QUIET_EDITS}, {QUIET_PAUSE_S:g} s apart; the first, with no plan "
            f"yet, a cold solve) get their fast answer in median {statistics.median(fast[1:]):.2f} s, at most "
            f"{max(fast[1:]):.2f} s (the first {fast[0]:.2f} s), the confirmed one in median "
            f"{statistics.median(confirmed):.2f} s, at most {max(confirmed):.2f} s"
        )
    return "Fair queues: " + "; ".join(parts) + " (target: a burst delays another session's edit by at most 2 s)."


def _compiled_in_background() -> float:
    """As ``pressplan serve`` does: compile the NLPs the page built (``planning.solver.background``); waits until
    none is left to compile and returns the seconds it took."""
    import time

    from planning.solver.background import BackgroundCompiler

    t_start = time.perf_counter()
    compiler = BackgroundCompiler(poll_s=0.1).start()
    try:
        while compiler.pending() and time.perf_counter() - t_start < 600:
            time.sleep(0.5)
    finally:
        compiler.close()
    return time.perf_counter() - t_start


def main() -> None:
    from tests.web_page import CASES, chromium, running_server, wait_rendered

    times, firsts, parts = [], [], []
    served_compiled = "--serve-compiles" in sys.argv  # the page after serve's background compile
    with running_server(CASES / "wang2023-side-panel.yaml") as url, chromium() as browser:
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        page.goto(url)
        wait_rendered(page)
        compile_s = _compiled_in_background() if served_compiled else None
        box = page.locator('[data-field="key_points.draw_start_deg"]')
        for k in range(1, EDITS + 1):
            before = int(page.evaluate("document.body.dataset.rendered"))
            box.fill(f"{131.5 + 0.1 * k:.1f}")
            start = page.evaluate(
                "() => { const t = performance.now(); "
                "document.querySelector('[data-field=\"key_points.draw_start_deg\"]')"
                ".dispatchEvent(new Event('change')); return t; }"
            )
            wait_rendered(page, before)
            assert page.evaluate("document.body.dataset.state") == "ready"
            times.append(page.evaluate("window.renderedAt") - start)
            firsts.append(page.evaluate("window.firstRenderedAt") - start)
            parts.append(page.evaluate("[window.solveSentAt, window.solveAnsweredAt, window.renderedAt]"))
            parts[-1] = [parts[-1][0] - start, parts[-1][1] - parts[-1][0], parts[-1][2] - parts[-1][1]]
        typed_first, typed = [], []
        for k in range(1, EDITS + 1):
            before = int(page.evaluate("document.body.dataset.rendered"))
            box.click()
            box.press("Control+A")
            # values not solved before (a kept answer would come at once)
            box.type(f"{133.55 - 0.1 * k:.2f}", delay=KEY_DELAY_MS)
            wait_rendered(page, before)
            last_key = page.evaluate("window.lastInputAt")
            typed_first.append(page.evaluate("window.firstRenderedAt") - last_key)
            typed.append(page.evaluate("window.renderedAt") - last_key)
        bursts = {n: burst(url, n) for n in (1, BURST_SESSIONS)}
    print("until sent, request to answer, answer to charts [ms]:", [[round(v) for v in p] for p in parts])
    first_median, first_p95 = _median_p95(firsts)
    median, p95 = _median_p95(times)
    typed_first_median, typed_first_p95 = _median_p95(typed_first)
    typed_median, typed_p95 = _median_p95(typed)
    from planning.solver.ipopt import BUILT

    compiled = any(solver.compiled for solver in list(BUILT))  # the NLPs from the cache (pressplan compile)
    how = "With the NLPs compiled (`pressplan compile`, `PRESSPLAN_CACHE` at its cache): " if compiled else ""
    if compile_s is not None:
        how = (
            f"With the NLPs compiled as `pressplan serve` compiles them in the background (`python "
            f"benchmarks/bench_web.py --serve-compiles`, an empty cache: done {compile_s:.0f} s after the page "
            "opened): "
        )
    section = (
        how + f"`pressplan serve`, published case, {EDITS} edits of θ2 in headless Chromium "
        "(`python benchmarks/bench_web.py`). Committed edits (a change event): to the first updated charts "
        f"(the fast answer from the plan before), median {first_median:.0f} ms, 95th percentile "
        f"{first_p95:.0f} ms; to the confirmed charts (the cold solve's plan or better), median {median:.0f} ms, "
        f"95th percentile {p95:.0f} ms. Typed (keys {KEY_DELAY_MS} ms apart), from the last key: to the first "
        f"charts median {typed_first_median:.0f} ms, 95th percentile {typed_first_p95:.0f} ms (target: median "
        f"≤ 300 ms, 95th percentile ≤ 600 ms); to the confirmed charts median {typed_median:.0f} ms, 95th "
        f"percentile {typed_p95:.0f} ms. {_burst_text(bursts)}"
    )
    write_section(*(COMPILED_MARKS if compiled else (BEGIN, END)), section)
    print(section)


if __name__ == "__main__":
    main()
