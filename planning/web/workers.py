"""The page's work done in worker processes beside the server's: the bounds, and the cold solves that confirm an
edit's fast answer.

IPOPT takes one call at a time per process, so what runs in the server's process waits for the solves there. Each
is a :class:`~planning.solver.ahead.WorkerProcess` (spawned: the server runs threads; started on first use, it
ignores Ctrl-C, which stops the server; the server's stop ends it, and it ends itself when the server is gone) that
runs one function at a time.

The confirming cold solve (:class:`ColdSolves`): when an edit's fast request comes (the warm start from the
session's plan, ``planning.web.server.solve_case``), the server starts the cold solve of the same case in the worker
at once (:func:`cold_solution`); the confirm request that follows takes it, with the fast answer the better of the
two, as ``planning.solver.optimize.solve`` with the neighbour does (:func:`planning.solver.optimize.better`). So the
two solves run side by side on two cores and the confirmed chart comes after the longer of them, not after their
sum. One cold solve runs at a time; of each session one more may wait (a newer edit's replaces it), and a confirm
that comes while its solve still waits withdraws it (the server solves it then: a confirm never waits behind other
edits' solves, only for its own under way). The worker solves with the NLPs the server's background compiler
compiled once they are in the cache (``planning.solver.ipopt.adopt_compiled``).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Any

from planning.model.case_file import CaseFileError, case_from_data
from planning.solver.ahead import WorkerProcess
from planning.solver.outcomes import PlanningError


@dataclass(eq=False)
class PendingCold:
    """A cold solve for an edit's fast request: the case's ``key`` (``server.case_key`` of its label and data), its
    ``sent`` data and label, the fast answer's solution once made (``fast``; None where the plan before gave none),
    and ``result``: the worker's :class:`~planning.solver.solution.Solution`, or None (none found, refused, withdrawn,
    the worker gone)."""

    key: str
    sent: tuple
    fast: Any = None
    result: Future = field(default_factory=Future)


class ColdSolves:
    """The edits' cold solves in one :class:`WorkerProcess` (module docstring): :meth:`start` one for a session,
    :meth:`take` it at the confirm."""

    def __init__(self, function: Callable[..., Any] | None = None) -> None:
        self.function = function or cold_solution  # called as function(*sent) in the worker
        self.worker = WorkerProcess()
        self._lock = threading.Lock()
        self._waiting: OrderedDict[str, PendingCold] = OrderedDict()  # by session, in order of arrival
        self._running: PendingCold | None = None

    def start(self, session: str, key: str, sent: tuple) -> PendingCold:
        """The cold solve of the case ``sent`` (data, label) queued for ``session`` (its waiting one replaced)."""
        pending = PendingCold(key, sent)
        with self._lock:
            replaced = self._waiting.pop(session, None)
            self._waiting[session] = pending
        if replaced is not None:
            replaced.result.set_result(None)
        self._dispatch()
        return pending

    def take(self, pending: PendingCold) -> Any:
        """The solution of ``pending``: waited for where it runs or ran; None where it had not started (withdrawn:
        the caller solves) or failed."""
        self.drop(pending)  # where it still waits
        return pending.result.result()

    def drop(self, pending: PendingCold) -> None:
        """``pending`` is not wanted (another case came): withdrawn where it waits, else left to run out."""
        with self._lock:
            for session, waiting in list(self._waiting.items()):
                if waiting is pending:
                    del self._waiting[session]
        if pending is not self._running and not pending.result.done():
            pending.result.set_result(None)

    def warm_up(self, sent: tuple) -> None:
        """The worker started with a solve of ``sent`` (its imports and NLPs made while the user reads the plan)."""
        if not self.worker.started:
            self.start("", "", sent)

    def idle(self) -> bool:
        """No solve runs or waits (the warm-up done, say)."""
        with self._lock:
            return self._running is None and not self._waiting

    def close(self) -> None:
        self.worker.close()
        with self._lock:
            left, self._waiting = list(self._waiting.values()), OrderedDict()
        for pending in left:
            pending.result.set_result(None)

    def _dispatch(self) -> None:
        """Start the first waiting solve where none runs."""
        with self._lock:
            if self._running is not None or not self._waiting:
                return
            _, pending = self._waiting.popitem(last=False)
            self._running = pending
        try:
            future = self.worker.submit(self.function, *pending.sent)
        except (RuntimeError, OSError):  # closed, or no process to be had: the server solves it
            self._finished(pending, None)
            return
        future.add_done_callback(lambda done: self._finished(pending, done))

    def _finished(self, pending: PendingCold, done: Future | None) -> None:
        try:
            value = done.result() if done is not None else None
        except Exception:  # noqa: BLE001 - the worker died or was stopped: the server solves it
            value = None
        with self._lock:
            self._running = None
        if not pending.result.done():
            pending.result.set_result(value)
        self._dispatch()


def cold_solution(data: Any, label: str) -> Any:
    """In the worker: the cold solve of the page's case ``data`` (``solve`` without a neighbour: its
    :class:`~planning.solver.solution.Solution`), or None where the case is refused or has no plan."""
    from planning.solver.ipopt import adopt_compiled
    from planning.solver.optimize import solve

    adopt_compiled()
    try:
        return solve(case_from_data(data, label))
    except (CaseFileError, PlanningError):
        return None
