"""Helpers of the browser tests and the web benchmark: the server in a thread, Chromium through Playwright.

Playwright's own browser download does not work on these machines: the tests launch Debian's
``chromium`` through ``executable_path``. Without it (or without Playwright) the browser tests skip
with the reason, except under CI (``CI=true``), where a missing browser fails them.
"""

from __future__ import annotations

import os
import shutil
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CASES = ROOT / "cases"
ARTIFACTS = ROOT / "tests" / "artifacts"  # screenshots of the browser tests (not in git)
RENDER_TIMEOUT_MS = 60_000


def chromium_path() -> str | None:
    """Debian's chromium (or ``PRESSPLAN_CHROMIUM``), None when there is none."""
    return os.environ.get("PRESSPLAN_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")


def missing_browser() -> str | None:
    """Why the browser tests cannot run here, None when they can."""
    try:
        import flask  # noqa: F401
        import playwright  # noqa: F401
        import plotly  # noqa: F401
    except ImportError as exc:
        return f"the web extra or Playwright is not installed ({exc.name})"
    if chromium_path() is None:
        return "no chromium (apt-get install -y chromium)"
    return None


def browser_mark():  # noqa: ANN201 - a pytest mark
    """The mark of a browser test: skipped with the reason where no browser can run, except under CI
    (``CI=true``), where a missing browser is an error."""
    import pytest

    why = missing_browser()
    if why is not None and os.environ.get("CI") == "true":
        raise RuntimeError(f"the browser tests must run in CI: {why}")
    return pytest.mark.skipif(why is not None, reason=why or "")


@contextmanager
def running_server(initial: Path | None = None, recipes: Path | None = None) -> Iterator[str]:
    """The app on a free port of 127.0.0.1 in a thread (with a recipes folder when given); yields its address."""
    from werkzeug.serving import make_server

    from planning.web.server import close_app, create_app

    app = create_app(CASES, initial, recipes_dir=recipes, cold_worker=True)  # as ``pressplan serve`` runs it
    server = make_server("127.0.0.1", 0, app, threaded=True)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_port}/"
    finally:
        server.shutdown()
        thread.join(timeout=10)
        close_app(app)


@contextmanager
def chromium() -> Iterator[object]:
    """A headless Chromium browser (Playwright)."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_path(), headless=True, args=["--no-sandbox"])
        try:
            yield browser
        finally:
            browser.close()


class _Tabs:
    """Pages of one profile with one viewport, opened and closed together (what a browser context offers the
    tests: the page keeps no cookies or storage, and each tab sends its own session id)."""

    def __init__(self, profile, viewport: dict | None):  # noqa: ANN001 - a Playwright BrowserContext
        self.profile, self.viewport, self.pages = profile, viewport, []

    def new_page(self):  # noqa: ANN201 - a Playwright page
        page = self.profile.new_page()
        if self.viewport:
            page.set_viewport_size(self.viewport)
        self.pages.append(page)
        return page

    def close(self) -> None:
        for page in self.pages:
            page.close()


class _Profile:
    """One persistent Chromium profile offering ``new_context`` as a browser does."""

    def __init__(self, profile):  # noqa: ANN001 - a Playwright BrowserContext
        self.profile = profile

    def new_context(self, viewport: dict | None = None, accept_downloads: bool = True) -> _Tabs:
        return _Tabs(self.profile, viewport)


@contextmanager
def chromium_profile(folder: Path) -> Iterator[_Profile]:
    """A headless Chromium with one persistent profile in ``folder``: its pages share the compiled-code
    cache, so a page after the second loads plotly.js in about 0.2 s instead of 1.3 s (the tests open about
    twenty pages). Downloads are accepted."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        profile = p.chromium.launch_persistent_context(
            str(folder),
            executable_path=chromium_path(),
            headless=True,
            args=["--no-sandbox"],
            accept_downloads=True,
        )
        try:
            yield _Profile(profile)
        finally:
            profile.close()


def wait_rendered(page, after: int = 0) -> int:  # noqa: ANN001 - a Playwright page
    """Wait until the page has answered an edit after number ``after`` with its confirmed answer (not the
    fast one it shows while confirming); returns the answer's number."""
    page.wait_for_function(
        f"Number(document.body.dataset.rendered) > {after} && "
        "!['solving', 'confirming'].includes(document.body.dataset.state)",
        timeout=RENDER_TIMEOUT_MS,
    )
    return int(page.evaluate("document.body.dataset.rendered"))


def pick_case(page, name: str) -> int:  # noqa: ANN001 - a Playwright page
    """Pick case ``name`` in the page's case list; returns the number of its answer."""
    before = int(page.evaluate("document.body.dataset.rendered"))
    page.select_option("#case-select", name)
    return wait_rendered(page, before)


def edit(page, field: str, value: str) -> int:  # noqa: ANN001 - a Playwright page
    """Type ``value`` into the form's ``field`` and leave it (a change); returns the number of the answer."""
    before = int(page.evaluate("document.body.dataset.rendered"))
    box = page.locator(f'[data-field="{field}"]')
    box.fill(value)
    box.dispatch_event("change")
    return wait_rendered(page, before)
