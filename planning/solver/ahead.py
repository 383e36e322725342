"""Worker processes, and calls made ahead in them while this process goes on, so that the time of two independent
computations is the longer one's, not their sum: the bracket's next upper bound while its verified motion is refined
(``planning.solver.bracket``; ``pressplan bound``'s time-optimal bound beside the bracket or the certified upper
bound), a multi-start's next start (``planning.solver.search.StartsAhead``); and independent calls side by side in two
workers (:func:`side_by_side`: ``pressplan line``'s presses, ``pressplan laws``' bounds and laws).

A :class:`WorkerProcess` runs one function at a time in each of its worker processes (spawned or forked; one by
default): the bracket's, the side-by-side calls', and the web page's (``planning.web.workers``: its bounds and its
edits' cold solves).

:meth:`Ahead.start` hands a call to a forked worker and returns at once (with one worker, calls run one after another,
in the order started; with two, side by side); :meth:`Call.take` returns its value. A call computed there is the same
computation as here (the same code and inputs: the same numbers); a typed outcome it raised there (no plan, none
verified, infeasible: ``planning.solver.outcomes``) is raised where it is taken, and where it raised anything else, or
the worker failed, the call is made again here when taken, so the caller sees the value or the exception it would
have seen without the worker (a fault's traceback its own). Where the machine has one core, the process cannot fork
(no ``fork``, threads running, among them a pressplan worker's watch of its parent, a daemon process, which may have
no children), calls are made here when taken. The worker ignores Ctrl-C (the caller's to handle), is stopped by
:meth:`Ahead.close` and ends itself when this process is gone (:func:`worker_signals`, which every worker process of
pressplan starts with).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from planning.solver.outcomes import PlanningError

HELD = {signal.SIGINT, signal.SIGTERM}  # held while a worker process starts (``signals_held``)
PARENT_WATCH_S = 1.0  # [s] how often a worker looks whether its parent is still there
LOAD_FREE = 0.5  # a core is free where the 1-minute load average is under the cores less this (``core_free``)


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """Ctrl-C and SIGTERM held in this thread while a worker process starts inside the block: the worker inherits
    them held and sees none before :func:`worker_signals` (no traceback of a worker still importing); this
    process gets them when the block ends."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, HELD)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def worker_signals() -> None:
    """In a worker process: Ctrl-C is the parent's to handle; SIGTERM (from the parent) just ends it; signals held
    while it started are let through now; and it ends itself once its parent is gone (killed without a word)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD)
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_WATCH_S)
        os._exit(1)

    threading.Thread(target=watch, name="pressplan-parent-watch", daemon=True).start()


def _stop(pool: ProcessPoolExecutor) -> None:
    """Stop ``pool``'s worker processes now (work under way is dropped) and close its queues (no semaphore left to
    the resource tracker). A worker killed while it wrote its result leaves part of a message in the result pipe, on
    which the pool's own thread would wait for ever (this process holds the pipe's other end too): that end is
    closed once the workers are gone, so the thread reads the pipe's end instead and the shutdown joins it."""
    processes = list(getattr(pool, "_processes", {}).values())  # the executor keeps no public handle
    for process in processes:
        process.terminate()
    for process in processes:
        process.join(timeout=5)
    results = getattr(pool, "_result_queue", None)
    if results is not None and not any(process.is_alive() for process in processes):
        results._writer.close()  # nothing writes there any more (a second close, in shutdown, does nothing)
    pool.shutdown(wait=True, cancel_futures=True)


class WorkerProcess:
    """One worker process running one function at a time (``workers`` of them, each taking the next call), started on
    first use (with :func:`signals_held`, under :func:`worker_signals`) and by ``method``: ``"spawn"`` (a fresh
    interpreter: for a process running threads, such as the web server) or ``"fork"`` (a copy of this one, its
    imports done)."""

    def __init__(self, method: str = "spawn", workers: int = 1) -> None:
        self.method, self.workers = method, workers
        self._pool: ProcessPoolExecutor | None = None
        self._lock = threading.Lock()
        self._closed = False

    @property
    def started(self) -> bool:
        return self._pool is not None

    def submit(self, function: Callable[..., Any], *args: Any) -> Future:
        """``function(*args)`` in the worker, queued behind what it runs; a worker that died is started anew. Raises
        ``RuntimeError`` once closed (or where no worker starts) or ``OSError`` (no process to be had)."""
        with self._lock:
            for _ in range(2):
                if self._closed:
                    raise RuntimeError("the worker process is closed")
                if self._pool is None:
                    context = multiprocessing.get_context(self.method)
                    self._pool = ProcessPoolExecutor(
                        max_workers=self.workers, mp_context=context, initializer=worker_signals
                    )
                try:
                    with signals_held():  # the process starts here: no Ctrl-C before it ignores it
                        return self._pool.submit(function, *args)
                except BrokenProcessPool:  # the worker died (killed, out of memory): a new one
                    self._pool.shutdown(wait=False, cancel_futures=True)
                    self._pool = None
            raise BrokenProcessPool("the worker process does not start")

    def close(self) -> None:
        """Stop the worker process now (work under way is dropped); no other starts."""
        with self._lock:
            pool, self._pool, self._closed = self._pool, None, True
        if pool is not None:
            _stop(pool)


class Ahead:
    """One forked worker making calls ahead (module docstring); ``workers``: that many, each taking the next call
    (the calls then run side by side, not in order: for independent calls this process only waits for); 0: none,
    every call made here when taken."""

    def __init__(self, workers: int = 1) -> None:
        self._worker = WorkerProcess("fork", workers) if workers > 0 and _can_fork() else None

    def start(self, function: Callable[..., Any], *args: Any) -> Call:
        """``function(*args)`` started in the worker (or, where there is none, made when taken)."""
        future = None
        if self._worker is not None:
            try:
                future = self._worker.submit(_guarded, function, args)
            except (OSError, RuntimeError):  # no process to be had: made here
                self.close()
        return Call(function, args, future)

    def close(self) -> None:
        """Stop the worker now (a call under way is dropped)."""
        worker, self._worker = self._worker, None
        if worker is not None:
            worker.close()

    def __enter__(self) -> Ahead:
        return self

    def __exit__(self, *exc: object) -> None:
        """The block's end, however it ends: :meth:`close`."""
        self.close()


class Call:
    """A call started by :meth:`Ahead.start`."""

    def __init__(self, function: Callable[..., Any], args: tuple, future: Future | None) -> None:
        self.function, self.args, self.future = function, args, future

    def take(self) -> Any:
        """The call's value (waiting for the worker), or the typed outcome it raised there (``planning.solver.
        outcomes``: the same exception, its data too), or, where it raised anything else or the worker failed, the
        call made here: its value or its exception."""
        if self.future is not None:
            try:
                done, value = self.future.result()
            except Exception:  # noqa: BLE001 - the worker died or was stopped: made here
                done, value = False, None
            if done:
                return value
            if isinstance(value, PlanningError):
                raise value
        return self.function(*self.args)


SIDE_BY_SIDE_WORKERS = 2  # independent calls made side by side in this many forked workers


def side_by_side(function: Callable[..., Any], calls: list[tuple]) -> list[Any]:
    """``function(*args)`` for each of ``calls``, made side by side in :data:`SIDE_BY_SIDE_WORKERS` forked workers
    (where :class:`Ahead` can fork; one call alone, or none can: made here in turn), taken in order: the values in
    the calls' order, and where a call raises, the first such call raises here (as :meth:`Call.take` says)."""
    with Ahead(SIDE_BY_SIDE_WORKERS if len(calls) > 1 else 0) as ahead:
        started = [ahead.start(function, *args) for args in calls]
        return [call.take() for call in started]


def in_turn(function: Callable[..., Any], calls: list[tuple]) -> list[Any]:
    """``function(*args)`` for each of ``calls``, here, one after another (:func:`side_by_side`'s other way)."""
    return [function(*args) for args in calls]


_FAILED = (False, None)


def _guarded(function: Callable[..., Any], args: tuple) -> tuple[bool, Any]:
    """In the worker: ``(True, function(*args))``; where it raised a typed outcome (``planning.solver.outcomes``: no
    plan, none verified, infeasible), ``(False, that exception)``, raised as it is where it is taken; where it raised
    anything else (a fault), :data:`_FAILED` (made again by the caller, whose traceback is then its own)."""
    try:
        return True, function(*args)
    except PlanningError as error:
        return False, error
    except Exception:  # noqa: BLE001 - made again where it is taken
        return _FAILED


def core_free() -> bool:
    """Whether a core is free for a short call made ahead: the 1-minute load average is under the cores less a half
    (where other processes hold every core, a test run's or a script's, a forked worker would only take turns with
    this process and cost its fork; a long call made ahead pays either way)."""
    try:
        return os.getloadavg()[0] < _cores() - LOAD_FREE
    except OSError:  # no load average here: as if free
        return True


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def _can_fork() -> bool:
    """A second core, ``fork``, no other thread running, not a daemon process (which may have no children)."""
    cores = _cores()
    return (
        cores >= 2
        and "fork" in multiprocessing.get_all_start_methods()
        and threading.active_count() == 1
        and not multiprocessing.current_process().daemon
    )
