"""Reading a case file (YAML) into a validated :class:`~planning.model.case.Case` (the only case I/O).

A case file is untrusted input. The reader bounds what it can cost: at most :data:`MAX_BYTES`
bytes, nesting at most :data:`MAX_DEPTH` deep, at most :data:`MAX_NODES` YAML nodes, and no aliases
(``*name``: the alias bomb's tool; a case never needs one). A key given twice in one mapping is an
error naming it (YAML's "last one wins" would hide a typo). Numbers follow YAML 1.2: ``3.5e3`` and
``1e-2`` are numbers, as an engineer means them (the YAML 1.1 loader reads them as strings). Every
value is then range-checked by the case model (``planning.model.case``), so no arithmetic on a
case can overflow.
"""

from __future__ import annotations

import copy
import difflib
import re
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import BaseModel, ValidationError

from planning.model.case import Case, CaseError, cross_checks, show_value

MAX_BYTES = 256_000  # a case is about 2 kB
MAX_DEPTH = 12  # a case nests 4 deep
MAX_NODES = 5_000  # a case has about 60
# YAML 1.2 floats that YAML 1.1 reads as strings: an exponent without a sign or without a decimal point
_FLOAT_12 = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9][0-9_]*)[eE][-+]?[0-9]+$")


class _CaseLoader(yaml.SafeLoader):
    """PyYAML's safe loader with the limits above; YAML 1.2 exponent floats; no aliases."""

    yaml_implicit_resolvers = {k: list(v) for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()}

    def __init__(self, stream: str):
        super().__init__(stream)
        self.depth = 0
        self.nodes = 0

    def compose_node(self, parent, index):  # noqa: ANN001 - PyYAML's signature
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise _Refused(event.start_mark, f"aliases (*{event.anchor}) are not allowed in a case file")
        self.depth += 1
        self.nodes += 1
        if self.depth > MAX_DEPTH:
            raise _Refused(self.peek_event().start_mark, f"nested more than {MAX_DEPTH} levels deep")
        if self.nodes > MAX_NODES:
            raise _Refused(self.peek_event().start_mark, f"more than {MAX_NODES} values")
        try:
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1


_CaseLoader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT_12, list("-+0123456789."))
# YAML 1.1 reads 1:30 as 90 (base 60) and 010 as 8 (octal): numbers no engineer means. They stay
# strings, so the case model rejects them as "not a number" instead of reading a different value.
_MISREAD = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?::[0-5]?[0-9])+(?:\.[0-9_]*)?|0[0-7_]+)$")
for _first in "-+0123456789":
    _CaseLoader.yaml_implicit_resolvers[_first].insert(0, ("tag:yaml.org,2002:str", _MISREAD))


class _Refused(Exception):
    """A YAML document the reader will not load: where (a PyYAML mark) and why."""

    def __init__(self, mark, problem: str):  # noqa: ANN001 - a PyYAML mark
        super().__init__(problem)
        self.mark = mark
        self.problem = problem


class CaseFileError(ValueError):
    """A case file that cannot be used; ``str()`` is the one-line message ``FILE: field: problem``;
    ``field`` the dotted case field it names (None when the problem is the file as a whole)."""

    def __init__(self, message: str, field: str | None = None):
        super().__init__(message)
        self.field = field


def read_case(path: str | Path, overrides: dict[str, Any] | None = None) -> Case:
    """Read, parse and validate a case file; raises :class:`CaseFileError` with a one-line message.
    ``overrides``: dotted case fields and the values that replace the file's (``process.transfer_time_s``
    -> 1.8), set before validation, so a value is checked as if the file held it."""
    path = Path(path)
    raw = _read_text(path)
    data = load_yaml(raw, str(path))
    if overrides:
        data = with_fields(data, overrides, str(path))
    return case_from_data(data, str(path))


def with_fields(data: Any, overrides: dict[str, Any], label: str = "<case>") -> Any:
    """A copy of the case mapping ``data`` with each dotted field of ``overrides`` set (sections made as
    needed); :class:`CaseFileError` when a field's parent is a value, not a section."""
    if not isinstance(data, dict):
        return data
    out = copy.deepcopy(data)
    for field, value in overrides.items():
        node = out
        *parents, leaf = field.split(".")
        for i, key in enumerate(parents):
            node = node.setdefault(key, {})
            if not isinstance(node, dict):
                raise CaseFileError(f"{label}: {'.'.join(parents[: i + 1])}: is a value, not a section", field)
        node[leaf] = value
    return out


def load_yaml(text: str, label: str = "<case>") -> Any:
    """Parse YAML text within the reader's limits; :class:`CaseFileError` (one line) if it cannot be."""
    loader = None
    try:
        loader = _CaseLoader(text)
        node = loader.get_single_node()
        if node is None:
            return None
        _check_duplicate_keys(node, label)
        return loader.construct_document(node)
    except _Refused as exc:
        where = f"line {exc.mark.line + 1}, column {exc.mark.column + 1}: " if exc.mark else ""
        raise CaseFileError(f"{label}: {where}{exc.problem}") from None
    except RecursionError:  # not reached within the depth limit; kept so no input can show a traceback
        raise CaseFileError(f"{label}: nested too deeply") from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = exc.problem or exc.context or "invalid YAML"
        raise CaseFileError(f"{label}: YAML syntax error: {where}{problem}") from None
    except yaml.YAMLError as exc:
        raise CaseFileError(f"{label}: YAML syntax error: {_first_line(str(exc))}") from None
    finally:
        if loader is not None:
            loader.dispose()


def _check_duplicate_keys(node: yaml.Node, label: str, path: tuple[str, ...] = ()) -> None:
    """Raise :class:`CaseFileError` naming the first key that a mapping holds twice."""
    if isinstance(node, yaml.MappingNode):
        seen: set[str] = set()
        for key_node, value_node in node.value:
            key = str(key_node.value)
            field = ".".join((*path, key))
            if key in seen:
                line = key_node.start_mark.line + 1
                raise CaseFileError(f"{label}: {field}: duplicate key (line {line}; each key at most once)")
            seen.add(key)
            _check_duplicate_keys(value_node, label, (*path, key))
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _check_duplicate_keys(item, label, (*path, str(i)))


def too_large_words() -> str:
    """The one wording of a case file's size limit."""
    return f"too large for a case file (more than {MAX_BYTES} bytes)"


def case_from_data(data: Any, label: str = "<case>") -> Case:
    """Validate already-parsed data (a mapping) as a case; ``label`` names it in error messages."""
    if data is None:
        raise CaseFileError(f"{label}: the file is empty")
    if not isinstance(data, dict):
        raise CaseFileError(f"{label}: expected a mapping of case fields at the top level (got {type(data).__name__})")
    if "process" in data and data["process"] is None:  # every process field optional: a section of comments
        data = {**data, "process": {}}
    robots = data.get("robots")
    for role in ("unloader", "loader"):  # an empty robot is not a robot left out (a typo's half-written section)
        if isinstance(robots, dict) and role in robots and robots[role] is None:
            reason = "is empty: give its path, limits, dwell and interference curve, or leave it out"
            raise CaseFileError(f"{label}: robots.{role}: {reason}", f"robots.{role}")
    try:
        case = Case.model_validate(data)
    except ValidationError as exc:
        raise CaseFileError(_pydantic_line(exc, data, label), _pydantic_field(exc)) from None
    try:
        with np.errstate(all="ignore"):
            cross_checks(case)
    except CaseError as exc:
        raise CaseFileError(exc.line(label), exc.field) from None
    except (ArithmeticError, ValueError) as exc:  # the ranges should prevent it; never a traceback
        raise CaseFileError(f"{label}: the numbers cannot be used together ({_first_line(str(exc))})") from None
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
        raise CaseFileError(f"{path}: {too_large_words()} ({len(blob)} bytes)")
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


def _first_error(exc: ValidationError) -> dict:
    # an unknown key explains a "missing" one next to it (a typo): report it first
    return min(exc.errors(include_url=False), key=lambda e: 0 if e["type"] == "extra_forbidden" else 1)


def _pydantic_field(exc: ValidationError) -> str:
    return ".".join(str(p) for p in _first_error(exc)["loc"])


def _pydantic_line(exc: ValidationError, data: Any, label: str, model: type[BaseModel] = Case) -> str:
    """The one line of a file's first validation error (``model``: the file's, a case's or a line's)."""
    err = _first_error(exc)
    loc = [str(p) for p in err["loc"]]
    field = ".".join(loc)
    kind = err["type"]
    value = err.get("input")
    if kind == "extra_forbidden":
        home = _section_of(loc[-1]) if len(loc) == 2 and model is Case else None
        if home is not None and home != loc[0]:  # a key of another section: say where it belongs
            return f"{label}: {field}: unknown key here; it belongs under {home}: ({home}.{loc[-1]})"
        valid = _fields_at(model, [p for p in loc[:-1] if not p.isdigit()])
        hint = difflib.get_close_matches(loc[-1], valid, n=1, cutoff=0.5)
        did = f"; did you mean '{hint[0]}'?" if hint else f"; valid keys: {', '.join(valid)}"
        return f"{label}: {field}: unknown key{did}"
    if kind == "missing":
        return f"{label}: {field}: missing required field"
    if kind in ("model_type", "dict_type"):  # (pydantic names its class: a section to the reader)
        return f"{label}: {field}: must be a section of keys (got {show_value(value)})"
    msg = err["msg"]
    msg = msg[0].lower() + msg[1:] if msg else kind
    return f"{label}: {field}: {msg} (got {show_value(value)})"


def _section_of(key: str) -> str | None:
    """The top-level section of the case whose own keys include ``key`` (None: none, or several)."""
    homes = [name for name in Case.model_fields if key in _fields_at(Case, [name])]
    return homes[0] if len(homes) == 1 else None


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
