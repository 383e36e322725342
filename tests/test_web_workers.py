"""The page's confirming cold solve in a worker process (``planning.web.workers``): started by an edit's fast
request, taken by its confirm request, the same answer as the server's own cold solve; and when the worker is
gone, the server solves it itself."""

from __future__ import annotations

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
def _app_with_worker():  # noqa: ANN202 - yields the app and its test client
    pytest.importorskip("flask")
    from planning.web.server import close_app, create_app

    app = create_app(CASES, cold_worker=True)
    try:
        yield app, app.test_client()
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
        assert _ask(client, _data(131.6), 1, True)["status"] == Outcome.VERIFIED
        fast = _ask(client, edited, 2, False)
        assert fast["status"] == Outcome.VERIFIED and fast["confirmed"] is False
        _solved_here_raises(monkeypatch)
        confirmed = _ask(client, edited, 2, True)
    assert confirmed["status"] == Outcome.VERIFIED and confirmed["confirmed"] is True
    assert confirmed["result"]["spm"] == cold.plan.spm


def test_a_worker_gone_before_the_confirm_leaves_the_cold_solve_to_the_server():
    """The worker stopped between an edit's fast and confirm requests (its cold solve lost): the confirm request
    solves here, the cold solve's plan all the same; the next edit starts a new worker and its answer is the cold
    solve's too."""
    with _app_with_worker() as (app, client):
        assert _ask(client, _data(131.6), 1, True)["status"] == Outcome.VERIFIED
        for seq, draw_start in ((2, 132.0), (3, 132.4)):
            edited = _data(draw_start)
            assert _ask(client, edited, seq, False)["confirmed"] is False
            if seq == 2:
                app.extensions["pressplan_workers"][1].close()  # the cold solves' worker
            confirmed = _ask(client, edited, seq, True)
            assert confirmed["status"] == Outcome.VERIFIED and confirmed["confirmed"] is True
            assert confirmed["result"]["spm"] == optimize.solve(case_from_data(edited, LABEL)).plan.spm
