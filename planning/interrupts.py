"""Ctrl-C and SIGTERM in the ``pressplan`` command: raised in the main thread as ``KeyboardInterrupt`` and
:class:`Terminated`, so that the clean-up in ``finally`` blocks (worker processes, temporary folders) runs and the
command ends with one line and exit 130 or 143 (:func:`stop`), wherever the signal arrives.

Python raises a signal's exception at the main thread's next bytecode. Where that bytecode lies in a Python function
that CasADi's C++ layer called (its wrappers convert an argument by trying Python functions in turn, and take an
exception raised there for "not this type"), the exception is swallowed and the run goes on: a Ctrl-C while an NLP was
built ended the run with exit 0 after the whole solve. A signal that arrives while CasADi's Python code is on the
stack is therefore delivered again :data:`RETRY_S` later (a timer's SIGALRM), until it arrives outside that code (a
build of a few tenths of a second at most). Inside an IPOPT call ``planning.solver.ipopt`` handles the signal itself.

This module loads nothing heavy: ``planning.__main__`` sets the handlers before the command's modules load, so that a
Ctrl-C while they load ends the run in the same way.
"""

from __future__ import annotations

import signal
import sys
from types import FrameType
from typing import NoReturn

from planning.model.outcome import Outcome

RETRY_S = 0.005  # [s] a signal that arrived inside CasADi's code is delivered again this much later
EXIT_INTERRUPTED, EXIT_TERMINATED = Outcome.INTERRUPTED.exit_code, Outcome.TERMINATED.exit_code


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
    if frame is not None and _inside_casadi(frame) and hasattr(signal, "setitimer"):
        signal.signal(signal.SIGALRM, lambda _signum, _frame: signal.raise_signal(signum))
        signal.setitimer(signal.ITIMER_REAL, RETRY_S)
        return
    raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt


def _inside_casadi(frame: FrameType | None) -> bool:
    """Whether a frame of CasADi's Python modules is on the stack from ``frame`` outwards."""
    while frame is not None:
        if frame.f_globals.get("__name__", "").partition(".")[0] == "casadi":
            return True
        frame = frame.f_back
    return False


def stop(message: str, code: int) -> NoReturn:
    """End an interrupted run with one line: the clean-up in ``finally`` blocks has run on the way here; the
    interpreter's own exit is skipped, since a worker pool's thread torn down mid-read would print a traceback after
    the line."""
    import os

    print(message, file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
