"""Write the web page's screenshots in docs/: the published case (``web.png``), a drive case
(``web-drive.png``), an error state (``web-error.png``: an infeasible transfer time), and the published case
at three screen sizes (``web/page-WxH.png``), in headless Chromium (Debian's, through Playwright).

    python scripts/web_screenshots.py
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    from tests.web_page import CASES, chromium, edit, running_server, wait_rendered

    docs = ROOT / "docs"
    (docs / "web").mkdir(exist_ok=True)
    bounded = "document.querySelector('#bound-share').textContent.endsWith('%')"
    with running_server(CASES / "wang2023-side-panel.yaml") as url, chromium() as browser:
        for width, height in ((800, 600), (1280, 720), (1920, 1080)):
            page = browser.new_page(viewport={"width": width, "height": height})
            page.goto(url)
            wait_rendered(page)
            page.wait_for_function(bounded, timeout=60_000)
            page.screenshot(path=docs / "web" / f"page-{width}x{height}.png")
            page.close()
        page = browser.new_page(viewport={"width": 1400, "height": 900})
        page.goto(url)
        wait_rendered(page)
        page.wait_for_function(bounded, timeout=60_000)
        page.screenshot(path=docs / "web.png")
        edit(page, "process.transfer_time_s", "60")
        page.screenshot(path=docs / "web-error.png")
        before = int(page.evaluate("document.body.dataset.rendered"))
        page.select_option("#case-select", "wang2023-side-panel-drive.yaml")
        wait_rendered(page, before)
        page.wait_for_function(bounded, timeout=60_000)
        page.locator("#result-panel").evaluate("(el) => el.scrollTo(0, el.scrollHeight)")  # the drive's charts
        page.screenshot(path=docs / "web-drive.png")
    print("wrote docs/web.png, docs/web-error.png, docs/web-drive.png, docs/web/page-*.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
