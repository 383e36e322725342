"""The NLPs a long-lived process builds, compiled in the background (``pressplan serve``).

A :class:`BackgroundCompiler` watches the SX problems the process has built (``planning.solver.ipopt.BUILT``: the
page's solves build them as cases come) and compiles each, one at a time in a daemon thread, into the cache
(``planning.solver.compiled``: the same functions, the same plans, about 0.6 times the solve time); the compiler runs
at a lower priority (:data:`NICENESS`) so that the solves keep the cores. A solver swaps to its compiled functions
when they are made (under the IPOPT lock: a solve under way finishes with the interpreted ones). Without a compiler
or a cache (:meth:`BackgroundCompiler.available`) ``pressplan serve`` starts none and its solves stay interpreted, as
with ``--no-compile``. :meth:`BackgroundCompiler.close` stops the thread and kills a compiler under way (none
outlives the process; the compiler's temporary files are in the cache's temporary folder, removed with it).
"""

from __future__ import annotations

import sys
import threading
import weakref
from collections.abc import Callable, Iterable

from planning.solver.compiled import Cancel, cache_dir, compiler
from planning.solver.ipopt import BUILT, NLPSolver

NICENESS = 10  # the background compiler's (the solves' priority stays the process's)
POLL_S = 1.0  # [s] how often the thread looks for a newly built problem


class BackgroundCompiler:
    """Compiles every SX problem this process builds, in a daemon thread (module docstring). ``say``: where the
    lines about it go (one when a problem is compiled); ``source``: the solvers it looks at (by default every one
    the process has built, ``BUILT``)."""

    def __init__(
        self,
        say: Callable[[str], None] | None = None,
        poll_s: float = POLL_S,
        source: Callable[[], Iterable[NLPSolver]] = lambda: BUILT,
    ) -> None:
        self._say = say or (lambda text: print(f"pressplan: {text}", file=sys.stderr, flush=True))
        self._source = source
        self._poll_s = poll_s
        self._stop = threading.Event()
        self._cancel = Cancel()
        self._handled: weakref.WeakSet = weakref.WeakSet()  # the solvers compiled or tried
        self._failed: set[str] = set()  # the keys whose compile failed (not tried again)
        self._busy = False  # a compile under way
        self._thread = threading.Thread(target=self._run, name="pressplan-compiler", daemon=True)
        self.compiled: list[str] = []  # the solvers' names, as they were compiled

    @staticmethod
    def available() -> bool:
        """A compiler and a cache are there (else nothing would be compiled)."""
        return compiler() is not None and cache_dir() is not None

    def start(self) -> BackgroundCompiler:
        self._thread.start()
        return self

    def pending(self) -> bool:
        """A built problem waits for its compile, or one is under way."""
        return self._busy or bool(self._waiting())

    def close(self) -> None:
        """Stop the thread; kill a compiler under way (its problem stays interpreted)."""
        self._stop.set()
        self._cancel.stop()
        if self._thread.is_alive():
            self._thread.join(timeout=10)

    def _run(self) -> None:
        while not self._stop.wait(self._poll_s):
            for solver in self._waiting():
                if self._stop.is_set():
                    return
                self._busy = True
                self._handled.add(solver)
                try:
                    seconds = solver.compile(NICENESS, self._cancel)  # 0.0: compiled before (another solver of it)
                except Exception as exc:  # noqa: BLE001 - a thread of a server: said in one line, never a traceback
                    self._say(f"{solver.name} not compiled ({type(exc).__name__}: {exc}); it stays interpreted")
                    seconds = None
                finally:
                    self._busy = False
                if self._stop.is_set():
                    return
                if seconds is None:
                    self._failed.add(solver.key)
                elif seconds > 0:
                    self.compiled.append(solver.name)
                    self._say(f"{solver.name} compiled in {seconds:.0f} s: its solves run compiled from now on")

    def _waiting(self) -> list[NLPSolver]:
        """The built SX problems not compiled nor tried yet (a problem whose compile failed is not tried again)."""
        try:
            built = list(self._source())
        except RuntimeError:  # a solver built while the set was read: next time
            return []
        fresh = [s for s in built if s.compilable and not s.compiled and s not in self._handled]
        return [s for s in fresh if s.key not in self._failed]
