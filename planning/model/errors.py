"""A problem with a case, naming its dotted field: what the case checks raise and the reader reports."""

from __future__ import annotations

from typing import Any


class CaseError(ValueError):
    """A problem with a case: ``field`` (dotted path), ``message``, and the offending ``value``."""

    def __init__(self, field: str, message: str, value: Any = None, has_value: bool = True):
        self.field = field
        self.message = message
        self.value = value
        self.has_value = has_value
        super().__init__(self.line())

    def line(self, file: str | None = None) -> str:
        """One line ``FILE: field: message (got VALUE)``."""
        parts = [p for p in (file, self.field) if p]
        got = f" (got {show_value(self.value)})" if self.has_value else ""
        return ": ".join(parts + [f"{self.message}{got}"])


def show_value(value: Any) -> str:
    """A value as an error message quotes it: strings quoted, at most 60 characters."""
    text = repr(value) if isinstance(value, str) else str(value)
    return text if len(text) <= 60 else text[:57] + "..."
