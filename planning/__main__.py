"""``pressplan`` and ``python -m planning``: the handlers of Ctrl-C and SIGTERM set first (``planning.interrupts``),
then the command's modules loaded and run (``planning.cli.run``): a Ctrl-C while they load (a few tenths of a
second) ends the run as one during a solve does, with one line and exit 130, not a traceback."""

from __future__ import annotations

from planning.interrupts import EXIT_INTERRUPTED, EXIT_TERMINATED, Terminated, install, stop


def run() -> None:
    """The console script's entry point."""
    install()
    try:
        from planning.cli import run as command
    except KeyboardInterrupt:
        stop("pressplan: interrupted", EXIT_INTERRUPTED)
    except Terminated:
        stop("pressplan: terminated", EXIT_TERMINATED)
    command()


if __name__ == "__main__":
    run()
