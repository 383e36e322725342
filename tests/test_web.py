"""``pressplan serve`` in a real browser: Chromium headless through Playwright (see tests/web_page.py).

Every number the page shows is compared with what the CLI gives for the same case, and the downloaded
files with what ``pressplan solve`` writes."""

from __future__ import annotations

import copy
import io
import json
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from planning.model.case_file import case_from_data, load_yaml, read_case
from planning.model.outcome import Outcome
from planning.reports.law_comparison import LAWS_UPPER_PIECES, LAWS_UPPER_POINTS
from planning.reports.report import result_dict
from planning.solver.optimize import solve
from planning.solver.upper_bound import upper_bound

from .web_page import ARTIFACTS, CASES, browser_mark, chromium_profile, edit, pick_case, running_server, wait_rendered

PUBLISHED = CASES / "wang2023-side-panel.yaml"
LABEL = "cases/wang2023-side-panel.yaml"

browser = browser_mark()


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    with running_server(PUBLISHED) as url, chromium_profile(tmp_path_factory.mktemp("chromium")) as browser:
        yield url, browser


@pytest.fixture
def page(site):
    url, browser = site
    context = browser.new_context(viewport={"width": 1400, "height": 1000}, accept_downloads=True)
    tab = context.new_page()
    tab.goto(url)
    wait_rendered(tab)
    yield tab
    context.close()


def published_data() -> dict:
    return load_yaml(PUBLISHED.read_text(encoding="utf-8"))


def cli_numbers(data: dict) -> dict:
    """What the CLI's solve gives for ``data``: the numbers the page shows, formatted as it shows them."""
    case = case_from_data(data, LABEL)
    result = result_dict(solve(case), case)
    return {
        "spm": f"{result['spm']:.3f}",
        "cycle": f"{result['cycle_time_s']:.4f}",
        "binding": ", ".join(result["binding_constraints"]) or "none",
        "key_points": [
            [
                k["name"],
                f"{k['angle_deg']:.2f}",
                f"{k['time_s']:.4f}",
                f"{k['height_mm']:.1f}",
                f"{k['slider_speed_mm_s']:.1f} {k['direction']}",
                f"{k['crank_speed_rpm']:.3f}",
            ]
            for k in result["key_points"]
        ],
        "status": f"{result['motion_law']}, {result['placement']} placement, verified: every limit holds on the "
        f"dense {result['verification']['step_s'] * 1e3:.3f} ms grid",
    }


def shown_numbers(tab) -> dict:  # noqa: ANN001 - a Playwright page
    rows = tab.locator("#key-points tbody tr").all()
    return {
        "spm": tab.locator("#spm").inner_text(),
        "cycle": tab.locator("#cycle").inner_text(),
        "binding": tab.locator("#binding").inner_text(),
        "key_points": [[c.inner_text() for c in row.locator("td").all()] for row in rows],
        "status": tab.locator("#status").inner_text(),
    }


def screenshot(tab, name: str) -> None:  # noqa: ANN001
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    tab.screenshot(path=str(ARTIFACTS / f"{name}.png"), full_page=True)


@pytest.mark.slow  # the slow tier keeps the fast one under 5 minutes
@browser
def test_page_shows_what_the_cli_gives_and_follows_an_edit(page) -> None:
    assert page.locator("#case-label").inner_text() == LABEL
    assert shown_numbers(page) == cli_numbers(published_data())
    # the share of the certified upper bound follows once the edits rest, as `pressplan laws` computes it
    page.wait_for_function("document.querySelector('#bound-share').textContent.endsWith('%')", timeout=60_000)
    case = case_from_data(published_data(), LABEL)
    share = 100 * solve(case).plan.spm / upper_bound(case, LAWS_UPPER_POINTS, LAWS_UPPER_PIECES).spm
    assert page.locator("#bound-share").inner_text() == f"{share:.1f} %"
    screenshot(page, "web-published")
    edit(page, "key_points.draw_start_deg", "133")
    data = published_data()
    data["key_points"]["draw_start_deg"] = 133.0
    assert shown_numbers(page) == cli_numbers(data)
    assert page.locator("#status").get_attribute("class") == "status "
    # pin, edit again: the page overlays the pinned plan and states the difference
    page.locator("#pin").click()
    edit(page, "process.transfer_time_s", "2.5")
    data["process"]["transfer_time_s"] = 2.5
    shown = shown_numbers(page)
    assert shown == cli_numbers(data)
    assert "pinned" in page.locator("#pin-line").inner_text()
    page.locator("#x-axis").select_option("time")
    page.wait_for_function("document.querySelector('#bound-share').textContent.endsWith('%')", timeout=60_000)
    screenshot(page, "web-pinned-time")


@browser
def test_a_bad_value_shows_the_cli_line_next_to_the_field(page, tmp_path: Path) -> None:
    good = page.locator("#spm").inner_text()
    edit(page, "limits.slider_accel_mm_s2", "-5")
    message = page.locator('.msg[data-for="limits.slider_accel_mm_s2"]').inner_text()
    # the CLI on the same edit: the same line after the file's name
    data = published_data()
    data["limits"]["slider_accel_mm_s2"] = -5  # as typed
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data), encoding="utf-8")
    cli = subprocess.run(
        [sys.executable, "-m", "planning.cli", "solve", str(bad), "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
    )
    assert cli.returncode == 2
    assert message == LABEL + cli.stderr.strip().removeprefix(f"pressplan: {bad}")
    assert page.locator("#spm").inner_text() == good  # the last good plan stays on screen
    assert "bad" in (page.locator('[data-field="limits.slider_accel_mm_s2"]').get_attribute("class") or "")
    screenshot(page, "web-bad-value")
    edit(page, "limits.slider_accel_mm_s2", "abc")
    assert (
        "limits.slider_accel_mm_s2: input should be a valid number"
        in page.locator('.msg[data-for="limits.slider_accel_mm_s2"]').inner_text()
    )


@browser
def test_an_upload_too_large_shows_the_servers_message(page) -> None:
    """A file larger than a case may be: the page says so with the CLI's words for a case file (it used to
    parse an HTML page and show nothing, then logged the server's 413 in the console), and keeps its case."""
    from planning.model.case_file import MAX_BYTES, too_large_words
    from planning.web.server import MAX_REQUEST_BYTES

    logged = []
    page.on("console", lambda message: logged.append(message.text))
    page.set_input_files(
        "#upload", files=[{"name": "huge.yaml", "mimeType": "text/yaml", "buffer": b"#" * (MAX_REQUEST_BYTES + 10)}]
    )
    page.wait_for_function("document.querySelector('#load-message').textContent.length > 0", timeout=10_000)
    assert page.locator("#load-message").inner_text() == f"huge.yaml: {too_large_words()}"
    assert str(MAX_BYTES) in too_large_words() and logged == []
    assert page.locator("#case-label").inner_text() == LABEL  # the case on screen is still the one shown


@browser
def test_an_infeasible_case_shows_the_limit(page) -> None:
    edit(page, "process.transfer_time_s", "60")
    status = page.locator("#status").inner_text()
    assert status.startswith(f"{LABEL}: infeasible: process.transfer_time_s = 60 cannot be met")
    assert status.endswith("(the limit: process.transfer_time_s)")
    assert "cannot be met" in page.locator('.msg[data-for="process.transfer_time_s"]').inner_text()


@browser
def test_downloads_equal_the_files_of_solve(page, tmp_path: Path) -> None:
    edit(page, "key_points.draw_end_deg", "200")
    data = published_data()
    data["key_points"]["draw_end_deg"] = 200.0
    case_file = tmp_path / "edited.yaml"
    case_file.write_text(yaml.safe_dump(data), encoding="utf-8")
    out = tmp_path / "solve"
    cli = subprocess.run(
        [sys.executable, "-m", "planning.cli", "solve", str(case_file), "--no-plots", "--out", str(out)]
    )
    assert cli.returncode == 0
    got = {}
    for name in ("cam_table.csv", "trajectory.csv", "result.json", "case.yaml"):
        button = page.locator("#download-case") if name == "case.yaml" else page.locator(f'[data-download="{name}"]')
        with page.expect_download(timeout=60_000) as info:
            button.click()
        path = tmp_path / f"page-{name}"
        info.value.save_as(path)
        got[name] = path.read_bytes()
    assert got["cam_table.csv"] == (out / "cam_table.csv").read_bytes()
    assert got["trajectory.csv"] == (out / "trajectory.csv").read_bytes()
    page_result, cli_result = json.loads(got["result.json"]), json.loads((out / "result.json").read_text())
    for r in (page_result, cli_result):
        # how the search went, not what it found (the page's plan counts the confirming search's starts too)
        r["solver"] = None
    assert page_result == cli_result
    assert yaml.safe_load(got["case.yaml"])["key_points"]["draw_end_deg"] == 200.0
    # the stage table: result.json's stages as the page prints them, and the limits that bind over the cycle
    shown = [[c.inner_text() for c in row.locator("td").all()] for row in page.locator("#stages tbody tr").all()]
    expected = [
        [
            st["name"],
            f"{st['start_angle_deg']:.2f}",
            f"{st['end_angle_deg']:.2f}",
            f"{st['start_time_s']:.4f}",
            f"{st['duration_s']:.4f}",
            f"{st['peak_crank_speed_rpm']:.3f}",
            ", ".join(st["binding"]) or "–",
        ]
        for st in cli_result["stages"]
    ]
    assert shown[: len(expected)] == expected and len(expected) == 4
    assert shown[len(expected) :] == [["the cycle", "", ", ".join(cli_result["binding_over_cycle"])]]


@pytest.mark.slow  # the browser: about 4 s
@browser
def test_two_pages_stay_separate(site) -> None:
    url, browser = site
    tabs, contexts = [], []
    for _ in range(2):
        context = browser.new_context(viewport={"width": 1200, "height": 900})
        tab = context.new_page()
        tab.goto(url)
        wait_rendered(tab)
        tabs.append(tab)
        contexts.append(context)
    a, b = tabs
    # edits in both before either answer is read: each page keeps its own case and plan
    a.locator('[data-field="key_points.draw_start_deg"]').fill("134")
    b.locator('[data-field="process.transfer_time_s"]').fill("3")
    before_a, before_b = (int(t.evaluate("document.body.dataset.rendered")) for t in tabs)
    a.locator('[data-field="key_points.draw_start_deg"]').dispatch_event("change")
    b.locator('[data-field="process.transfer_time_s"]').dispatch_event("change")
    wait_rendered(a, before_a)
    wait_rendered(b, before_b)
    data_a, data_b = published_data(), published_data()
    data_a["key_points"]["draw_start_deg"] = 134.0
    data_b["process"]["transfer_time_s"] = 3.0
    assert shown_numbers(a) == cli_numbers(data_a)
    assert shown_numbers(b) == cli_numbers(data_b)
    assert shown_numbers(a)["spm"] != shown_numbers(b)["spm"]
    for context in contexts:
        context.close()


@pytest.mark.slow  # the browser: about 9 s
@browser
def test_a_drive_case_shows_its_motor(site) -> None:
    url, browser = site
    context = browser.new_context(viewport={"width": 1400, "height": 1200})
    tab = context.new_page()
    tab.goto(url)
    wait_rendered(tab)
    pick_case(tab, "cup-2000kN-drive.yaml")
    data = load_yaml((CASES / "cup-2000kN-drive.yaml").read_text(encoding="utf-8"))
    expected = cli_numbers(copy.deepcopy(data))
    assert tab.locator("#spm").inner_text() == expected["spm"]
    assert "% of rated" in tab.locator("#drive-line").inner_text()
    assert tab.locator("#drive-chart .main-svg").count() > 0
    # the objective at the line's rate, chosen in the form: without a rate the field says so
    before = int(tab.evaluate("document.body.dataset.rendered"))
    tab.locator('[data-field="planner.objective"]').select_option("min-energy")
    wait_rendered(tab, before)
    assert "needs the line's rate" in tab.locator('.msg[data-for="planner.target_spm"]').inner_text()
    edit(tab, "planner.target_spm", "30")
    assert tab.locator("#spm").inner_text() == "30.000"
    assert tab.locator("#objective-line").inner_text().startswith("min-energy at 30 SPM")
    assert not tab.locator("#energy-chart").is_visible()  # no electrical side stated, nor the grid's objective
    screenshot(tab, "web-drive")
    # the least grid peak: the grid's side is computed, its chart shown with the CLI's grid peak
    before = int(tab.evaluate("document.body.dataset.rendered"))
    tab.locator('[data-field="planner.objective"]').select_option("min-grid-peak")
    wait_rendered(tab, before)
    data["planner"].update(objective="min-grid-peak", target_spm=30.0)
    expected = solve(case_from_data(copy.deepcopy(data), "cases/cup-2000kN-drive.yaml")).drive.power.grid_peak_kW
    line = tab.locator("#objective-line").inner_text()
    assert line.startswith("min-grid-peak at 30 SPM") and f"→ {expected:.0f} kW" in line, line
    assert tab.locator("#energy-chart .main-svg").count() > 0
    names = tab.evaluate("Array.from(document.querySelector('#energy-chart').data, (t) => t.name)")
    assert f"grid power [kW] (peak {expected:.0f} kW)" in names and any(n.startswith("mean bus power") for n in names)
    screenshot(tab, "web-energy")
    context.close()


@pytest.mark.slow  # the browser: about 7 s
@browser
def test_a_linkage_case_shows_its_mechanism_and_follows_a_geometry_edit(site) -> None:
    """The link drive: its own fields (not the crank-slider's), a drawing of the linkage that follows the
    crank angle, and an edit of a link's dimension solved as the CLI solves it."""
    url, browser = site
    context = browser.new_context(viewport={"width": 1400, "height": 1200})
    tab = context.new_page()
    tab.goto(url)
    wait_rendered(tab)
    pick_case(tab, "link-drive-side-panel.yaml")
    data = load_yaml((CASES / "link-drive-side-panel.yaml").read_text(encoding="utf-8"))
    label = "cases/link-drive-side-panel.yaml"
    assert tab.locator("#spm").inner_text() == f"{solve(case_from_data(copy.deepcopy(data), label)).plan.spm:.3f}"
    assert tab.locator('[data-field="press.link_drive.rocker_mm"]').input_value() == "810"
    assert tab.locator('[data-field="press.crank_radius_mm"]').count() == 0
    assert tab.locator('[data-field="drive.rod_mass_kg"]').count() == 0
    assert tab.locator('[data-field="press.mechanism"]').input_value() == "link-drive"
    svg = tab.locator("#mechanism-svg")
    assert svg.locator("line.bar").count() == 3 and svg.locator("polygon.bar").count() == 1  # the ternary link
    assert svg.locator("circle.joint.fixed").count() == 2  # the crank centre and the rocker's pivot
    tab.locator("#crank-angle").fill("150")
    tab.locator("#crank-angle").dispatch_event("input")
    assert float(svg.get_attribute("data-angle")) == 150.0
    edit(tab, "press.link_drive.rocker_pivot_y_mm", "380")
    data["press"]["link_drive"]["rocker_pivot_y_mm"] = 380.0
    assert tab.locator("#spm").inner_text() == f"{solve(case_from_data(copy.deepcopy(data), label)).plan.spm:.3f}"
    screenshot(tab, "web-link-drive")
    context.close()


# ---- the server without a browser (Flask's test client) ------------------------------------------------


def test_uploads_and_requests_are_checked() -> None:
    pytest.importorskip("flask")
    from planning.web.server import MAX_REQUEST_BYTES, create_app

    client = create_app(CASES).test_client()
    big = b"name: x\n" + b"#" * 300_000
    answer = client.post("/api/upload", data={"file": (io.BytesIO(big), "big.yaml")})
    assert answer.status_code == 200 and answer.get_json()["status"] == Outcome.BAD_INPUT  # a refused case: an answer
    assert answer.get_json()["message"] == "big.yaml: too large for a case file (more than 256000 bytes)"
    ok = client.post("/api/upload", data={"file": (io.BytesIO(PUBLISHED.read_bytes()), "mine.yaml")})
    assert "case" in ok.get_json() and ok.get_json()["label"] == "mine.yaml"
    bad = client.post("/api/upload", data={"file": (io.BytesIO(b"a: [1,\n"), "broken.yaml")})
    assert bad.status_code == 200 and bad.get_json()["message"].startswith("broken.yaml: YAML syntax error")
    assert client.get("/api/case/..%2Fpyproject.toml").status_code == 404  # names are looked up, never paths
    assert client.get("/static/../pyproject.toml").status_code == 404
    too_much = client.post("/api/solve", data=b"{" + b" " * MAX_REQUEST_BYTES + b"}", content_type="application/json")
    assert too_much.status_code == 413


def test_serve_without_the_web_extra_says_what_to_install(monkeypatch, capsys) -> None:
    from planning.cli import main

    monkeypatch.setitem(sys.modules, "flask", None)  # import flask now fails
    monkeypatch.delitem(sys.modules, "planning.web.server", raising=False)
    assert main(["serve"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "pressplan: serve needs the web extra: pip install -e '.[web]' (flask is missing)"


def test_a_newer_edit_supersedes_a_waiting_one() -> None:
    """While a tab's solve runs, a second request waits; a third, newer one makes the second return at once
    as superseded, so work never queues up behind a user's typing."""
    pytest.importorskip("flask")
    import threading

    from planning.web.server import create_app

    app = create_app(CASES)
    client = app.test_client()
    data = published_data()
    session = app.extensions["pressplan_sessions"].get("tab-1")
    answers: dict[int, dict] = {}

    def send(seq: int) -> None:
        body = {"session": "tab-1", "seq": seq, "label": LABEL, "case": data}
        answers[seq] = client.post("/api/solve", json=body).get_json()

    with session.lock:  # a solve of this tab is running
        first = threading.Thread(target=send, args=(1,))
        first.start()
        while session.newest < 1:
            pass
        second = threading.Thread(target=send, args=(2,))
        second.start()
        while session.newest < 2:
            pass
    first.join(60)
    second.join(60)
    assert answers[1]["status"] == Outcome.INTERRUPTED
    assert answers[2]["status"] == Outcome.VERIFIED and answers[2]["seq"] == 2
    other = create_app(CASES).test_client()  # another tab's plan is its own
    answer = other.post("/api/solve", json={"session": "tab-2", "seq": 1, "case": data}).get_json()
    assert answer["status"] == Outcome.VERIFIED


def test_every_error_is_json_with_a_4xx() -> None:
    """Deep nesting, a body too large, malformed JSON, an unknown route, a wrong method: each a JSON answer
    with its 4xx and a message, never a 500 or an HTML page (the page shows the message)."""
    pytest.importorskip("flask")
    from planning.web.server import MAX_REQUEST_BYTES, create_app

    client = create_app(CASES).test_client()
    deep = b"[" * 1000 + b"]" * 1000  # 2 kB: past Python's recursion limit if it were parsed
    for url in ("/api/solve", "/api/bound", "/api/download/result.json"):
        answer = client.post(url, data=deep, content_type="application/json")
        assert answer.status_code == 400 and "nests deeper" in answer.get_json()["message"], url
        answer = client.post(url, data=b'{"case": ', content_type="application/json")
        assert answer.status_code == 400 and answer.get_json()["message"] == "the request's body is not JSON", url
        answer = client.post(url, data=b"[1, 2]", content_type="application/json")
        assert answer.status_code == 400 and "not a JSON object" in answer.get_json()["message"], url
    too_big = client.post("/api/solve", data=b"{" + b" " * MAX_REQUEST_BYTES + b"}", content_type="application/json")
    assert too_big.status_code == 413 and "too large" in too_big.get_json()["message"]
    upload = client.post("/api/upload", data={"file": (io.BytesIO(b"#" * (MAX_REQUEST_BYTES + 10)), "big.yaml")})
    assert upload.status_code == 413 and upload.get_json()["status"] == Outcome.BAD_INPUT
    assert client.get("/api/nothing").status_code == 404 and client.get("/api/nothing").get_json()["message"]
    wrong = client.get("/api/solve")
    assert wrong.status_code == 405 and wrong.get_json()["status"] == Outcome.BAD_INPUT
    quoted = client.post("/api/solve", json={"session": "s", "case": {"name": 'a "]]]] [[[' + "[" * 40}})
    assert quoted.status_code == 200  # brackets inside strings do not count as nesting


def test_only_this_machines_names_are_served() -> None:
    """DNS rebinding: a request naming another host is refused; this machine's names and the bound
    address are served; bound to every address (--host 0.0.0.0), every name is."""
    pytest.importorskip("flask")
    from planning.web.server import create_app

    client = create_app(CASES).test_client()
    assert client.get("/api/meta", headers={"Host": "evil.example:8050"}).status_code == 403
    for host in ("localhost:8050", "127.0.0.1:8050", "[::1]:8050", "localhost"):
        assert client.get("/api/meta", headers={"Host": host}).status_code == 200, host
    lan = create_app(CASES, allowed_hosts=("192.168.1.20",)).test_client()
    assert lan.get("/api/meta", headers={"Host": "192.168.1.20:8050"}).status_code == 200
    assert lan.get("/api/meta", headers={"Host": "evil.example"}).status_code == 403
    everyone = create_app(CASES, allowed_hosts=("0.0.0.0",)).test_client()
    assert everyone.get("/api/meta", headers={"Host": "press-7.plant.local:8050"}).status_code == 200


def test_a_download_is_the_confirmed_plan_on_screen_without_a_solve(monkeypatch) -> None:
    """The files come from the plan the page shows once confirmed: no solve runs for a download (a solve
    would fail the test), a case whose plan is not on screen is refused with a message."""
    pytest.importorskip("flask")
    import planning.solver.optimize as optimize
    from planning.web.server import create_app

    client = create_app(CASES).test_client()
    data = published_data()
    body = {"session": "tab", "label": LABEL, "case": data}
    early = client.post("/api/download/result.json", json=body)
    assert early.status_code == 409 and "no confirmed plan" in early.get_json()["message"]
    answer = client.post("/api/solve", json={**body, "seq": 1, "confirm": True}).get_json()
    assert answer["status"] == Outcome.VERIFIED and answer["confirmed"]

    def no_solve(*args, **kwargs):
        raise AssertionError("a download solved the case again")

    monkeypatch.setattr(optimize, "solve", no_solve)
    got = client.post("/api/download/result.json", json=body)
    assert got.status_code == 200 and json.loads(got.data)["spm"] == answer["result"]["spm"]
    other = {**body, "case": {**data, "process": {**data["process"], "transfer_time_s": 2.5}}}
    assert client.post("/api/download/trajectory.csv", json=other).status_code == 409


@browser
def test_the_charts_draw_every_limit_of_the_case_and_the_robot_window(page) -> None:
    """On the servo-limited case (crank speed, acceleration and jerk bind) every limit of the case is a
    named line on the charts (the figures' own lines), the robot window is shaded with its time written."""
    pick_case(page, "side-panel-servo-limits.yaml")
    for box in page.locator("[data-panel]").all():  # every panel shown (four are by default)
        box.check()
    names = page.evaluate("document.getElementById('motion-chart').data.map((t) => t.name)")
    case = read_case(CASES / "side-panel-servo-limits.yaml")
    set_limits = [f"limits.{k}" for k, v in case.limits.model_dump().items() if v is not None]
    fields = ["process.safety_height_mm", *set_limits]
    missing = [f for f in fields if not any(str(n).startswith(f) for n in names)]
    assert not missing, missing
    assert "crank jerk [rad/s³]" in names
    notes = page.evaluate("document.getElementById('motion-chart').layout.annotations.map((a) => a.text)")
    assert any("window" in n and "2.000 s" in n for n in notes), notes  # shortened where the shading is narrow
    assert "draw θ2 → θ3" in notes  # the draw's shading named too
    screenshot(page, "web-limits")


@browser
def test_the_pin_is_cleared_on_a_case_change(page) -> None:
    page.locator("#pin").click()
    assert page.locator("#pin-line").inner_text().startswith("pinned 12.123 SPM")
    pick_case(page, "small-fast-cup.yaml")
    assert page.locator("#pin-line").inner_text() == ""
    names = page.evaluate("document.getElementById('motion-chart').data.map((t) => t.name)")
    assert not any(str(n).startswith("pinned") for n in names)


@browser
def test_typing_alone_solves_once_the_keys_pause(page) -> None:
    """No change event: the keys alone solve once they pause; the status says so from the first key."""
    before = int(page.evaluate("document.body.dataset.rendered"))
    spm = float(page.locator("#spm").inner_text())
    page.evaluate(
        "window.statuses = []; new MutationObserver(() => window.statuses.push(document.querySelector('#status')"
        ".textContent)).observe(document.querySelector('#status'), { childList: true, characterData: true, "
        "subtree: true })"
    )
    box = page.locator('[data-field="process.transfer_time_s"]')
    box.click()
    box.press("Control+A")
    box.type("1.5", delay=30)
    wait_rendered(page, before)
    statuses = page.evaluate("window.statuses")
    assert statuses[0].startswith("editing"), statuses  # pending from the first key, before any solve
    assert float(page.locator("#spm").inner_text()) > spm + 0.5  # a shorter transfer: more strokes


@browser
def test_the_page_shows_the_clis_summary_lines(page, tmp_path: Path, capsys) -> None:
    from planning.cli import main

    assert main(["solve", str(PUBLISHED), "--no-plots", "--out", str(tmp_path / "o")]) == 0
    cli = [line for line in capsys.readouterr().out.splitlines() if not line.lstrip().startswith(("solver:", "wrote"))]
    page.locator("#summary").locator("xpath=..").locator("summary").click()  # the summary unfolded
    shown = [line for line in page.locator("#summary").inner_text().splitlines() if "solver:" not in line]
    assert shown == cli


@browser
def test_objectives_that_weigh_the_motor_are_offered_only_with_a_drive(page) -> None:
    option = 'select[data-field="planner.objective"] option[value="min-energy"]'
    assert page.locator(option).is_disabled()
    assert "needs a drive" in page.locator(option).get_attribute("title")
    pick_case(page, "wang2023-side-panel-drive.yaml")
    assert not page.locator(option).is_disabled()


@browser
def test_an_infeasible_upload_shows_the_new_case_and_no_old_plan(page, tmp_path: Path) -> None:
    data = published_data()
    data["name"] = "too-long-a-transfer"
    data["process"]["transfer_time_s"] = 60
    page.set_input_files(
        "#upload", files=[{"name": "long.yaml", "mimeType": "text/yaml", "buffer": yaml.safe_dump(data).encode()}]
    )
    page.wait_for_function("document.body.dataset.state === 'infeasible'", timeout=30_000)
    assert page.locator("#case-label").inner_text() == "long.yaml"
    assert "process.transfer_time_s = 60" in page.locator("#status").inner_text()
    assert page.locator("#spm").inner_text() == "–" and page.locator("#key-points tbody tr").count() == 0


def _children(pid: int) -> set[int]:
    """Every process below ``pid`` (from /proc)."""
    found, frontier = set(), {pid}
    while frontier:
        parents, frontier = frontier, set()
        for stat in Path("/proc").glob("[0-9]*/stat"):
            try:
                fields = stat.read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) in parents:
                child = int(stat.parent.name)
                if child not in found:
                    found.add(child)
                    frontier.add(child)
    return found


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc")
def test_sigterm_stops_the_server_and_every_process_it_started(tmp_path: Path) -> None:
    """The bound's worker process (and what it started) ends with the server on SIGTERM (exit 143)."""
    pytest.importorskip("flask")
    import signal
    import socket
    import time
    import urllib.request

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    root = Path(__file__).resolve().parents[1]
    server = subprocess.Popen(
        [sys.executable, "-m", "planning.cli", "serve", "--port", str(port)],
        cwd=root,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert "serving on" in server.stdout.readline()
        body = json.dumps({"label": LABEL, "case": published_data()}).encode()
        request = urllib.request.Request(
            f"http://127.0.0.1:{port}/api/bound", data=body, headers={"Content-Type": "application/json"}
        )
        for _ in range(50):  # the server may take a moment to listen
            try:
                answer = json.loads(urllib.request.urlopen(request, timeout=60).read())
                break
            except OSError:
                time.sleep(0.1)
        assert answer["upper_spm"] > 0
        workers = _children(server.pid)
        assert workers  # the bound ran in a worker process
        server.send_signal(signal.SIGTERM)
        assert server.wait(timeout=20) == 143
        assert "leaked semaphore" not in server.stderr.read()  # the bound's pool closed, queues and all
        deadline = time.time() + 10
        while time.time() < deadline and any(Path(f"/proc/{p}").exists() for p in workers):
            time.sleep(0.1)
        alive = [p for p in workers if Path(f"/proc/{p}").exists() and "Z" not in _state(p)]
        assert not alive, alive
    finally:
        if server.poll() is None:
            server.kill()


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "gone"


def test_a_burst_of_other_sessions_never_queues_ahead_of_a_quiet_one() -> None:
    """The fair queue: while one solve runs, ten busy sessions (each solved before) and a quiet one wait;
    the quiet one starts next, so a burst delays it by the running solve only. A session's older waiting
    request is superseded by its newer one."""
    pytest.importorskip("flask")
    import threading

    from planning.web.server import SUPERSEDED, FairQueue

    queue = FairQueue(slots=1)
    started: list[str] = []
    busy = [f"burst-{k}" for k in range(10)]
    for name in busy:  # each busy session has had its turn
        queue.run(name, 0, lambda name=name: started.append(name))
    release = threading.Event()
    results: dict[str, object] = {}

    def send(name: str, seq: int, work) -> None:  # noqa: ANN001
        results[f"{name}#{seq}"] = queue.run(name, seq, work)

    def record(name: str):  # noqa: ANN202
        return lambda: started.append(name) or name

    running = threading.Thread(target=send, args=("burst-0", 1, lambda: release.wait(30) and started.append("held")))
    running.start()
    while "held" not in started and not queue._running:  # noqa: SLF001 - the held solve has started
        pass
    threads = [threading.Thread(target=send, args=(name, 1, record(name))) for name in busy[1:]]
    for t in threads:
        t.start()
    while len(queue._waiting) < len(busy) - 1:  # noqa: SLF001
        pass
    quiet = threading.Thread(target=send, args=("quiet", 1, record("quiet")))
    quiet.start()
    older = threading.Thread(target=send, args=("burst-5", 0, record("never")))  # older than its waiting one
    older.start()
    older.join(5)
    while "quiet" not in queue._waiting:  # noqa: SLF001
        pass
    release.set()
    for t in (running, *threads, quiet):
        t.join(30)
    after = started[len(busy) + 1 :]
    assert after[0] == "quiet", after
    assert sorted(after[1:]) == sorted(busy[1:])
    assert results["burst-5#0"] is SUPERSEDED and "never" not in started


def test_an_edits_fast_answer_never_waits_behind_cold_solves() -> None:
    """Both cold slots held by other sessions' solves: a session with a plan still gets its edit's fast
    answer (the cold queue and the fast queue are apart)."""
    pytest.importorskip("flask")
    import threading

    from planning.web.server import SOLVES_AT_ONCE, create_app

    app = create_app(CASES)
    client = app.test_client()
    data = published_data()
    first = client.post("/api/solve", json={"session": "quiet", "seq": 1, "case": data, "confirm": True})
    assert first.get_json()["status"] == Outcome.VERIFIED
    sessions = app.extensions["pressplan_sessions"]
    held = [sessions.get(f"busy-{k}") for k in range(SOLVES_AT_ONCE)]
    threads = []
    for k, session in enumerate(held):
        session.lock.acquire()  # its cold solve has its slot and cannot go on
        body = {"session": f"busy-{k}", "seq": 1, "case": data, "confirm": True}
        threads.append(threading.Thread(target=client.post, args=("/api/solve",), kwargs={"json": body}))
        threads[-1].start()
    cold = app.extensions["pressplan_queues"]["cold"]
    while len(cold._running) < SOLVES_AT_ONCE:  # noqa: SLF001 - both slots taken
        pass
    edited = {**data, "process": {**data["process"], "transfer_time_s": 1.9}}
    answer = client.post("/api/solve", json={"session": "quiet", "seq": 2, "case": edited}).get_json()
    for session in held:
        session.lock.release()
    for t in threads:
        t.join(60)
    assert answer["status"] == Outcome.VERIFIED and answer["confirmed"] is False


def test_every_field_has_words_a_unit_and_help() -> None:
    """The form's labels: each field's title (with its unit where the key carries one) and a help text,
    from the case model; no field shows its raw key."""
    pytest.importorskip("flask")
    from planning.web.server import field_specs

    units = {  # the longest suffix first
        "_mm_s2": "[mm/s²]",
        "_mm_s": "[mm/s]",
        "_rad_s2": "[rad/s²]",
        "_rad_s3": "[rad/s³]",
        "_kg_m2": "[kg m²]",
        "_mm": "[mm",
        "_deg": "[deg",
        "_s": "[s]",
        "_rpm": "[rpm]",
        "_kg": "[kg]",
        "_Nm": "[N m]",
        "_kN": "[kN",
    }
    for spec in field_specs():
        leaf = spec["name"].rsplit(".", 1)[-1]
        assert "_" not in spec["title"] and len(spec["help"]) > 20, spec  # words, not a key
        unit = next((u for suffix, u in units.items() if leaf.endswith(suffix)), "")
        assert unit in spec["title"], spec


@pytest.mark.slow  # the browser: about 5 s
@browser
def test_a_drive_added_and_its_forming_force_edited_in_the_page(page) -> None:
    """No drive on the published case: "add a drive" puts in the template press's drive and forming force
    (``pressplan new --drive``), solved as the CLI solves that case; a cell of the forming-force table edited
    is solved the same way; a bad cell is named next to the table and marked; "remove the drive" gives the
    published plan again."""
    from planning.reports.new_case import drive_template

    data = published_data()
    template = drive_template("crank-slider")
    before = int(page.evaluate("document.body.dataset.rendered"))
    page.locator("#add-drive").click()
    wait_rendered(page, before)
    data["drive"], data["process"]["forming_force_kN"] = template["drive"], template["forming_force_kN"]
    assert shown_numbers(page)["spm"] == cli_numbers(copy.deepcopy(data))["spm"]
    assert "% of rated" in page.locator("#drive-line").inner_text()
    cell = page.locator(".force-table tbody tr").nth(2).locator("input").nth(1)
    before = int(page.evaluate("document.body.dataset.rendered"))
    cell.fill("7000")
    cell.dispatch_event("change")
    wait_rendered(page, before)
    data["process"]["forming_force_kN"][2][1] = 7000
    assert shown_numbers(page)["spm"] == cli_numbers(copy.deepcopy(data))["spm"]
    before = int(page.evaluate("document.body.dataset.rendered"))
    cell.fill("lots")
    cell.dispatch_event("change")
    page.wait_for_function(f"Number(document.body.dataset.rendered) > {before}", timeout=60_000)
    message = page.locator('.msg[data-for="process.forming_force_kN"]').inner_text()
    assert message == f"{LABEL}: process.forming_force_kN.2.1: input should be a valid number (got 'lots')"
    assert "bad" in (cell.get_attribute("class") or "")
    cell.fill("7000")
    cell.dispatch_event("change")
    wait_rendered(page, before)
    before = int(page.evaluate("document.body.dataset.rendered"))
    page.locator("#remove-drive").click()
    wait_rendered(page, before)
    assert page.locator("#spm").inner_text() == "12.123" and page.locator("#drive-line").inner_text() == ""
    assert page.locator("#add-drive").count() == 1


@pytest.mark.slow  # the browser: about 4 s
@browser
def test_the_cam_is_proved_on_the_page_and_downloaded_as_the_cli_writes_it(page, tmp_path: Path) -> None:
    """The cam panel, with the mouse: a CODESYS cam of the confirmed plan is proved (its numbers beside the
    button) and downloaded byte for byte as `pressplan cam` writes it; a linear table too coarse is refused with
    the limit it breaks, and nothing can be downloaded."""
    page.select_option("#cam-target", "codesys")
    page.locator("#cam-prove").click()
    page.wait_for_function("document.querySelector('#cam-proof').textContent.includes('points')", timeout=60_000)
    proof = page.locator("#cam-proof").inner_text()
    assert proof.startswith("cam_codesys.st: 19 points") and "every limit holds up to 100.00 %" in proof
    with page.expect_download(timeout=60_000) as info:
        page.locator("#cam-download").click()
    info.value.save_as(tmp_path / "page.st")
    out = tmp_path / "cli"
    command = [sys.executable, "-m", "planning.cli", "cam", str(PUBLISHED), "--cam", "codesys", "--out", str(out)]
    cli = subprocess.run(command)
    assert cli.returncode == 0
    assert (tmp_path / "page.st").read_bytes() == (out / "cam_codesys.st").read_bytes()
    page.select_option("#cam-target", "csv")
    page.select_option("#cam-interpolation", "linear")
    page.locator("#cam-count").fill("3600")
    page.locator("#cam-prove").click()
    page.wait_for_function("document.querySelector('#cam-message').textContent !== ''", timeout=60_000)
    assert "|slider acceleration|" in page.locator("#cam-message").inner_text()
    assert page.locator("#cam-download").is_disabled()


@browser
def test_a_hold_is_shown_and_its_time_edited_with_the_mouse_and_keys(page) -> None:
    """The coining case's hold: the page's numbers are the CLI's, the standstill is shaded and named on the chart
    against time, the summary says where the crank stands; the hold's time clicked, typed and left with Tab
    gives the CLI's plan of the new time."""
    pick_case(page, "coining-hold.yaml")
    data = load_yaml((CASES / "coining-hold.yaml").read_text(encoding="utf-8"))
    label = "cases/coining-hold.yaml"
    case = case_from_data(copy.deepcopy(data), label)
    result = result_dict(solve(case), case)
    assert page.locator("#spm").inner_text() == f"{result['spm']:.3f}"
    page.locator("#summary").locator("xpath=..").locator("summary").click()  # the summary unfolded
    assert "stands 0.3000 s" in page.locator("#summary").inner_text()
    page.locator("#x-axis").select_option("time")
    notes = page.evaluate("document.getElementById('motion-chart').layout.annotations.map((a) => a.text)")
    assert "hold 0.3 s" in notes, notes
    shapes = page.evaluate("document.getElementById('motion-chart').layout.shapes.map((s) => [s.x0, s.x1])")
    t3 = next(k["time_s"] for k in result["key_points"] if k["name"] == "draw_end")
    start = t3 + result["hold"]["brake_s"]
    assert any(abs(a - start) < 1e-9 and abs(b - start - 0.3) < 1e-9 for a, b in shapes), shapes
    before = int(page.evaluate("document.body.dataset.rendered"))
    page.locator('[data-field="process.hold_time_s"]').click(click_count=3)  # the mouse selects the value
    page.keyboard.type("0.5")
    page.keyboard.press("Tab")
    wait_rendered(page, before)
    data["process"]["hold_time_s"] = 0.5
    longer = case_from_data(data, label)
    assert page.locator("#spm").inner_text() == f"{solve(longer).plan.spm:.3f}"
    assert "stands 0.5000 s" in page.locator("#summary").inner_text()
    screenshot(page, "web-hold")


@pytest.mark.slow  # the browser: about 7 s
@browser
def test_a_draw_at_slide_speed_is_planned_and_its_speed_edited_with_the_mouse_and_keys(page) -> None:
    """The cup drawn at 60 mm/s (the optimal law's free draw): the page's strokes are the CLI's and its summary
    says where the slide holds its speed; the speed clicked, typed (45) and left with Tab gives the CLI's plan."""
    pick_case(page, "cup-slide-speed-draw.yaml")
    data = load_yaml((CASES / "cup-slide-speed-draw.yaml").read_text(encoding="utf-8"))
    label = "cases/cup-slide-speed-draw.yaml"
    assert page.locator("#spm").inner_text() == f"{solve(case_from_data(copy.deepcopy(data), label)).plan.spm:.3f}"
    page.locator("#summary").locator("xpath=..").locator("summary").click()  # the summary unfolded
    assert "draw at 60 mm/s slide speed: within 0.1 %" in page.locator("#summary").inner_text()
    before = int(page.evaluate("document.body.dataset.rendered"))
    page.locator('[data-field="process.draw_slide_speed_mm_s"]').click(click_count=3)
    page.keyboard.type("45")
    page.keyboard.press("Tab")
    wait_rendered(page, before)
    data["process"]["draw_slide_speed_mm_s"] = 45.0
    assert page.locator("#spm").inner_text() == f"{solve(case_from_data(data, label)).plan.spm:.3f}"
    assert "draw at 45 mm/s slide speed" in page.locator("#summary").inner_text()
    screenshot(page, "web-slide-draw")


@pytest.mark.slow  # the browser: about 7 s
@browser
def test_a_pendulum_stroke_on_the_page(page) -> None:
    """The shallow cup's press set to pendulum strokes with the mouse and the keys: the page's strokes are the CLI's
    pendulum plan's, the summary says the swing's gain over the rotary stroke, both robot's windows and both draws are
    shaded on the chart against time, and the bracket's bound is the pendulum's certified bound."""
    from planning.solver.pendulum import solve_pendulum
    from planning.solver.pendulum_bound import pendulum_bound

    pick_case(page, "small-fast-cup.yaml")
    data = load_yaml((CASES / "small-fast-cup.yaml").read_text(encoding="utf-8"))
    before = int(page.evaluate("document.body.dataset.rendered"))
    _choose_with_mouse_and_keys(page, '[data-field="planner.mode"]', "pendulum")
    wait_rendered(page, before)
    data["planner"]["mode"] = "pendulum"
    case = case_from_data(data, "cases/small-fast-cup.yaml")
    solution = solve_pendulum(case)
    assert page.locator("#spm").inner_text() == f"{solution.plan.spm:.3f}"
    page.locator("#summary").locator("xpath=..").locator("summary").click()  # the summary unfolded
    summary = page.locator("#summary").inner_text()
    assert (
        "in pendulum strokes" in summary
        and f"the rotary stroke under the same limits: {solution.rotary_spm:.3f}" in summary
    )
    _choose_with_mouse_and_keys(page, "#x-axis", "time")
    rects = "document.getElementById('motion-chart').layout.shapes.filter((s) => s.type === 'rect')"
    shapes = page.evaluate(rects + ".map((s) => [s.x0, s.x1])")
    f, b = solution.plan.key_times("forward"), solution.plan.key_times("backward")
    for lo, hi in ((f[3], b[0]), (f[1], f[2]), (b[1], b[2])):  # the window through theta_e, both draws
        assert any(abs(x0 - lo) < 1e-9 and abs(x1 - hi) < 1e-9 for x0, x1 in shapes), (lo, hi, shapes)
    page.wait_for_function("document.getElementById('bound-share').textContent.endsWith('%')")
    share = float(page.locator("#bound-share").inner_text().rstrip(" %"))
    assert share == pytest.approx(round(100 * solution.plan.spm / pendulum_bound(case).spm, 1))
    assert page.locator("#downloads button").first.is_disabled()  # its files: the CLI's (not the page's yet)
    screenshot(page, "web-pendulum")


@pytest.mark.slow  # the browser and two solves of the optimal swings: about 25 s
@browser
def test_optimal_swings_on_the_page(page) -> None:
    """The side panel under servo limits set to pendulum strokes and to the optimal law with the mouse and the keys:
    the page's strokes are the CLI's optimal swings' (``solve_pendulum``), its summary names the law, no error."""
    from planning.solver.pendulum import solve_pendulum

    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    pick_case(page, "side-panel-servo-limits.yaml")
    for field, value in (("planner.mode", "pendulum"), ("planner.motion_law", "optimal")):
        before = int(page.evaluate("document.body.dataset.rendered"))
        _choose_with_mouse_and_keys(page, f'[data-field="{field}"]', value)
        wait_rendered(page, before)
    data = load_yaml((CASES / "side-panel-servo-limits.yaml").read_text(encoding="utf-8"))
    data["planner"].update(mode="pendulum", motion_law="optimal")
    solution = solve_pendulum(case_from_data(data, "cases/side-panel-servo-limits.yaml"), compare=False)
    assert page.locator("#spm").inner_text() == f"{solution.plan.spm:.3f}"
    page.locator("#summary").locator("xpath=..").locator("summary").click()  # the summary unfolded
    summary = page.locator("#summary").inner_text()
    assert "in pendulum strokes" in summary and "(optimal, verified)" in summary and not errors
    screenshot(page, "web-pendulum-optimal")


@pytest.mark.slow
@browser
def test_a_pendulum_stroke_at_the_lines_rate_on_the_page(page) -> None:
    """The cup's drive case set to pendulum strokes and to the least energy at 30 strokes/min with the mouse, the
    keys and the rate typed in: the page's answer is the CLI's (``solve_swings``): 30 strokes/min, and the summary
    states the energy a stroke against the baseline's and the saving, the same numbers; the motor's chart drawn
    (a swing's answer once lacked the motor's data: a script error, no answer shown as done)."""
    from planning.solver.pendulum_rate import solve_swings

    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))  # a script error stops the page's answer
    pick_case(page, "cup-2000kN-drive.yaml")
    before = int(page.evaluate("document.body.dataset.rendered"))
    _choose_with_mouse_and_keys(page, '[data-field="planner.mode"]', "pendulum")
    wait_rendered(page, before)
    before = int(page.evaluate("document.body.dataset.rendered"))
    _choose_with_mouse_and_keys(page, '[data-field="planner.objective"]', "min-energy")
    wait_rendered(page, before)
    assert "needs the line's rate" in page.locator('.msg[data-for="planner.target_spm"]').inner_text()
    page.locator('[data-field="planner.target_spm"]').click()
    page.keyboard.type("30")
    before = int(page.evaluate("document.body.dataset.rendered"))
    page.keyboard.press("Tab")
    wait_rendered(page, before)
    data = load_yaml((CASES / "cup-2000kN-drive.yaml").read_text(encoding="utf-8"))
    data["planner"].update(mode="pendulum", objective="min-energy", target_spm=30.0)
    solution = solve_swings(case_from_data(data, "cases/cup-2000kN-drive.yaml"))
    assert page.locator("#spm").inner_text() == "30.000"
    page.locator("#summary").locator("xpath=..").locator("summary").click()  # the summary unfolded
    summary = " ".join(page.locator("#summary").inner_text().split())
    energy, baseline = solution.energy_kJ, solution.at_rate.baseline.energy_kJ
    expected = f"supply energy {energy:.1f} kJ a stroke against {baseline:.1f} of the fastest swings"
    assert "min-energy at 30 strokes/min" in summary and expected in summary, summary
    assert f"{solution.saving_pct('energy_kJ'):.1f} % less" in summary
    assert page.locator("#drive-chart .main-svg").count() > 0 and not errors  # the motor's chart drawn for swings
    envelope = page.evaluate("document.getElementById('drive-chart').data.find((t) => t.name === 'peak envelope').x")
    assert min(envelope) < 0 < max(envelope)  # drawn for both ways the motor turns (backward on the backward swing)
    screenshot(page, "web-pendulum-rate")


def _choose_with_mouse_and_keys(page, selector: str, value: str) -> None:  # noqa: ANN001 - a Playwright page
    """Choose ``value`` in the select ``selector`` as a user does: scrolled into view, a mouse click at its
    coordinates opens its list, the arrow keys move to the option, Enter takes it."""
    page.locator(selector).scroll_into_view_if_needed()
    box = page.locator(selector).bounding_box()
    page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    options = page.locator(selector).evaluate("(s) => [...s.options].map((o) => o.value)")
    current = page.locator(selector).evaluate("(s) => s.selectedIndex")
    steps = options.index(value) - current
    for _ in range(abs(steps)):
        page.keyboard.press("ArrowDown" if steps > 0 else "ArrowUp")
    page.keyboard.press("Enter")
    assert page.locator(selector).input_value() == value


@browser
def test_a_confirmed_answer_with_the_fast_answers_charts_is_not_drawn_again(site, page) -> None:
    """An edit (a mouse click into θ2, the value typed, Tab): its fast answer is drawn; its confirmed answer, when
    its charts are the same (curves, limit lines, strokes, key points), only marks the plan confirmed: the charts
    are drawn once for the edit, and what they show is the confirmed answer's (the server's confirmed solve of the
    same case, asked again here)."""
    import urllib.request

    url, _ = site
    draws = page.evaluate("window.chartDraws")
    before = int(page.evaluate("document.body.dataset.rendered"))
    field = page.locator('[data-field="key_points.draw_start_deg"]')
    field.scroll_into_view_if_needed()
    box = field.bounding_box()
    page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)  # a real click in the field
    page.keyboard.press("Control+A")
    page.keyboard.type("132.2")
    page.keyboard.press("Tab")  # Tab solves at once (docs/web.md)
    wait_rendered(page, before)
    data = published_data()
    data["key_points"]["draw_start_deg"] = 132.2
    body = json.dumps({"session": "a-check", "seq": 1, "case": data, "confirm": True}).encode()
    request = urllib.request.Request(url + "/api/solve", body, {"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=60) as response:
        confirmed = json.load(response)
    assert confirmed["confirmed"] and page.evaluate("document.body.dataset.state") == "ready"
    shown = page.evaluate("document.getElementById('motion-chart').data.map((t) => [t.name, t.y])")
    curves = [v for v in confirmed["curves"].values() if isinstance(v, list)]

    def same(y: list, v: list) -> bool:  # the page's own rule: within 1e-9 of the larger value (or of 1)
        return len(y) == len(v) and all(abs(a - b) <= 1e-9 * max(1, abs(a), abs(b)) for a, b in zip(y, v, strict=True))

    plotted = [(name, y) for name, y in shown if y and len(y) == len(curves[0]) and "=" not in name]  # not limits
    assert len(plotted) >= 3 and all(any(same(y, v) for v in curves) for _, y in plotted), [n for n, _ in plotted]
    assert page.evaluate("window.chartDraws") - draws == 1
