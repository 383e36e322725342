"""The first solves of a multi-start's coming starts, made ahead in a forked worker (``planning.solver.search.
StartsAhead``): the same answers, to the last bit, as the starts solved in turn, and the solves taken made there."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from planning.model.case_file import read_case
from planning.solver import ahead as ahead_module
from planning.solver import search as search_module
from planning.solver.optimize import solve
from planning.solver.search import StartsAhead, prepare
from planning.solver.starts import free_starts, published_starts

CASES = Path(__file__).resolve().parents[1] / "cases"
forking = pytest.mark.skipif(not ahead_module._can_fork(), reason="no second core or no fork here")


@pytest.fixture(autouse=True)
def _a_core_free(monkeypatch):  # noqa: ANN001, ANN202
    """As on a quiet machine (a test run's workers hold the cores, so the load says none is free)."""
    monkeypatch.setattr(search_module, "core_free", lambda: True)


def _record_takes(monkeypatch) -> list[bool]:  # noqa: ANN001 - pytest's monkeypatch
    """Whether each solve taken from the worker was made there (not made here after a failure)."""
    made_there: list[bool] = []
    take = ahead_module.Call.take

    def taken(call):  # noqa: ANN001, ANN202
        if call.function is search_module._solve_there:
            made_there.append(call.future is not None and call.future.result()[0])
        return take(call)

    monkeypatch.setattr(ahead_module.Call, "take", taken)
    return made_there


def _in_turn(case, placement, monkeypatch):  # noqa: ANN001, ANN202 - a Case; a Solution
    """The case solved with every start made here, in turn (no worker: as before the starts were made ahead)."""
    with monkeypatch.context() as patched:
        patched.setattr(ahead_module, "_can_fork", lambda: False)
        return solve(case, placement)


def _same_answer(a, b) -> None:  # noqa: ANN001 - two Solutions
    assert a.plan.nlp_values == b.plan.nlp_values  # to the last bit
    assert a.plan.period == b.plan.period
    assert (a.plan.solver.iterations, a.plan.solver.starts) == (b.plan.solver.iterations, b.plan.solver.starts)
    assert a.plan.placement == b.plan.placement


@forking
@pytest.mark.parametrize(
    ("name", "placement"),
    [("wang2023-side-panel", "free"), ("wang2023-side-panel", "published"), ("wang2023-side-panel-drive", "free")],
)
def test_the_starts_solved_ahead_give_the_answer_of_the_starts_in_turn(name, placement, monkeypatch):
    case = read_case(CASES / f"{name}.yaml")
    made_there = _record_takes(monkeypatch)
    ahead = solve(case, placement)
    assert made_there and all(made_there)  # the confirming start's first solve came from the worker
    _same_answer(ahead, _in_turn(case, placement, monkeypatch))


@forking
def test_a_solve_begun_ahead_is_taken_only_by_the_very_same_call():
    case = read_case(CASES / "wang2023-side-panel.yaml")
    search = prepare(case, "free")
    w2 = search.draw_speed_range[1]
    x0 = free_starts(case, w2, None, None)[0]
    other = published_starts(case, w2, None)[0]
    args = (x0, search.parameters.copy(), search.lbx, search.ubx, "free", search.scale, None, False)
    ahead = StartsAhead()
    try:
        ahead.start(search.nlp, args)
        ahead.start(search.nlp, args)  # begun already: not twice
        assert len(ahead._calls) == 1
        assert ahead.take(search.nlp, (other, *args[1:])) is None  # another start
        moved = search.parameters.copy()
        moved[0] *= 1 + 1e-15
        assert ahead.take(search.nlp, (x0, moved, *args[2:])) is None  # another problem, by one bit
        assert ahead.take(search.nlp, (*args[:4], "published", *args[5:])) is None  # another placement
        made = ahead.take(search.nlp, args)
        assert ahead.take(search.nlp, args) is None  # taken once
    finally:
        ahead.close()
    here = search.nlp.solve(*args)
    assert np.array_equal(made.x, here.x) and made.iterations == here.iterations


class _Other:
    """An NLP the worker holds (it answers every solve with a word)."""

    def solve(self, *args) -> str:  # noqa: ANN002 - whatever it is given
        return "other"


@forking
def test_a_worker_forked_before_an_nlp_was_built_leaves_its_solve_to_this_process(monkeypatch):
    case = read_case(CASES / "wang2023-side-panel.yaml")
    search = prepare(case, "free")
    x0 = free_starts(case, search.draw_speed_range[1], None, None)[0]
    args = (x0, search.parameters.copy(), search.lbx, search.ubx, "free", search.scale, None, False)
    made_there = _record_takes(monkeypatch)
    other = _Other()
    ahead = StartsAhead()
    try:
        token = search_module._token(search.nlp)
        search_module._SOLVABLE.pop(token)
        ahead.start(other, ("a start",))  # the worker forked now, holding the other NLP, not this one
        ahead._forked_with |= {token}  # ... and believed to hold it
        search_module._SOLVABLE[token] = search.nlp
        ahead.start(search.nlp, args)
        made = ahead.take(search.nlp, args)
        assert ahead.take(other, ("a start",)) == "other"
    finally:
        ahead.close()
    assert made_there == [False, True]  # this NLP's solve raised there (no such NLP): made here; the other's there
    assert np.array_equal(made.x, search.nlp.solve(*args).x)


def test_an_nlps_token_is_never_another_ones_even_at_the_same_address():
    """A worker finds an NLP by its token: an object's id may be taken by a later object (the same address), a
    token is given once."""
    seen = set()
    for _ in range(50):
        nlp = _Other()
        token = search_module._token(nlp)
        assert token not in seen and search_module._token(nlp) == token
        seen.add(token)
        del nlp  # the next one may take its address


@forking
def test_where_no_core_is_free_nothing_is_made_ahead_and_the_answer_is_the_same(monkeypatch):
    case = read_case(CASES / "wang2023-side-panel.yaml")
    made_there = _record_takes(monkeypatch)
    monkeypatch.setattr(search_module, "core_free", lambda: False)
    busy = solve(case)
    assert made_there == []  # nothing begun: no worker forked
    _same_answer(busy, _in_turn(case, "free", monkeypatch))


def test_a_core_is_free_where_the_load_leaves_one(monkeypatch):
    monkeypatch.setattr(ahead_module, "_cores", lambda: 2)
    for load, free in ((0.2, True), (1.4, True), (1.6, False), (3.0, False)):
        monkeypatch.setattr(ahead_module.os, "getloadavg", lambda load=load: (load, load, load))
        assert ahead_module.core_free() is free
