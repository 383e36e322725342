"""Types of command-line values that the CLI and the outputs' options share (argparse types: a wrong value is
one line naming the option)."""

from __future__ import annotations

import argparse
from collections.abc import Callable


def whole(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: a whole number in ``lo ... hi``."""

    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if not lo <= n <= hi:
            raise argparse.ArgumentTypeError(f"must be {lo} ... {hi}, got {n}")
        return n

    return parse
