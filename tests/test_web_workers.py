"""The page's confirming cold solve in a worker process (``planning.web.workers``): started by an edit's fast
request, taken by its confirm request, the same answer as the server's own cold solve; and when the worker is
gone, the server solves it itself."""

from __future__ import annotations

import os
import signal
import time
from contextlib import contextmanager
from pathlib import Path

import pytest
import yaml

from planning.model.case_file import case_from_data
from planning.model.outcome import Outcome
from planning.solver import optimize

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
LABEL = "cases/wang2023-side-panel.yaml"


def _data(draw_start_deg: float) -> dict:
    data = yaml.safe_load((CASES / "wang2023-side-panel.yaml").read_text(encoding="utf-8"))
    data.pop("published", None)
    data["key_points"]["draw_start_deg"] = draw_start_deg
    return data


@contextmanager
def _app_with_worker():  # noqa: ANN202 - yields the app and its test client, the first case solved
    """The app with its cold-solve worker, the first case (no plan yet) solved in the server's process and the
    worker's warm-up done (an edit's cold solve started during the warm-up would wait: its confirm solves here)."""
    pytest.importorskip("flask")
    from planning.web.server import close_app, create_app

    app = create_app(CASES, cold_worker=True)
    try:
        client = app.test_client()
        assert _ask(client, _data(131.6), 1, True)["status"] == Outcome.VERIFIED
        deadline = time.monotonic() + 60
        while not app.extensions["pressplan_workers"][1].idle() and time.monotonic() < deadline:
            time.sleep(0.05)
        yield app, client
    finally:
        close_app(app)


def _ask(client, data: dict, seq: int, confirm: bool) -> dict:  # noqa: ANN001 - a Flask test client
    body = {"session": "tab", "seq": seq, "label": LABEL, "case": data, "confirm": confirm}
    return client.post("/api/solve", json=body).get_json()


def _solved_here_raises(monkeypatch) -> None:  # noqa: ANN001 - pytest's monkeypatch
    """From here on a solve in this (the server's) process fails the test; the worker process is not touched."""

    def here(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        raise AssertionError("the confirming cold solve ran in the server's process")

    monkeypatch.setattr(optimize, "solve", here)


def test_an_edits_confirmed_answer_is_the_cold_solve_the_worker_started_with_its_fast_request(monkeypatch):
    """The first solve (no plan yet) is the server's; an edit's fast request starts the cold solve in the worker,
    and its confirm request takes it: the server's process solves nothing for it (a solve there fails the test),
    and the plan shown is the cold solve's to the last digit."""
    edited = _data(132.0)
    cold = optimize.solve(case_from_data(edited, LABEL))
    with _app_with_worker() as (_app, client):
        fast = _ask(client, edited, 2, False)
        assert fast["status"] == Outcome.VERIFIED and fast["confirmed"] is False
        _solved_here_raises(monkeypatch)
        confirmed = _ask(client, edited, 2, True)
    assert confirmed["status"] == Outcome.VERIFIED and confirmed["confirmed"] is True
    assert confirmed["result"]["spm"] == cold.plan.spm


def test_a_worker_killed_before_the_confirm_leaves_the_cold_solve_to_the_server():
    """The worker killed between an edit's fast and confirm requests (its cold solve lost): the confirm request
    solves here, the cold solve's plan all the same; the next edit starts a new worker, and its confirm is the
    worker's cold solve again."""
    with _app_with_worker() as (app, client):
        solves = app.extensions["pressplan_workers"][1]
        for seq, draw_start in ((2, 132.0), (3, 132.4)):
            edited = _data(draw_start)
            assert _ask(client, edited, seq, False)["confirmed"] is False
            if seq == 2:
                for process in list(solves.worker._pool._processes.values()):  # killed, as by the OOM killer
                    os.kill(process.pid, signal.SIGKILL)
            pending = app.extensions["pressplan_sessions"].get("tab").pending
            confirmed = _ask(client, edited, seq, True)
            assert confirmed["status"] == Outcome.VERIFIED and confirmed["confirmed"] is True
            assert confirmed["result"]["spm"] == optimize.solve(case_from_data(edited, LABEL)).plan.spm
            assert (pending.result.result() is None) == (seq == 2)  # the second edit's from the new worker


def test_a_confirm_of_another_case_than_the_fast_requests_is_that_cases_cold_solve(monkeypatch):
    """An edit's fast request started the cold solve of case A; a confirm request then comes for case B (no fast
    request of it): the answer is B's cold solve, never A's plan."""
    a, b = _data(132.0), _data(131.0)
    b["process"]["transfer_time_s"] = 1.5
    cold_b = optimize.solve(case_from_data(b, LABEL)).plan.spm
    with _app_with_worker() as (_app, client):
        assert _ask(client, a, 2, False)["confirmed"] is False
        confirmed = _ask(client, b, 3, True)
    assert confirmed["status"] == Outcome.VERIFIED and confirmed["result"]["spm"] == cold_b


def _pid_after(seconds: float) -> int:
    time.sleep(seconds)
    return os.getpid()


def test_a_confirm_never_waits_behind_another_edits_solve_and_a_newer_edit_replaces_a_waiting_one():
    """One solve runs in the worker at a time: another session's, started after it, waits; its confirm withdraws it
    at once (the server then solves it) instead of waiting for the one under way. A session's newer edit replaces
    its older one that waits."""
    from planning.web.workers import ColdSolves

    solves = ColdSolves(_pid_after)
    try:
        running = solves.start("tab-a", "a", (1.5,))
        waiting = solves.start("tab-b", "b", (0.0,))
        older = solves.start("tab-c", "c1", (0.0,))
        newer = solves.start("tab-c", "c2", (0.0,))
        t0 = time.perf_counter()
        assert solves.take(waiting) is None and time.perf_counter() - t0 < 0.5  # withdrawn, not waited for
        assert older.result.result(timeout=1) is None  # replaced by the newer edit's
        assert solves.take(running) not in (None, os.getpid())  # made in the worker
        assert newer.result.result(timeout=30) not in (None, os.getpid())  # started after the one under way
    finally:
        solves.close()
