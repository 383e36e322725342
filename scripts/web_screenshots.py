"""Write the web page's screenshots in docs/: the published case (``web.png``), a drive case
(``web-drive.png``) and an error state (``web-error.png``: an infeasible transfer time), in headless
Chromium (Debian's, through Playwright).

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
    with running_server(CASES / "wang2023-side-panel.yaml") as url, chromium() as browser:
        page = browser.new_page(viewport={"width": 1400, "height": 1500})
        page.goto(url)
        wait_rendered(page)
        page.wait_for_function("document.querySelector('#bound-share').textContent.endsWith('%')", timeout=60_000)
        page.screenshot(path=docs / "web.png", full_page=True)
        edit(page, "process.transfer_time_s", "60")
        page.screenshot(path=docs / "web-error.png", full_page=True)
        before = int(page.evaluate("document.body.dataset.rendered"))
        page.select_option("#case-select", "wang2023-side-panel-drive.yaml")
        wait_rendered(page, before)
        page.wait_for_function("document.querySelector('#bound-share').textContent.endsWith('%')", timeout=60_000)
        page.screenshot(path=docs / "web-drive.png", full_page=True)
    print("wrote docs/web.png, docs/web-error.png, docs/web-drive.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
