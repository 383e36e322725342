"""Reading a line file (the only line I/O): its stations' cases read from their own files, the transfers
checked against the stations' order; every problem one :class:`CaseFileError` line naming the file and the
field."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from planning.model.case_file import CaseFileError, _pydantic_field, _pydantic_line, _read_text, load_yaml, read_case
from planning.model.line import EndModel, Line, LineModel, LineRobot, Station, TransferModel, transfer_robot

LINE_FIELDS = ("path_mm", "speed_mm_s", "accel_mm_s2")  # a transfer's move, when no time_s is given


def read_line(path: str | Path, overrides: dict[str, Any] | None = None) -> Line:
    """Read, parse and validate a line file and each station's case; :class:`CaseFileError` (one line).
    ``overrides``: dotted fields and the values that replace the file's, set before validation: a line
    field (``transfers.0.speed_mm_s``, ``feeder.time_s``) or a station's case field after its name
    (``draw.limits.slider_accel_mm_s2``)."""
    path = Path(path)
    label = str(path)
    data = load_yaml(_read_text(path), label)
    if not isinstance(data, dict):
        raise CaseFileError(f"{label}: expected a mapping of line fields at the top level")
    data, by_station = _with_overrides(data, overrides or {}, label)
    try:
        model = LineModel.model_validate(data)
    except ValidationError as exc:
        raise CaseFileError(_pydantic_line(exc, data, label, LineModel), _pydantic_field(exc)) from None
    stations = tuple(
        _station(model, k, path, by_station.get(model.stations[k].name)) for k in range(len(model.stations))
    )
    robots = _robots(model, label)
    return Line(model.name, model.title, stations, robots, path)


def _with_overrides(data: dict, overrides: dict[str, Any], label: str) -> tuple[dict, dict[str, dict[str, Any]]]:
    """A copy of the line's mapping with its own overridden fields set, and each station's case overrides."""
    data = copy.deepcopy(data)
    stations = data.get("stations")
    names = [s.get("name") for s in stations if isinstance(s, dict)] if isinstance(stations, list) else []
    by_station: dict[str, dict[str, Any]] = {}
    for field, value in overrides.items():
        first, _, rest = field.partition(".")
        if first in names and first not in LineModel.model_fields:
            if not rest:
                raise CaseFileError(f"{label}: {field}: a station's case field follows its name", field)
            by_station.setdefault(first, {})[rest] = value
            continue
        if first not in LineModel.model_fields:
            raise CaseFileError(
                f"{label}: {field}: neither a line field nor a station's case field (draw.limits.die_height_mm)",
                field,
            )
        *parents, leaf = field.split(".")
        node: Any = data
        for part in parents:
            if isinstance(node, list) and part.isdigit() and int(part) < len(node):
                node = node[int(part)]
            elif isinstance(node, dict):
                node = node.setdefault(part, {})
            else:
                raise CaseFileError(f"{label}: {field}: no {part} there", field)
        if isinstance(node, list) or not isinstance(node, dict):
            raise CaseFileError(f"{label}: {field}: not a field", field)
        node[leaf] = value
    return data, by_station


def _station(model: LineModel, k: int, line_path: Path, overrides: dict[str, Any] | None = None) -> Station:
    """Station ``k``: its case read from its file (relative to the line file), with both robots and a law
    that plans at a rate."""
    entry = model.stations[k]
    field = f"stations.{k}.case"
    names = [s.name for s in model.stations]
    if names.index(entry.name) != k:
        raise CaseFileError(f"{line_path}: stations.{k}.name: '{entry.name}' names two stations", f"stations.{k}.name")
    if entry.name in LineModel.model_fields:
        raise CaseFileError(
            f"{line_path}: stations.{k}.name: '{entry.name}' is a line file's key", f"stations.{k}.name"
        )
    case_path = line_path.parent / entry.case
    if not case_path.exists():
        raise CaseFileError(f"{line_path}: {field}: no such file ({case_path})", field)
    if not case_path.is_file():
        raise CaseFileError(f"{line_path}: {field}: not a file ({case_path})", field)
    where = f"{line_path}: {field} ({entry.name}): "
    no_robots = CaseFileError(
        f"{where}{entry.case} has no robots: section (a station of a line needs its unloader and its loader)", field
    )
    try:
        case = read_case(case_path, overrides)
    except CaseFileError as exc:
        if not _has_robots(case_path, overrides):
            raise no_robots from None
        raise CaseFileError(where + str(exc), f"{entry.name}.{exc.field}" if exc.field else field) from None
    if case.robots is None:
        raise no_robots
    missing = [role for role in ("unloader", "loader") if getattr(case.robots, role) is None]
    if missing:
        raise CaseFileError(
            f"{where}{entry.case} has no robots.{missing[0]} (a station of a line needs its unloader and its loader "
            "on their interference curves)",
            field,
        )
    return Station(entry.name, case, case_path)


def _has_robots(case_path: Path, overrides: dict[str, Any] | None) -> bool:
    """Whether the case file (with the run's ``overrides``) holds a ``robots:`` section: its mapping as read."""
    try:
        data = load_yaml(_read_text(case_path), str(case_path))
    except CaseFileError:
        return True  # not the robots' fault: the file's own error says what is
    robots = (overrides or {}).get("robots", data.get("robots") if isinstance(data, dict) else None)
    return robots is not None or any(f.startswith("robots.") for f in overrides or {})


def _robots(model: LineModel, label: str) -> tuple[LineRobot, ...]:
    """The feeder, one transfer robot between each two stations in the stations' order, the exit."""
    names = [s.name for s in model.stations]
    by_pair: dict[int, TransferModel] = {}
    for i, transfer in enumerate(model.transfers):
        k = _transfer_index(transfer, i, names, label)
        if k in by_pair:
            raise CaseFileError(f"{label}: transfers.{i}: a second transfer from '{names[k]}'", f"transfers.{i}")
        _check_move(transfer, i, label)
        by_pair[k] = transfer
    for k in range(len(names) - 1):
        if k not in by_pair:
            raise CaseFileError(
                f"{label}: transfers: none unloads '{names[k]}' and loads '{names[k + 1]}' (one between each two "
                "stations)",
                "transfers",
            )
    end = EndModel(time_s=0.0)
    feeder = LineRobot("feeder", None, 0, (model.feeder or end).time_s)
    exit_robot = LineRobot("exit", len(names) - 1, None, (model.exit or end).time_s)
    return (feeder, *(transfer_robot(by_pair[k], k) for k in range(len(names) - 1)), exit_robot)


def _transfer_index(transfer: TransferModel, i: int, names: list[str], label: str) -> int:
    """The index of the station transfer ``i`` unloads; it must load the next one."""
    for key in ("unloads", "loads"):
        if getattr(transfer, key) not in names:
            field = f"transfers.{i}.{key}"
            raise CaseFileError(f"{label}: {field}: no station '{getattr(transfer, key)}' in stations", field)
    k = names.index(transfer.unloads)
    if k == len(names) - 1 or names[k + 1] != transfer.loads:
        field = f"transfers.{i}.loads"
        after = f"the next is '{names[k + 1]}'" if k < len(names) - 1 else f"'{names[k]}' is the last station"
        raise CaseFileError(
            f"{label}: {field}: '{transfer.loads}' is not the station after '{transfer.unloads}' ({after}; the "
            "parts go through the stations in their order)",
            field,
        )
    return k


def _check_move(transfer: TransferModel, i: int, label: str) -> None:
    """A transfer's move: a time, or a path with its speed and acceleration (not both, not half of one)."""
    given = [key for key in LINE_FIELDS if getattr(transfer, key) is not None]
    if transfer.time_s is not None:
        extra = given + (["jerk_mm_s3"] if transfer.jerk_mm_s3 is not None else [])
        if extra:
            field = f"transfers.{i}.{extra[0]}"
            raise CaseFileError(f"{label}: {field}: give time_s or the path and its limits, not both", field)
        return
    missing = [key for key in LINE_FIELDS if key not in given]
    if missing:
        field = f"transfers.{i}.{missing[0]}"
        raise CaseFileError(f"{label}: {field}: missing (or give time_s, the move's time each way)", field)
