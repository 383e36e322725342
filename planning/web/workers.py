"""The page's work done in worker processes beside the server's: the bounds, and the cold solves that confirm an
edit's fast answer.

IPOPT takes one call at a time per process, so what runs in the server's process waits for the solves there. A
:class:`WorkerProcess` is one spawned process (started on first use, stopped by :meth:`WorkerProcess.close`; it
ignores Ctrl-C, which stops the server, and the server's stop ends it) that runs one function at a time.

The confirming cold solve: when an edit's fast request comes (the warm start from the session's plan,
``planning.web.server.solve_case``), the server starts the cold solve of the same case here at once
(:func:`cold_solution`); the confirm request that follows takes it, with the fast answer the better of the two, as
``planning.solver.optimize.solve`` with the neighbour does (:func:`planning.solver.optimize.better`). So the two
solves run side by side on two cores and the confirmed chart comes after the longer of them, not after their sum.
The worker solves with the NLPs the server's background compiler compiled once they are in the cache
(``planning.solver.ipopt.adopt_compiled``).
"""

from __future__ import annotations

import multiprocessing
import threading
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from typing import Any

from planning.model.case_file import CaseFileError, case_from_data
from planning.solver.ahead import stop_pool, worker_signals
from planning.solver.outcomes import PlanningError


class WorkerProcess:
    """One spawned worker process running one function at a time (module docstring)."""

    def __init__(self) -> None:
        self._pool: ProcessPoolExecutor | None = None
        self._lock = threading.Lock()

    @property
    def started(self) -> bool:
        return self._pool is not None

    def submit(self, function: Callable[..., Any], *args: Any) -> Future:
        """``function(*args)`` in the worker, queued behind what it runs; a worker that died is started anew."""
        with self._lock:
            for _ in range(2):
                if self._pool is None:
                    context = multiprocessing.get_context("spawn")
                    self._pool = ProcessPoolExecutor(max_workers=1, mp_context=context, initializer=worker_signals)
                try:
                    return self._pool.submit(function, *args)
                except BrokenProcessPool:  # the worker died (killed, out of memory): a new one
                    self._pool.shutdown(wait=False, cancel_futures=True)
                    self._pool = None
            raise BrokenProcessPool("the worker process does not start")

    def close(self) -> None:
        """Stop the worker process now (work under way is dropped)."""
        with self._lock:
            pool, self._pool = self._pool, None
        if pool is not None:
            stop_pool(pool)


@dataclass
class PendingCold:
    """A cold solve started in the worker for an edit's fast request: the case's ``key`` (``server.case_key`` of
    its label and data), the ``future`` of :func:`cold_solution`, and the fast answer's solution once made
    (``fast``; None where the plan before gave none)."""

    key: str
    future: Future
    fast: Any = None

    def cold(self) -> Any:
        """The worker's cold solution, or None where it found none, refused the case, or the worker failed (the
        server's own solve then answers, with the reason)."""
        try:
            return self.future.result()
        except Exception:  # noqa: BLE001 - a worker's failure (died, cancelled): the server solves it itself
            return None


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
