"""Types of command-line values that the CLI and the outputs' options share (argparse types: a wrong value is
one line naming the option)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Option:
    """A command-line option of ``pressplan solve`` that an output takes: ``flag`` and argparse's keyword
    arguments (``dest`` is the name the output reads in :attr:`Written.options`)."""

    flag: str
    kwargs: dict[str, Any]


def whole(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: a whole number in ``lo ... hi``."""
    return _ranged(int, "a whole number", lo, hi, "")


def number(lo: float, hi: float, unit: str = "") -> Callable[[str], float]:
    """An argparse type: a number in ``lo ... hi`` (``unit`` named in the message)."""
    return _ranged(float, "a number", lo, hi, unit)


def _ranged(kind: Callable[[str], Any], what: str, lo: float, hi: float, unit: str) -> Callable[[str], Any]:
    """An argparse type: ``kind`` of the text, within ``lo ... hi`` (NaN is not)."""

    def parse(text: str) -> Any:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"must be {lo:g} ... {hi:g}{' ' + unit if unit else ''}, got {text}")
        return value

    return parse


def whole_or_auto(lo: int, hi: int) -> Callable[[str], int | str]:
    """An argparse type: ``auto`` or a whole number in ``lo ... hi``."""
    count = whole(lo, hi)

    def parse(text: str) -> int | str:
        return "auto" if text.strip().lower() == "auto" else count(text)

    return parse


def listed(choices: tuple[str, ...]) -> Callable[[str], tuple[str, ...]]:
    """An argparse type: comma-separated words each one of ``choices`` (``all``: every one)."""

    def parse(text: str) -> tuple[str, ...]:
        words = tuple(w.strip().lower() for w in text.split(",") if w.strip())
        if words == ("all",):
            return choices
        wrong = [w for w in words if w not in choices]
        if wrong or not words:
            raise argparse.ArgumentTypeError(f"expected {', '.join(choices)} or all (comma-separated), got {text!r}")
        return tuple(dict.fromkeys(words))

    return parse
