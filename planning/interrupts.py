"""Ctrl-C and SIGTERM in the ``pressplan`` command: raised in the main thread as ``KeyboardInterrupt`` and
:class:`Terminated`, so that the clean-up in ``finally`` blocks (worker processes, temporary folders) runs, and the
command ends with one line and exit 130 or 143 (:func:`stopping`), wherever in its run the signal arrives.

Python raises a signal's exception at the main thread's next bytecode. Where that bytecode lies in a Python function
that CasADi's C++ layer called (its wrappers convert an argument by trying Python functions in turn, and take an
exception raised there for "not this type"), the exception is swallowed and the run goes on: a Ctrl-C while an NLP was
built ended the run with exit 0 after the whole solve. A signal that arrives while CasADi's Python code is on the
stack is therefore delivered again :data:`RETRY_S` later (a one-shot timer's SIGALRM, the handler it replaced put
back when it fires), until it arrives outside that code (a build of a few tenths of a second at most) or
:data:`RETRY_LIMIT_S` have passed (then it is raised where it is). Signals waiting for that are delivered together,
SIGTERM first. Inside an IPOPT call ``planning.solver.ipopt`` handles the signal itself. Where the platform has no
such timer (Windows), the exception is raised at once, as Python does.

This module loads nothing heavy: ``planning.__main__`` sets the handlers before the command's modules load, so that a
Ctrl-C while they load ends the run in the same way.
"""

from __future__ import annotations

import signal
import sys
import time
from collections.abc import Callable
from types import FrameType
from typing import NoReturn, TypeVar

from planning.model.outcome import Outcome

RETRY_S = 0.005  # [s] a signal that arrived inside CasADi's code is delivered again this much later ...
RETRY_LIMIT_S = 2.0  # [s] ... until this long after it first arrived: then it is raised where it is
EXIT_INTERRUPTED, EXIT_TERMINATED = Outcome.INTERRUPTED.exit_code, Outcome.TERMINATED.exit_code
_waiting: dict[int, float] = {}  # the signals delivered again later, and when each first arrived [s, monotonic]
_alarm_before: list = []  # while the retry's timer is set: SIGALRM's handler before it
T = TypeVar("T")


class Terminated(BaseException):
    """SIGTERM, raised in the main thread so that clean-up (worker processes, temporary folders) runs."""


def install() -> None:
    """Ctrl-C and SIGTERM handled as the module docstring says (from the main thread; a Ctrl-C that this process
    ignores, as one started in the background of a shell does, stays ignored)."""
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)


def on_signal(signum: int, frame: FrameType | None) -> None:
    """The handler: ``KeyboardInterrupt`` for SIGINT, :class:`Terminated` for SIGTERM, or, while CasADi's Python code
    is on the stack (where the exception would be swallowed), the same signal again :data:`RETRY_S` later."""
    first = _waiting.pop(signum, time.monotonic())
    if hasattr(signal, "setitimer") and _inside_casadi(frame) and time.monotonic() - first < RETRY_LIMIT_S:
        if not _alarm_before:  # (else the timer set for the one waiting delivers this one too)
            _alarm_before.append(signal.signal(signal.SIGALRM, _deliver_waiting))
            signal.setitimer(signal.ITIMER_REAL, RETRY_S)
        _waiting[signum] = first
        return
    _cancel_timer()
    _waiting.clear()
    raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt


def _deliver_waiting(_signum: int, _frame: FrameType | None) -> None:
    """The timer's SIGALRM: its handler put back as it was, the signal waiting delivered again (SIGTERM where both
    wait: the run ends either way)."""
    _cancel_timer()
    chosen = signal.SIGTERM if signal.SIGTERM in _waiting else next(iter(_waiting), None)
    for other in [s for s in _waiting if s != chosen]:
        del _waiting[other]
    if chosen is not None:
        signal.raise_signal(chosen)


def _cancel_timer() -> None:
    """The retry's timer stopped and SIGALRM's handler put back as it was before (where the timer is set)."""
    if _alarm_before:
        signal.setitimer(signal.ITIMER_REAL, 0)
        before = _alarm_before.pop()
        signal.signal(signal.SIGALRM, before if before is not None else signal.SIG_DFL)


def _inside_casadi(frame: FrameType | None) -> bool:
    """Whether a frame of CasADi's Python modules is on the stack from ``frame`` outwards."""
    while frame is not None:
        if frame.f_globals.get("__name__", "").partition(".")[0] == "casadi":
            return True
        frame = frame.f_back
    return False


def stopping(function: Callable[[], T]) -> T:
    """``function()``; a Ctrl-C or SIGTERM meanwhile ends the process with one line and exit 130 or 143 (:func:`stop`)
    once the clean-up on the way out has run."""
    try:
        return function()
    except KeyboardInterrupt:
        stop("pressplan: interrupted", EXIT_INTERRUPTED)
    except Terminated:
        stop("pressplan: terminated", EXIT_TERMINATED)


def stop(message: str, code: int) -> NoReturn:
    """End an interrupted run with one line: the clean-up in ``finally`` blocks has run on the way here; the
    interpreter's own exit is skipped, since a worker pool's thread torn down mid-read would print a traceback after
    the line."""
    import os

    print(message, file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
