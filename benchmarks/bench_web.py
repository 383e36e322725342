"""Edit-to-chart latency of ``pressplan serve`` in a real browser; rewrites the web section of RESULTS.md.

The published case is opened in headless Chromium (Debian's ``chromium`` through Playwright), then
θ2 is edited 20 times (131.6 ... 133.5 deg); each time is measured in the page, from the change event
to the charts redrawn with the new plan (the server's warm re-solve included). Then θ2 is typed 20 times
as a user types it (the field's text selected, the new value's keys 80 ms apart, no change event): from
the last key's input event to the first chart and to the confirmed chart, typing's pause included. Run with
``python benchmarks/bench_web.py`` from the project root with the test extra installed.
"""

from __future__ import annotations

import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
EDITS = 20
BEGIN, END = "<!-- web:begin -->", "<!-- web:end -->"


KEY_DELAY_MS = 80  # between a typist's keys


def _median_p95(values: list[float]) -> tuple[float, float]:
    ordered = sorted(values)
    return statistics.median(ordered), ordered[min(len(ordered) - 1, int(round(0.95 * (len(ordered) - 1))))]


def main() -> None:
    from tests.web_page import CASES, chromium, running_server, wait_rendered

    times, firsts, parts = [], [], []
    with running_server(CASES / "wang2023-side-panel.yaml") as url, chromium() as browser:
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        page.goto(url)
        wait_rendered(page)
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
            box.type(f"{133.5 - 0.1 * k:.1f}", delay=KEY_DELAY_MS)
            wait_rendered(page, before)
            last_key = page.evaluate("window.lastInputAt")
            typed_first.append(page.evaluate("window.firstRenderedAt") - last_key)
            typed.append(page.evaluate("window.renderedAt") - last_key)
    print("until sent, request to answer, answer to charts [ms]:", [[round(v) for v in p] for p in parts])
    first_median, first_p95 = _median_p95(firsts)
    median, p95 = _median_p95(times)
    typed_first_median, typed_first_p95 = _median_p95(typed_first)
    typed_median, typed_p95 = _median_p95(typed)
    section = (
        f"{BEGIN}\n"
        f"`pressplan serve`, published case, {EDITS} edits of θ2 in headless Chromium "
        "(`python benchmarks/bench_web.py`). Committed edits (a change event): to the first updated charts "
        f"(the fast answer from the plan before), median {first_median:.0f} ms, 95th percentile "
        f"{first_p95:.0f} ms; to the confirmed charts (the cold solve's plan or better), median {median:.0f} ms, "
        f"95th percentile {p95:.0f} ms. Typed (keys {KEY_DELAY_MS} ms apart), from the last key: to the first "
        f"charts median {typed_first_median:.0f} ms, 95th percentile {typed_first_p95:.0f} ms (target: median "
        f"≤ 300 ms, 95th percentile ≤ 600 ms); to the confirmed charts median {typed_median:.0f} ms, 95th "
        f"percentile {typed_p95:.0f} ms.\n{END}"
    )
    results = ROOT / "benchmarks" / "RESULTS.md"
    text = results.read_text(encoding="utf-8")
    if BEGIN in text:
        head, rest = text.split(BEGIN)
        text = head + section + rest.split(END)[1]
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    results.write_text(text, encoding="utf-8")
    print(section)


if __name__ == "__main__":
    main()
