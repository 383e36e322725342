"""Calls made ahead in a worker process (``planning.solver.ahead``), and the bracket that uses them: the same
numbers as made here, the caller's own exception where the call raises."""

from __future__ import annotations

import math
import os
import time
from types import SimpleNamespace

import numpy as np
import pytest

from planning.solver import ahead as ahead_module
from planning.solver.ahead import Ahead

forking = pytest.mark.skipif(not ahead_module._can_fork(), reason="no second core or no fork here")


def _pid_after(seconds: float) -> int:
    time.sleep(seconds)
    return os.getpid()


def _raises(text: str) -> None:
    raise ValueError(f"{text} in {os.getpid()}")


@forking
def test_a_call_runs_in_the_worker_while_this_process_goes_on_and_in_order():
    ahead = Ahead()
    try:
        t0 = time.perf_counter()
        calls = [ahead.start(_pid_after, 0.3), ahead.start(_pid_after, 0.0)]
        started = time.perf_counter() - t0
        values = [call.take() for call in calls]
    finally:
        ahead.close()
    assert started < 0.25  # start returned before the call was done
    assert values[0] == values[1] != os.getpid()  # both in the one worker


@forking
def test_a_call_that_raises_there_raises_here_as_it_would_without_the_worker():
    ahead = Ahead()
    try:
        call = ahead.start(_raises, "wrong")
        with pytest.raises(ValueError, match=f"wrong in {os.getpid()}$"):  # this process's own exception
            call.take()
    finally:
        ahead.close()


@forking
def test_a_worker_stopped_before_the_take_leaves_the_call_to_this_process():
    ahead = Ahead()
    call = ahead.start(_pid_after, 30.0)
    t0 = time.perf_counter()
    ahead.close()
    assert time.perf_counter() - t0 < 5.0  # the worker killed, not waited for
    ahead.close()
    assert ahead_module.Call(_pid_after, (0.0,), call.future).take() == os.getpid()


def test_without_a_worker_the_call_is_made_when_taken(monkeypatch):
    monkeypatch.setattr(ahead_module, "_can_fork", lambda: False)
    ahead = Ahead()
    call = ahead.start(_pid_after, 0.0)
    assert call.future is None and call.take() == os.getpid()
    ahead.close()


def _both_ways(monkeypatch, compute):  # noqa: ANN001, ANN202 - pytest's monkeypatch, a callable; its two values
    """``compute()`` with its calls made in workers (whether each one taken was made there recorded), then with none
    made in a worker (no fork): ``(made_there, the first value, the second)``."""
    made_there: list[bool] = []
    take = ahead_module.Call.take

    def taken(call):  # noqa: ANN001, ANN202
        made_there.append(call.future is not None and call.future.result()[0])
        return take(call)

    with monkeypatch.context() as m:
        m.setattr(ahead_module.Call, "take", taken)
        parallel = compute()
    with monkeypatch.context() as m:
        m.setattr(ahead_module, "_can_fork", lambda: False)
        alone = compute()
    return made_there, parallel, alone


def _bracket_both_ways(case, tolerance_pct: float, monkeypatch):  # noqa: ANN001, ANN202 - a Case; two Brackets
    """The bracket with its upper bounds made ahead in the worker (each one taken was made there), and made here."""
    from planning.solver.bracket import bracket

    made_there, parallel, alone = _both_ways(monkeypatch, lambda: bracket(case, tolerance_pct))
    assert made_there and all(made_there), made_there
    return parallel, alone


FAKE_UPPER_SPM = {1440: 10.1, 2880: 10.08, 5760: 10.06}  # a bound that falls with each finer mesh


def _fake_upper(case, points: int, pieces: int) -> SimpleNamespace:  # noqa: ANN001 - a Case
    return SimpleNamespace(spm=FAKE_UPPER_SPM[points], points=points)


def _fake_motion(spm: float) -> SimpleNamespace:
    return SimpleNamespace(plan=SimpleNamespace(spm=spm))


@forking
def test_the_brackets_rounds_with_their_bounds_made_ahead_take_each_mesh_in_its_turn(monkeypatch):
    """The bracket's rounds on stand-ins (a motion 0.02 SPM faster on each finer layout, a bound lower on each finer
    mesh): four rounds, both meshes taken in their turns, each bound made in the worker; the same rounds as made
    here."""
    from planning.model.case_file import read_case
    from planning.solver import bracket as bracket_module
    from tests.conftest import PUBLISHED_CASE

    monkeypatch.setattr(bracket_module, "upper_bound", _fake_upper)
    monkeypatch.setattr(bracket_module, "solve_optimal", lambda case: _fake_motion(10.0))
    monkeypatch.setattr(bracket_module, "on_layout", lambda case, answer, layout: _fake_motion(answer.plan.spm + 0.02))
    monkeypatch.setattr(bracket_module, "_checked", lambda case, solution, previous=None: solution)
    parallel, alone = _bracket_both_ways(read_case(PUBLISHED_CASE), 0.05, monkeypatch)
    upper_spm = [r.upper_spm for r in alone.rounds]
    assert upper_spm == [10.1, 10.1, 10.08, 10.08, 10.06], alone.rounds
    assert parallel.rounds == alone.rounds


@forking
def test_the_brackets_first_round_with_its_bound_made_ahead_is_the_one_made_here(monkeypatch):
    from planning.model.case_file import read_case
    from tests.conftest import PUBLISHED_CASE

    parallel, alone = _bracket_both_ways(read_case(PUBLISHED_CASE), math.inf, monkeypatch)
    assert parallel.rounds == alone.rounds and parallel.upper.spm == alone.upper.spm


@pytest.mark.slow  # 15 s: three rounds, two meshes
@forking
def test_the_cup_presss_bracket_with_its_bounds_made_ahead_is_the_one_made_here(monkeypatch):
    from planning.model.case_file import read_case
    from tests.conftest import ROOT

    parallel, alone = _bracket_both_ways(read_case(ROOT / "cases" / "cup-2000kN-drive.yaml"), 0.05, monkeypatch)
    assert len(alone.rounds) == 3 and alone.upper.points == 2880  # the bound on the second mesh was taken
    assert parallel.rounds == alone.rounds and parallel.upper.spm == alone.upper.spm
    assert parallel.verified.plan.spm == alone.verified.plan.spm


def _fake_bound(case, points: int) -> SimpleNamespace:  # noqa: ANN001 - a Case
    return SimpleNamespace(points=points, pid=os.getpid())


def _failing_bound(case, points: int) -> None:  # noqa: ANN001 - a Case
    from planning.solver.outcomes import Infeasible

    raise Infeasible(f"the bound's own error in {os.getpid()}")


def _failing_bracket(case, tolerance_pct: float, ahead: Ahead) -> None:  # noqa: ANN001 - a Case
    from planning.solver.outcomes import NoPlanFound

    raise NoPlanFound("the bracket's error")


@forking
def test_bound_makes_its_time_optimal_bound_in_the_brackets_worker_and_says_its_error_first(monkeypatch):
    """``pressplan bound --bracket``: the time-optimal bound made in the worker while the bracket runs here; where
    both fail, the bound's error (raised here, as when it was computed before the bracket); where the bracket alone
    fails, the bracket's."""
    from planning import cli
    from planning.solver import bound as bound_module
    from planning.solver import bracket as bracket_module
    from planning.solver.outcomes import Infeasible, NoPlanFound

    monkeypatch.setattr(bound_module, "time_optimal_bound", _fake_bound)
    monkeypatch.setattr(bracket_module, "bracket", lambda case, tolerance_pct, ahead: ("bracket", os.getpid()))
    bound, result = cli._bound_and_bracket(None, 720, 0.05)
    assert bound.points == 720 and bound.pid != os.getpid() and result == ("bracket", os.getpid())
    monkeypatch.setattr(bracket_module, "bracket", _failing_bracket)
    with pytest.raises(NoPlanFound, match="the bracket's error"):
        cli._bound_and_bracket(None, 720, 0.05)
    monkeypatch.setattr(bound_module, "time_optimal_bound", _failing_bound)
    with pytest.raises(Infeasible, match="the bound's own error in ") as raised:
        cli._bound_and_bracket(None, 720, 0.05)
    assert not raised.value.reason.endswith(f" {os.getpid()}")  # the worker's, raised here as it is (made once)


def _no_plan_once(marker: str) -> None:
    from planning.model.limits.base import Check
    from planning.solver.outcomes import NoPlanFound, Unverified

    with open(marker, "a") as f:
        f.write(f"{os.getpid()}\n")
    if marker.endswith("unverified"):
        check = Check("slider acceleration", 2.0, 1.0, "m/s^2", "max", False, "slider_accel")
        raise Unverified(f"checked in {os.getpid()}", check)
    raise NoPlanFound(f"none in {os.getpid()}", ())


@forking
@pytest.mark.parametrize("kind", ["no-plan", "unverified"])
def test_a_typed_outcome_raised_in_the_worker_is_raised_here_as_it_is_and_the_call_made_once(tmp_path, kind):
    """A call that ends without a plan (``planning.solver.outcomes``) in the worker: that exception, its data too, is
    raised where the call is taken, and the call is not made again here (a law or a press that fails cost twice)."""
    from planning.solver.outcomes import NoPlanFound, Unverified

    marker = tmp_path / kind
    with Ahead() as ahead, pytest.raises((NoPlanFound, Unverified)) as raised:
        ahead.start(_no_plan_once, str(marker)).take()
    made_in = marker.read_text().split()
    assert len(made_in) == 1 and made_in[0] != str(os.getpid())  # once, in the worker
    error = raised.value
    assert error.reason == f"{'checked' if kind == 'unverified' else 'none'} in {made_in[0]}"
    assert str(error) == f"{error.outcome}: {error.reason}"
    if kind == "unverified":
        assert isinstance(error, Unverified) and error.check.value == 2.0 and error.check.id == "slider_accel"
    else:
        assert isinstance(error, NoPlanFound) and error.attempts == ()


def _station_pid(seconds: float) -> tuple[float, int]:
    time.sleep(seconds)
    return seconds, os.getpid()


def _station_raises(name: str) -> None:
    raise ValueError(f"station {name} in {os.getpid()}")


@forking
def test_calls_side_by_side_run_at_once_each_result_in_its_place_the_first_error_its_own():
    """``planning.solver.ahead.side_by_side`` (a line's stations, the laws) on stand-ins: the calls run at once in
    two workers (four of 0.3 s in about 0.6 s), each result in its station's place; the first station that fails
    raises here, its own error."""
    _side_by_side = ahead_module.side_by_side

    t0 = time.perf_counter()
    results = _side_by_side(_station_pid, [(0.3,), (0.3,), (0.3,), (0.0,)])
    assert time.perf_counter() - t0 < 1.0
    assert [r[0] for r in results] == [0.3, 0.3, 0.3, 0.0]
    assert len({r[1] for r in results}) == 2 and os.getpid() not in {r[1] for r in results}
    assert _side_by_side(_station_pid, [(0.0,)])[0][1] == os.getpid()  # one station: solved here
    with pytest.raises(ValueError, match=f"station b in {os.getpid()}$"):
        _side_by_side(_station_raises, [("b",), ("c",)])


@pytest.mark.slow  # 12 s: a line of two presses with robots, twice
@forking
def test_a_lines_stations_solved_side_by_side_give_the_line_solved_in_turn(monkeypatch):
    from planning.model.line_file import read_line
    from planning.solver import line as line_module
    from tests.conftest import ROOT

    path = ROOT / "tests" / "data" / "line" / "fast.yaml"

    def solved():  # noqa: ANN202 - a LineSolution
        line_module._ALONE.clear()
        return line_module.solve_line(read_line(path), side_by_side_workers=True)

    made_there, side_by_side, in_turn = _both_ways(monkeypatch, solved)
    assert len(made_there) == 4 and all(made_there)  # two stations alone, two at the line's period
    assert side_by_side.period_s == in_turn.period_s and side_by_side.offsets_s == in_turn.offsets_s
    for a, b in zip(side_by_side.at_line + side_by_side.alone, in_turn.at_line + in_turn.alone, strict=True):
        assert a.plan.nlp_values == b.plan.nlp_values


@forking
def test_the_laws_compared_side_by_side_give_the_comparison_made_in_turn(monkeypatch):
    """``compare_laws``: the bounds and the laws' solves made in the workers (each taken was made there), the
    optimal law under the improved S-curve's peak jerk after its row; the same table as made in turn."""
    from planning.model.case_file import read_case
    from planning.reports.law_comparison import compare_laws
    from tests.conftest import PUBLISHED_CASE

    case = read_case(PUBLISHED_CASE)
    laws = ("improved-s-curve", "quintic", "optimal")
    made_there, (side_by_side, tables), (in_turn, tables_in_turn) = _both_ways(
        monkeypatch, lambda: compare_laws(case, laws, side_by_side_workers=True)
    )
    assert len(made_there) == 5 and all(made_there)  # two bounds, three laws
    for data in (side_by_side, in_turn):  # the bounds' times aside
        data["bound"].pop("wall_time_s"), data["upper_bound"].pop("wall_time_s")
    assert side_by_side == in_turn  # every other number, the optimal law's jerk limit among them
    assert all(np.array_equal(tables[law], tables_in_turn[law]) for law in laws)


def _fake_certified(case, points: int) -> SimpleNamespace:  # noqa: ANN001 - a Case
    return SimpleNamespace(points=points, pid=os.getpid())


@forking
def test_bound_certified_makes_its_upper_bound_in_a_worker_and_says_the_time_optimal_bounds_error_first(monkeypatch):
    from planning import cli
    from planning.solver import bound as bound_module
    from planning.solver import upper_bound as upper_module
    from planning.solver.outcomes import Infeasible

    monkeypatch.setattr(bound_module, "time_optimal_bound", _fake_bound)
    monkeypatch.setattr(upper_module, "upper_bound", _fake_certified)
    bound, upper = cli._bound_and_upper(None, 720, None)
    assert bound.pid == os.getpid() and upper.pid != os.getpid() and upper.points == upper_module.UPPER_POINTS
    monkeypatch.setattr(bound_module, "time_optimal_bound", _failing_bound)
    with pytest.raises(Infeasible, match=f"the bound's own error in {os.getpid()}$"):
        cli._bound_and_upper(None, 720, 2880)


def _large_after_marking(marker: str, size: int) -> bytes:
    large = b"x" * size
    with open(marker, "w") as f:
        f.write("sending")  # the result is pickled and sent from now on
    return large


@forking
def test_a_worker_stopped_while_it_sends_a_large_result_does_not_hang_the_stop(tmp_path):
    """A worker killed halfway through writing its result left part of a message in the pool's result pipe, and
    the pool's thread waited for the rest for ever: the page's close once hung the test run there."""
    import threading

    for k, into_sending_s in enumerate((0.3, 0.5)):  # on a quiet machine 300 MB are sent from 0.2 s to 0.6 s on
        marker = tmp_path / f"marker{k}"
        worker = ahead_module.WorkerProcess("fork")
        worker.submit(_large_after_marking, str(marker), 300_000_000)
        deadline = time.perf_counter() + 30
        while not marker.exists() and time.perf_counter() < deadline:
            time.sleep(0.01)
        time.sleep(into_sending_s)
        closing = threading.Thread(target=worker.close, daemon=True)
        closing.start()
        closing.join(timeout=15)
        assert not closing.is_alive(), into_sending_s  # the stop returned
