"""The page's cam for the controller: the confirmed plan on screen proved as a cam (``POST /api/cam``) and its
file (``POST /api/download/<cam file>``), with the options ``pressplan cam`` takes (``planning.reports.outputs.
_cam``), checked by the same parsers: a wrong value is the CLI's line, next to the field it names.

The page sends ``cam: {target, interpolation, count}`` (a target of ``csv``, ``codesys``, ``twincat``,
``plcopen``; ``poly5``, ``spline`` or ``linear``; a number of points or ``auto``); the proof answers with what
the CLI prints: the points, the slide's deviation from the plan, whether every limit holds and the highest
master speed that keeps them (or the refusal: the limit a cam breaks). A session keeps its last proved cam, so
its download writes that cam without proving it again."""

from __future__ import annotations

import argparse
import json
import tempfile
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from flask import Response, jsonify

from planning.model.outcome import Outcome
from planning.reports.outputs import OUTPUTS, Written
from planning.reports.outputs._cam import COUNT, FORMATS, INTERPOLATION, TARGETS, CamOptionError

CAM_FILES = frozenset(
    pattern
    for output in OUTPUTS
    if output.name.startswith("cam_") and output.name != "cam_table.csv"
    for pattern in output.files
)
MIME = {".csv": "text/csv", ".st": "text/plain", ".xml": "application/xml", ".json": "application/json"}


@dataclass
class CamCache:
    """A session's last proved cam: ``key`` (the case's key and the options), its :class:`Written`."""

    lock: threading.Lock = field(default_factory=threading.Lock)
    key: str = ""
    written: Written | None = None


class CamRequestError(ValueError):
    """A cam option the page sent that cannot be used: ``field`` is the form's field (``cam-count``)."""

    def __init__(self, field_name: str, message: str) -> None:
        super().__init__(message)
        self.field = field_name


def cam_meta() -> dict[str, Any]:
    """What the page offers: the targets, each with the interpolations it takes."""
    return {"targets": {target: [i.value for i in FORMATS[target]] for target in TARGETS}}


def options_of(body: dict[str, Any]) -> dict[str, Any]:
    """The outputs' options (by dest) of the page's ``cam``: parsed as the CLI parses them."""
    cam = body.get("cam")
    if not isinstance(cam, dict):
        raise CamRequestError("cam-target", "cam: expected the cam's target, interpolation and points")
    target = str(cam.get("target", ""))
    if target not in TARGETS:
        raise CamRequestError("cam-target", f"--cam: expected one of {', '.join(TARGETS)}, got {target!r}")
    interpolation = str(cam.get("interpolation", ""))
    if interpolation not in INTERPOLATION.kwargs["choices"]:
        choices = ", ".join(INTERPOLATION.kwargs["choices"])
        raise CamRequestError("cam-interpolation", f"--cam-interpolation: expected {choices}, got {interpolation!r}")
    try:
        count = COUNT.kwargs["type"](str(cam.get("count", "auto")))
    except argparse.ArgumentTypeError as exc:
        raise CamRequestError("cam-count", f"--cam-count: {exc}") from None
    return {"cam": (target,), "cam_interpolation": interpolation, "cam_count": count}


def proved(cache: CamCache, shown: tuple[str, Any, Any], options: dict[str, Any]) -> Written:
    """The session's proved cam for the plan ``shown`` and ``options`` (proved now unless it is the last one)."""
    key = shown[0] + json.dumps(options, sort_keys=True, default=str)
    with cache.lock:
        if cache.key == key and cache.written is not None:
            return cache.written
        _, case, solution = shown
        written = Written(solution, case, options)
        written.cam  # noqa: B018 - proved here (raises when the options do not go together or a limit breaks)
        cache.key, cache.written = key, written
        return written


def proof_answer(written: Written) -> dict[str, Any]:
    """The proof as the page shows it beside the cam's button."""
    from planning.reports.cam_export import proof_dict, proof_lines

    export = written.cam
    data = proof_dict(export)
    name = next(n for n in _writers(written) if n != "cam_proof.json")
    return {
        "status": Outcome.VERIFIED,
        "file": name,
        "points": data["points"],
        "deviation_mm": data["deviation_mm"],
        "highest_speed_pct": data["highest_speed_pct"],
        "above": [] if export.proof.above is None else [c.name for c in export.proof.above.failures()],
        "lines": proof_lines(export),
    }


def refused(exc: Exception) -> tuple[Response, int]:
    """A cam the page cannot have: options that do not go together (400, next to the field) or a cam that
    breaks a limit (422, the refusal's line)."""
    if isinstance(exc, CamRequestError):
        return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": exc.field}), 400
    if isinstance(exc, CamOptionError):
        field_name = exc.option.removeprefix("--")
        return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": field_name}), 400
    return jsonify({"status": Outcome.UNVERIFIED, "message": getattr(exc, "reason", str(exc))}), 422


def cam_file(written: Written, name: str) -> Response | tuple[Response, int]:
    """The file ``name`` of the proved cam, as ``pressplan cam`` writes it."""
    write = _writers(written).get(name)
    if write is None:
        return jsonify({"status": Outcome.BAD_INPUT, "message": f"{name}: not a file of this cam"}), 404
    return attachment(write, name)


def attachment(write: Any, name: str) -> Response:
    """The file one writer writes, as a download named ``name`` (a writer writes into a scratch folder)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / name
        write(path)
        blob = path.read_bytes()
    safe = "".join(ch for ch in name if ch.isalnum() or ch in "._-") or "file"
    headers = {"Content-Disposition": f'attachment; filename="{safe}"'}
    return Response(blob, mimetype=MIME.get(Path(name).suffix, "text/plain"), headers=headers)


def _writers(written: Written) -> dict[str, Any]:
    writers: dict[str, Any] = {}
    for output in OUTPUTS:
        if any(pattern in CAM_FILES for pattern in output.files):
            writers.update(output.writers(written))
    return writers
