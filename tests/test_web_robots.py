"""The robots on the page (issue 39): their fields edited with real mouse and keyboard events in Chromium, the
tools' needed heights drawn on the slide's panel, robots added to and removed from a case."""

from __future__ import annotations

import pytest

from .web_page import CASES, browser_mark, chromium_profile, pick_case, running_server, wait_rendered

ROBOTS_CASE = CASES / "wang2023-side-panel-robots.yaml"

pytestmark = browser_mark()


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    with running_server(ROBOTS_CASE) as url, chromium_profile(tmp_path_factory.mktemp("chromium")) as browser:
        yield url, browser


@pytest.fixture
def page(site):
    url, browser = site
    context = browser.new_context(viewport={"width": 1280, "height": 1400})
    tab = context.new_page()
    errors: list[str] = []
    tab.on("pageerror", lambda e: errors.append(str(e)))
    tab.goto(url)
    wait_rendered(tab)
    tab.errors = errors
    yield tab
    context.close()


def click(tab, selector: str) -> None:  # noqa: ANN001 - a Playwright page
    """A real mouse click at the middle of ``selector``'s box, scrolled into view first."""
    target = tab.locator(selector)
    target.scroll_into_view_if_needed()
    box = target.bounding_box()
    tab.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)


def click_and_confirm(tab, selector: str) -> None:  # noqa: ANN001 - a Playwright page
    """A real mouse click on ``selector``, then the page's confirmed answer."""
    before = int(tab.evaluate("document.body.dataset.rendered"))
    click(tab, selector)
    wait_rendered(tab, before)
    tab.wait_for_function("state.last && state.last.confirmed && state.last.result", timeout=60_000)


def type_and_confirm(tab, selector: str, text: str) -> None:  # noqa: ANN001 - a Playwright page
    """A real mouse click into ``selector``, its text replaced by ``text`` typed, Tab; then the confirmed answer."""
    before = int(tab.evaluate("document.body.dataset.rendered"))
    click(tab, selector)
    tab.keyboard.press("Control+A")
    tab.keyboard.type(text)
    tab.keyboard.press("Tab")
    wait_rendered(tab, before)
    tab.wait_for_function("state.last && state.last.confirmed && state.last.result", timeout=60_000)


def spm(tab) -> float:  # noqa: ANN001
    return float(tab.evaluate("state.last.result.spm"))
@pytest.mark.slow  # the browser: about 10 s


def test_the_robots_fields_edit_the_plan(page) -> None:
    """The robots' section is on the form (no safety height, no transfer time), the chart draws each tool's
    needed height; a slower unloader typed in with the keyboard gives fewer strokes, verified."""
    assert page.locator('[data-field="robots.unloader.speed_mm_s"]').count() == 1
    assert page.locator('[data-field="process.safety_height_mm"]').count() == 0
    assert page.locator("#f-robots-unloader-interference_mm tbody tr").count() == 3
    names = page.evaluate("document.querySelector('#motion-chart').data.map((t) => t.name)")
    assert any(n.startswith("robots.unloader: the height its tool needs") for n in names), names
    assert any(n.startswith("robots.loader: the height its tool needs") for n in names), names
    chart = page.locator("#robots-chart")  # the interference chart: needs, least clearances, paths
    assert chart.is_visible()
    robots = page.evaluate("document.querySelector('#robots-chart').data.map((t) => t.name)")
    for name in ("unloader", "loader"):
        assert f"height the {name}'s tool needs [mm]" in robots
        assert f"{name}: least clearance 0.00 mm" in robots
        assert f"{name} on its path [mm from the die centre]" in robots
    fast = spm(page)
    type_and_confirm(page, '[data-field="robots.unloader.speed_mm_s"]', "2000")
    assert page.evaluate("state.last.result.verified")
    assert spm(page) < fast
    assert page.errors == []
@pytest.mark.slow  # the browser: about 6 s


def test_robots_added_and_removed(page) -> None:
    """The published case has no robots: "add robots" (a mouse click) gives it the template's two, verified;
    "remove the robots" gives the one-height model back, its 12.123 strokes/min."""
    pick_case(page, "wang2023-side-panel.yaml")
    assert page.locator('[data-field="robots.unloader.speed_mm_s"]').count() == 0
    click_and_confirm(page, "#add-robots")
    assert page.locator('[data-field="robots.loader.path_mm"]').count() == 1
    assert page.evaluate("state.last.result.verified") and page.evaluate("state.last.result.robots != null")
    click_and_confirm(page, "#remove-robots")
    assert page.evaluate("state.last.result.robots == null")
    assert not page.locator("#robots-chart").is_visible()
    assert round(spm(page), 3) == 12.123
    assert page.errors == []


def test_the_robots_form_fits_a_small_screen_with_a_bad_cell(site) -> None:
    """At 800x600 the robots' fieldsets fit the form's panel and the stage table the result's (no sideways
    scrolling), also with a bad cell
    typed into a curve's table (its message below the table, the table in place); each tool's need drawn down
    to zero where it leaves the die."""
    url, browser = site
    context = browser.new_context(viewport={"width": 800, "height": 600})
    tab = context.new_page()
    tab.goto(url)
    wait_rendered(tab)
    panel = "document.querySelector('#form-panel')"
    assert tab.evaluate(f"{panel}.scrollWidth <= {panel}.clientWidth")
    result = "document.querySelector('#result-panel')"  # the stage table's long binding names wrap
    assert tab.evaluate(f"{result}.scrollWidth <= {result}.clientWidth")
    table = "#f-robots-unloader-interference_mm"
    before_box = tab.locator(table).bounding_box()
    before = int(tab.evaluate("document.body.dataset.rendered"))
    click(tab, f"{table} tbody tr:nth-child(2) td:first-child input")
    tab.keyboard.press("Control+A")
    tab.keyboard.type("6o0")
    tab.keyboard.press("Tab")
    wait_rendered(tab, before)
    message = tab.locator('.msg[data-for="robots.unloader.interference_mm"]')
    assert "valid number" in message.inner_text()
    assert tab.evaluate(f"{panel}.scrollWidth <= {panel}.clientWidth")
    assert tab.locator(table).bounding_box()["x"] == before_box["x"]  # the table stays where it was
    needs = tab.evaluate(
        "document.querySelector('#robots-chart').data.filter((t) => t.name.startsWith('height the'))"
        ".map((t) => t.y.filter((v) => v !== null))"
    )
    assert needs and all(0 in ys for ys in needs)
    context.close()


@pytest.mark.slow  # 13 s of clicks; the fast tier adds and removes both robots (test_robots_added_and_removed)
def test_one_robot_removed_and_added_back(page) -> None:
    """"remove the loader" (a mouse click) plans the press with its unloader alone, verified, at least as fast;
    "add the loader" brings the template's back."""
    both = spm(page)
    click_and_confirm(page, "#remove-loader")
    assert page.locator('[data-field="robots.loader.path_mm"]').count() == 0
    assert page.evaluate("state.last.result.verified")
    assert [r["name"] for r in page.evaluate("state.last.result.robots.robots")] == ["unloader"]
    assert spm(page) >= both - 1e-9
    assert page.locator("#remove-unloader").count() == 0  # the last robot goes with "remove the robots"
    click_and_confirm(page, "#add-loader")
    assert page.locator('[data-field="robots.loader.path_mm"]').count() == 1
    assert page.evaluate("state.last.result.verified")
    assert page.errors == []
@pytest.mark.slow  # the browser: about 23 s


def test_robots_on_pendulum_strokes(site) -> None:
    """The shallow bracket's pendulum strokes with two robots: the page's strokes are the CLI's plan's, the
    interference chart marks each robot's least clearance in both windows; a longer loader dwell typed in after
    a mouse click gives the CLI's plan of that case, with fewer strokes."""
    from planning.model.case_file import case_from_data, load_yaml
    from planning.solver.pendulum import solve_pendulum

    path = CASES / "pendulum" / "shallow-pendulum-robots.yaml"
    data = load_yaml(path.read_text(encoding="utf-8"))
    _, browser = site  # (one Playwright a process: the module's browser, a server of this case)
    with running_server(path) as url:
        context = browser.new_context(viewport={"width": 1280, "height": 1400})
        tab = context.new_page()
        tab.goto(url)
        wait_rendered(tab)
        tab.wait_for_function("state.last && state.last.confirmed && state.last.result", timeout=60_000)
        solution = solve_pendulum(case_from_data(data, str(path)), compare=False)
        assert tab.locator("#spm").inner_text() == f"{solution.plan.spm:.3f}"
        names = tab.evaluate("document.querySelector('#robots-chart').data.map((t) => t.name)")
        for name in ("unloader at theta_e", "unloader at theta_s", "loader at theta_e", "loader at theta_s"):
            assert any(n.startswith(f"{name}: least clearance") for n in names), names
        assert sum(n.endswith("on its path [mm from the die centre]") for n in names) == 2
        type_and_confirm(tab, '[data-field="robots.loader.dwell_s"]', "0.1")
        data["robots"]["loader"]["dwell_s"] = 0.1
        slower = solve_pendulum(case_from_data(data, str(path)), compare=False)
        assert tab.locator("#spm").inner_text() == f"{slower.plan.spm:.3f}"
        assert slower.plan.spm < solution.plan.spm
        context.close()
