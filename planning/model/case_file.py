"""Reading a case file (YAML) into a validated :class:`~planning.model.case.Case` (the only case I/O)."""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from planning.model.case import Case, CaseError, cross_checks, show_value

MAX_BYTES = 1_000_000


class CaseFileError(ValueError):
    """A case file that cannot be used; ``str()`` is the one-line message ``FILE: field: problem``."""


def read_case(path: str | Path) -> Case:
    """Read, parse and validate a case file; raises :class:`CaseFileError` with a one-line message."""
    path = Path(path)
    raw = _read_text(path)
    try:
        data = yaml.safe_load(raw)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = exc.problem or exc.context or "invalid YAML"
        raise CaseFileError(f"{path}: YAML syntax error: {where}{problem}") from None
    except yaml.YAMLError as exc:
        raise CaseFileError(f"{path}: YAML syntax error: {_first_line(str(exc))}") from None
    return case_from_data(data, str(path))


def case_from_data(data: Any, label: str = "<case>") -> Case:
    """Validate already-parsed data (a mapping) as a case; ``label`` names it in error messages."""
    if data is None:
        raise CaseFileError(f"{label}: the file is empty")
    if not isinstance(data, dict):
        raise CaseFileError(f"{label}: expected a mapping of case fields at the top level (got {type(data).__name__})")
    try:
        case = Case.model_validate(data)
    except ValidationError as exc:
        raise CaseFileError(_pydantic_line(exc, data, label)) from None
    try:
        cross_checks(case)
    except CaseError as exc:
        raise CaseFileError(exc.line(label)) from None
    return case


def _read_text(path: Path) -> str:
    if not path.exists():
        raise CaseFileError(f"{path}: no such file")
    if not path.is_file():
        raise CaseFileError(f"{path}: not a regular file")
    try:
        blob = path.read_bytes()
    except OSError as exc:
        raise CaseFileError(f"{path}: cannot be read ({exc.strerror})") from None
    if len(blob) > MAX_BYTES:
        raise CaseFileError(f"{path}: too large for a case file ({len(blob)} bytes > {MAX_BYTES})")
    if b"\x00" in blob:
        raise CaseFileError(f"{path}: binary file, expected a YAML case")
    try:
        text = blob.decode("utf-8")
    except UnicodeDecodeError:
        raise CaseFileError(f"{path}: not UTF-8 text, expected a YAML case") from None
    if not text.strip():
        raise CaseFileError(f"{path}: the file is empty")
    return text


def _first_line(text: str) -> str:
    return " ".join(text.split())


def _pydantic_line(exc: ValidationError, data: Any, label: str) -> str:
    errors = exc.errors(include_url=False)
    # an unknown key explains a "missing" one next to it (a typo): report it first
    err = min(errors, key=lambda e: 0 if e["type"] == "extra_forbidden" else 1)
    loc = [str(p) for p in err["loc"]]
    field = ".".join(loc)
    kind = err["type"]
    value = err.get("input")
    if kind == "extra_forbidden":
        valid = _fields_at(Case, loc[:-1])
        hint = difflib.get_close_matches(loc[-1], valid, n=1, cutoff=0.5)
        did = f"; did you mean '{hint[0]}'?" if hint else f"; valid keys: {', '.join(valid)}"
        return f"{label}: {field}: unknown key{did}"
    if kind == "missing":
        return f"{label}: {field}: missing required field"
    msg = err["msg"]
    msg = msg[0].lower() + msg[1:] if msg else kind
    return f"{label}: {field}: {msg} (got {show_value(value)})"


def _fields_at(model: type[BaseModel], path: list[str]) -> list[str]:
    """Field names of the (nested) model at ``path``."""
    for name in path:
        field = model.model_fields.get(name)
        if field is None:
            return []
        ann = field.annotation
        nested = [a for a in getattr(ann, "__args__", (ann,)) if isinstance(a, type) and issubclass(a, BaseModel)]
        if not nested:
            return []
        model = nested[0]
    return list(model.model_fields)
