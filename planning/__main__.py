"""``pressplan`` and ``python -m planning``: the handlers of Ctrl-C and SIGTERM set first (``planning.interrupts``),
then the command's modules loaded and run (``planning.cli.run``): a Ctrl-C while they load (a few tenths of a
second) ends the run as one during a solve does, with one line and exit 130, not a traceback."""

from __future__ import annotations

from planning.interrupts import install, stopping


def run() -> None:
    """The console script's entry point."""
    install()
    stopping(_command)


def _command() -> None:
    from planning.cli import run as command

    command()


if __name__ == "__main__":
    run()
