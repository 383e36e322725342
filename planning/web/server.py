"""``pressplan serve``: a local web page to plan a press motion, on Flask, with plotly.js for the charts.

The page (``static/``) sends the case it shows as JSON; every answer comes from the same functions as
the CLI: ``case_from_data`` (the validated reader), ``solve``, ``time_optimal_bound``, ``result_dict``, the
outputs' registry (``planning.reports.outputs``: the downloads). Nothing here solves, checks or evaluates a
plan on its own: the charts and the files read the plan's evaluation, made once by its verification. Every
answer's ``status`` is an :class:`~planning.model.outcome.Outcome`.

Safety: the server binds to 127.0.0.1 unless told otherwise; a request body is at most
:data:`MAX_REQUEST_BYTES`; an uploaded case goes through the reader's limits (256 kB, depth, values);
case files are offered by name from one folder, and a name is looked up in that listing, never joined
to a path; each browser tab sends its own session id, and a session's plan (its warm start) is seen by
no other session. A solve is superseded by a newer edit of the same session: a request that was
overtaken while it waited returns at once, so at most one solve runs and one waits per session. The
solves of all sessions share two fair queues (:class:`FairQueue`), one for the fast answers (one warm
start from the session's plan) and one for the cold solves that confirm them: in each at most
:data:`SOLVES_AT_ONCE` run, and the waiting session served least recently goes first. So one tab's burst
of edits, or many tabs' cold solves, delay another tab's fast answer to an edit by the fast answers
already running at most (``benchmarks/bench_web.py`` measures it under a 20-session burst). With a cold-solve
worker (``serve``), an edit's cold solve starts in a worker process when its fast request comes, and the confirm
request takes it (``planning.web.workers``): the two solves side by side. A confirmed
answer is kept by its case (:data:`ANSWER_CACHE` of them): the same case again, from any tab, is
answered without a solve. The number of sessions kept is bounded (:data:`MAX_SESSIONS`, the least
recently used is dropped).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import threading
from collections import OrderedDict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import numpy as np
import yaml
from flask import Flask, Response, jsonify, request, send_file
from werkzeug.exceptions import HTTPException, RequestEntityTooLarge

from planning.model.case import OBJECTIVES, ROBOT_NAMES, Case, Mode, RobotOrder
from planning.model.case_file import MAX_BYTES, CaseFileError, case_from_data, load_yaml, read_case, too_large_words
from planning.model.laws import LAWS
from planning.model.outcome import Outcome
from planning.reports.new_case import MECHANISMS, drive_template, robots_template
from planning.reports.outputs import downloads
from planning.reports.outputs._cam import CamOptionError
from planning.solver.ahead import WorkerProcess
from planning.solver.outcomes import PlanningError
from planning.web.cams import (
    CAM_FILES,
    CamCache,
    CamRequestError,
    attachment,
    cam_file,
    cam_meta,
    options_of,
    proof_answer,
    proved,
    refused,
)
from planning.web.workers import ColdSolves, PendingCold

STATIC = Path(__file__).resolve().parent / "static"
PENDULUM_BOUND_LEAVES_OUT = (  # what the pendulum's bound leaves out (``planning.solver.pendulum_bound``)
    "limits.crank_jerk_rad_s3",
    "limits.min_crank_speed_rpm",
    "the motor's and the crank's torques",
    "the turns",
)
MAX_REQUEST_BYTES = 2 * MAX_BYTES  # a case as JSON, with the page's own fields
MAX_SESSIONS = 64
CHART_POINTS = 600  # samples of a plan's curves sent to the page (the files keep the full 1 ms step)
DRAWING_STEP_DEG = 2.0  # [deg] the mechanism's drawing is sent at every such crank angle from TDC
BOUND_CACHE = 32
ANSWER_CACHE = 32  # confirmed answers kept by case (each about 0.2 MB with its curves and solution)
SOLVES_AT_ONCE = 2  # solves running at once; IPOPT takes one call at a time per process, so two interleave


@dataclass
class Session:
    """One browser tab: its last plan (the next solve's warm start) and the newest request it sent."""

    lock: threading.Lock = field(default_factory=threading.Lock)  # held while the session's solve runs
    guard: threading.Lock = field(default_factory=threading.Lock)  # held while ``newest`` changes
    newest: int = -1
    plan: Any = None
    shown: tuple[str, Any, Any] | None = None  # the last confirmed plan: (its case's key, case, solution)
    pending: PendingCold | None = None  # the cold solve started in the worker for the last edit's fast request
    cam: CamCache = field(default_factory=CamCache)  # the last cam proved of it (planning.web.cams)


class FairQueue:
    """The solves of every session: at most ``slots`` run at once, one per session; a session waits with
    its newest request only (an older waiting one is superseded), and of the waiting sessions the one
    whose last solve started earliest (or that never solved) starts first. So a session that keeps
    sending (or many of them) delays another session's request by the solves already running, never by
    its own queue."""

    def __init__(self, slots: int = SOLVES_AT_ONCE) -> None:
        self._cond = threading.Condition()
        self._slots = slots
        self._running: set[str] = set()
        self._waiting: dict[str, list[int]] = {}  # session -> [seq] of its newest waiting request
        self._last_start: dict[str, int] = {}
        self._clock = itertools.count()

    def run(self, key: str, seq: int, work: Any) -> Any:
        """``work()`` when this request's turn comes; :data:`SUPERSEDED` when a newer request of the same
        session arrives first."""
        ticket = [seq]
        with self._cond:
            waiting = self._waiting.get(key)
            if waiting is not None:
                if waiting[0] > seq:
                    return SUPERSEDED
                waiting[0] = -1  # overtaken: that request returns at once
                self._cond.notify_all()
            self._waiting[key] = ticket
            while ticket[0] >= 0 and not self._turn(key):
                self._cond.wait()
            if ticket[0] < 0:
                return SUPERSEDED
            del self._waiting[key]
            self._running.add(key)
            self._last_start[key] = next(self._clock)
            if len(self._last_start) > 4 * MAX_SESSIONS:  # forget sessions long gone
                keep = self._running | set(self._waiting)
                self._last_start = {k: v for k, v in self._last_start.items() if k in keep}
        try:
            return work()
        finally:
            with self._cond:
                self._running.discard(key)
                self._cond.notify_all()

    def _turn(self, key: str) -> bool:
        if len(self._running) >= self._slots or key in self._running:
            return False
        ready = [k for k in self._waiting if k not in self._running]  # in order of arrival
        return min(ready, key=lambda k: self._last_start.get(k, -1)) == key


SUPERSEDED = object()


class Sessions:
    """The sessions by id, at most :data:`MAX_SESSIONS` (least recently used dropped)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._items: OrderedDict[str, Session] = OrderedDict()

    def get(self, key: str) -> Session:
        with self._lock:
            session = self._items.pop(key, None) or Session()
            self._items[key] = session
            while len(self._items) > MAX_SESSIONS:
                self._items.popitem(last=False)
            return session


def case_files(folder: Path | None) -> dict[str, Path]:
    """The case files offered by name: ``*.yaml`` in ``folder``."""
    if folder is None or not folder.is_dir():
        return {}
    return {p.name: p for p in sorted(folder.glob("*.yaml")) if p.is_file()}


@dataclass
class _Shared:
    """What the requests of every session share: the case files ``offered`` by name, the ``sessions``, the two
    solve ``queues``, the confirmed ``answers`` and the ``bounds`` kept by case key (each with its lock), and
    the bounds' worker process."""

    offered: dict[str, Path]
    sessions: Sessions = field(default_factory=Sessions)
    queues: dict[str, FairQueue] = field(default_factory=lambda: {"fast": FairQueue(), "cold": FairQueue()})
    answers: OrderedDict = field(default_factory=OrderedDict)  # case key -> (answer, case, solution)
    answers_lock: threading.Lock = field(default_factory=threading.Lock)
    bounds: OrderedDict = field(default_factory=OrderedDict)
    bounds_lock: threading.Lock = field(default_factory=threading.Lock)
    bound_pool: Any = None
    cold_worker: ColdSolves | None = None
    recipes: Path | None = None


def create_app(
    cases_dir: Path | None = None,
    initial: Path | None = None,
    allowed_hosts: tuple[str, ...] = (),
    recipes_dir: Path | None = None,
    cold_worker: bool = False,
) -> Flask:
    """The application: the page, its static files and the JSON endpoints. Requests are answered for the
    host names of this machine and ``allowed_hosts`` (the address ``serve`` binds) only. With
    ``recipes_dir`` the page saves cases under a name there and reopens them (``planning.web.recipes``).
    ``cold_worker``: an edit's confirming cold solve runs in a worker process beside its fast answer
    (``planning.web.workers``; ``serve`` and the browser tests); without, after it in this process. Either way
    the cold solve's plan or better; ``close_app`` stops the worker processes."""
    import logging

    logging.getLogger("werkzeug").setLevel(logging.WARNING)  # no line per request
    app = Flask(__name__, static_folder=None)
    app.config["MAX_CONTENT_LENGTH"] = MAX_REQUEST_BYTES
    offered = case_files(cases_dir)
    if initial is not None:
        offered = {initial.name: initial, **{k: v for k, v in offered.items() if k != initial.name}}
    shared = _Shared(offered, bound_pool=_BoundPool(), recipes=recipes_dir)
    shared.cold_worker = ColdSolves() if cold_worker else None
    app.extensions["pressplan_workers"] = [shared.bound_pool.worker, shared.cold_worker]  # stopped by close_app
    app.extensions["pressplan_sessions"] = shared.sessions  # the tests hold a session's lock to see superseding
    app.extensions["pressplan_queues"] = shared.queues  # the edits' fast answers never wait behind cold solves
    _guard(app, allowed_hosts)
    _page_routes(app, shared)
    _solve_routes(app, shared)
    _recipe_routes(app, shared)
    return app


def _guard(app: Flask, allowed_hosts: tuple[str, ...]) -> None:
    """Only this machine's names and the address served; every error answered as JSON the page reads."""
    allowed = {"localhost", "127.0.0.1", "::1", *allowed_hosts}
    everyone = bool(allowed & {"0.0.0.0", "::"})  # bound to every address: the user opened it to the network

    @app.before_request
    def host_allowed() -> tuple[Response, int] | None:
        """Only the names of this machine and the address it binds: a page on another site that rebinds
        its own name to 127.0.0.1 (DNS rebinding) reaches nothing."""
        host = _hostname(request.host or "").lower()  # host names are case-insensitive
        origin = request.headers.get("Origin")  # a request another site's page sends names that site
        sender = _hostname(urlsplit(origin).netloc).lower() if origin and origin != "null" else None
        if everyone or (host in allowed and (sender is None or sender in allowed)):
            return None
        name = host if host not in allowed else sender
        return jsonify({"status": Outcome.BAD_INPUT, "message": f"host {name!r} is not served here"}), 403

    @app.errorhandler(BadRequest)
    def bad_request(exc: BadRequest) -> Response:
        return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc)}), 400

    @app.errorhandler(HTTPException)
    def http_error(exc: HTTPException) -> Response:
        """Every HTTP error as JSON the page reads (413 too large, 404 no such route, 405 wrong method)."""
        messages = {413: too_large_request()}
        message = messages.get(exc.code, f"{exc.code} {exc.name}")
        return jsonify({"status": Outcome.BAD_INPUT, "message": message}), exc.code


def _page_routes(app: Flask, shared: _Shared) -> None:
    """The page, its static files, what it offers (``/api/meta``), the cases by name and uploads."""
    offered = shared.offered

    @app.get("/")
    def index() -> Response:
        return send_file(STATIC / "index.html")

    @app.get("/static/<name>")
    def static_file(name: str) -> Response:
        files = {"app.js": STATIC / "app.js", "style.css": STATIC / "style.css", "plotly.min.js": _plotly_js()}
        if name not in files:
            return jsonify({"status": Outcome.BAD_INPUT, "message": f"/static/{name}: no such file"}), 404
        return send_file(files[name], max_age=3600)

    @app.get("/api/meta")
    def meta() -> Response:
        return jsonify(
            {
                "cases": list(offered),
                "initial": next(iter(offered), None),
                "laws": list(LAWS),
                "objectives": list(OBJECTIVES),
                "placements": ["free", "published"],
                "fields": field_specs(),
                "drive_templates": {kind: drive_template(kind) for kind in MECHANISMS},
                "robot_templates": {kind: robots_template(kind) for kind in MECHANISMS},
                "outcomes": {outcome.name: outcome.value for outcome in Outcome},
                "downloads": [{"name": o.name, "title": o.title} for o in downloads()],
                "cam": cam_meta(),
                "max_case_bytes": MAX_BYTES,
                "recipes": shared.recipes is not None,
            }
        )

    @app.get("/api/case/<name>")
    def load_case(name: str) -> Response:
        path = offered.get(name)
        if path is None:
            return jsonify({"status": Outcome.BAD_INPUT, "message": f"{name}: no such case here"}), 404
        try:
            case = read_case(path)
        except CaseFileError as exc:
            return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": exc.field}), 400
        return jsonify({"label": _label(path), "case": _data(case)})

    @app.post("/api/upload")
    def upload() -> Response:
        file = request.files.get("file")
        if file is None:
            return jsonify({"status": Outcome.BAD_INPUT, "message": "the request sends no file"}), 400
        name = Path(file.filename or "upload.yaml").name[:100]
        blob = file.read(MAX_BYTES + 1)
        try:  # a case refused is an answer (its outcome and line), not an HTTP error: the page shows it
            if len(blob) > MAX_BYTES:
                raise CaseFileError(f"{name}: {too_large_words()}")
            try:
                text = blob.decode("utf-8")
            except UnicodeDecodeError:
                raise CaseFileError(f"{name}: not UTF-8 text, expected a YAML case") from None
            case = case_from_data(load_yaml(text, name), name)
        except CaseFileError as exc:
            return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": exc.field})
        return jsonify({"label": name, "case": _data(case)})


def _recipe_routes(app: Flask, shared: _Shared) -> None:
    """The recipes of the folder the server is given: listed, saved under a name, reopened."""
    from planning.web.recipes import RecipeError, recipe_names, recipe_path, save_recipe

    def folder() -> Path:
        if shared.recipes is None:
            raise BadRequest("no recipes here: start the server with --recipes DIR")
        return shared.recipes

    @app.get("/api/recipes")
    def recipes() -> Response:
        return jsonify({"names": recipe_names(folder())})

    @app.get("/api/recipe/<name>")
    def open_recipe(name: str) -> Response:
        try:
            path = recipe_path(folder(), name)
        except RecipeError as exc:
            return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": "recipe"}), 400
        if not path.is_file():
            return jsonify({"status": Outcome.BAD_INPUT, "message": f"{name}: no such recipe here"}), 404
        try:
            case = read_case(path)
        except CaseFileError as exc:
            return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": exc.field}), 400
        return jsonify({"label": f"recipe {name}", "case": _data(case)})

    @app.post("/api/recipes")
    def keep_recipe() -> Response:
        """Save the body's ``case`` as recipe ``name`` (in the body: a name with a slash is refused by its rule,
        not lost in the route); a refusal is an answer (200) the page shows."""
        body = _body()
        name = body.get("name")
        try:
            path = recipe_path(folder(), name)
            case = case_from_data(body.get("case"), _label_of(body))
        except RecipeError as exc:
            return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": "recipe"})
        except CaseFileError as exc:  # only a case that reads is kept
            return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": exc.field})
        try:
            save_recipe(path, _data(case))
        except OSError as exc:  # the folder read-only, full, or the name taken by a folder
            message = f"recipe {name}: cannot be written to the recipes' folder ({exc.strerror or exc})"
            return jsonify({"status": Outcome.ERROR, "message": message, "field": "recipe"})
        return jsonify({"saved": path.stem, "names": recipe_names(folder())})


def _solve_routes(app: Flask, shared: _Shared) -> None:
    """The solves (fast, then confirmed), the bound, the downloads of the confirmed plan."""

    @app.post("/api/solve")
    def solve_endpoint() -> Response:
        body = _body()
        key = str(body.get("session", ""))[:80]
        session = shared.sessions.get(key)
        seq = int(body.get("seq", 0)) if isinstance(body.get("seq", 0), int) else 0
        with session.guard:
            session.newest = max(session.newest, seq)
        fast = body.get("confirm") is not True and session.plan is not None  # else solve_case solves cold
        answer = shared.queues["fast" if fast else "cold"].run(key, seq, lambda: _answer(shared, session, body, seq))
        answer = {"status": Outcome.INTERRUPTED} if answer is SUPERSEDED else answer
        return jsonify({**answer, "seq": seq})

    @app.post("/api/bound")
    def bound_endpoint() -> Response:
        body = _body()
        data = body.get("case")
        key = case_key(data)
        with shared.bounds_lock:
            if key in shared.bounds:
                return jsonify(shared.bounds[key])
        answer = shared.bound_pool.run(data, _label_of(body))
        with shared.bounds_lock:
            shared.bounds[key] = answer
            while len(shared.bounds) > BOUND_CACHE:
                shared.bounds.popitem(last=False)
        return jsonify(answer)

    @app.post("/api/download/<name>")
    def download(name: str) -> Response:
        body = _body()
        label = _label_of(body)
        try:
            case = case_from_data(body.get("case"), label)
        except CaseFileError as exc:
            return jsonify({"status": Outcome.BAD_INPUT, "message": str(exc), "field": exc.field}), 400
        if name == "case.yaml":
            text = yaml.safe_dump(_data(case), sort_keys=False, allow_unicode=True)
            return Response(text, mimetype="application/x-yaml", headers=_attachment(f"{case.name}.yaml"))
        if name not in {o.name for o in downloads()} and name not in CAM_FILES:
            return jsonify({"status": Outcome.BAD_INPUT, "message": f"{name}: no such file"}), 404
        session = shared.sessions.get(str(body.get("session", ""))[:80])
        with session.guard:
            shown = session.shown
        if name in CAM_FILES:
            return _cam_response(session, shown, body, label, name)
        return files_of(shown, body.get("case"), label, name)

    @app.post("/api/cam")
    def cam_endpoint() -> Response:
        body = _body()
        session = shared.sessions.get(str(body.get("session", ""))[:80])
        with session.guard:
            shown = session.shown
        return _cam_response(session, shown, body, _label_of(body), None)


def _cam_response(session: Session, shown: Any, body: dict[str, Any], label: str, name: str | None) -> Any:
    """The cam of the confirmed plan on screen: its proof (``name`` None) or its file ``name``."""
    if _pendulum(body.get("case")):
        return jsonify({"status": Outcome.BAD_INPUT, "message": PENDULUM_FILES.format(label=label)}), 409
    if shown is None or shown[0] != case_key(body.get("case")):
        message = f"{label}: no confirmed plan of this case on the page yet; wait for the plan, then prove its cam"
        return jsonify({"status": Outcome.BAD_INPUT, "message": message}), 409
    try:
        written = proved(session.cam, shown, options_of(body))
    except (CamRequestError, CamOptionError, PlanningError) as exc:  # the options, or a limit the cam breaks
        answer, code = refused(exc)
        return answer if name is None else (answer, code)  # a proof refused is an answer the page shows
    return proof_answer(written) if name is None else cam_file(written, name)


def _answer(shared: _Shared, session: Session, body: dict[str, Any], seq: int) -> dict[str, Any]:
    """One solve request of ``session`` when its turn comes: interrupted when a newer one of the session came
    first; this case's confirmed answer when one is kept (from any tab: no solve); else the solve's."""
    with session.lock:
        if seq < session.newest:
            return {"status": Outcome.INTERRUPTED}
        data = body.get("case")
        label = _label_of(body)
        known = case_key({"label": label, "case": data})
        with shared.answers_lock:
            hit = shared.answers.get(known)
            if hit is not None:
                shared.answers.move_to_end(known)
        if hit is not None:  # this case's confirmed answer, from any tab: no solve
            answer, case, solution = hit
            session.plan = solution.plan
            with session.guard:
                session.shown = (case_key(data), case, solution)
            return dict(answer)
        answer = solve_case(data, label, session, body.get("confirm") is True, shared.cold_worker)
        if answer.get("confirmed") and answer["status"] is Outcome.VERIFIED and session.shown is not None:
            with shared.answers_lock:  # (a pendulum's answer is not kept: no plan of it is shown for downloads)
                shared.answers[known] = (answer, *session.shown[1:])
                while len(shared.answers) > ANSWER_CACHE:
                    shared.answers.popitem(last=False)
        return answer


def _hostname(host: str) -> str:
    """The name in a Host header: ``localhost:8050`` -> ``localhost``, ``[::1]:8050`` -> ``::1``."""
    if host.startswith("["):
        return host[1:].split("]", 1)[0]
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


def too_large_request() -> str:
    """The one wording of the request's size limit (a case file's own limit, and the page's fields with it)."""
    return f"the request is too large (more than {MAX_REQUEST_BYTES} bytes; {too_large_words()})"


class BadRequest(Exception):
    """A request the page never sends: answered 400 with ``{"status": Outcome.BAD_INPUT, "message": ...}``."""


MAX_JSON_DEPTH = 32  # a request nests 4 deep (case -> section -> table -> row); deeper is refused unparsed


def _body() -> dict[str, Any]:
    """The request's JSON object; :class:`BadRequest` when it is not one (malformed, nested deeper than
    :data:`MAX_JSON_DEPTH`, another type). The depth is counted before parsing, so no input reaches the
    parser's recursion limit."""
    if request.mimetype != "application/json":  # the page's; another site's form (text/plain) is not read
        raise BadRequest("the request's body is not JSON (Content-Type: application/json)")
    if request.content_length is None and request.environ.get("wsgi.input_terminated"):
        # chunked: at most one byte past the limit, then refused (the request's own stream stops at the limit
        # without a word: the server's decoded input is read)
        raw = request.environ["wsgi.input"].read(MAX_REQUEST_BYTES + 1)
        if len(raw) > MAX_REQUEST_BYTES:
            raise RequestEntityTooLarge()
    else:  # a length given (or none and no chunks: no body)
        raw = request.get_data(cache=True)
    if _depth(raw) > MAX_JSON_DEPTH:
        raise BadRequest(f"the request nests deeper than {MAX_JSON_DEPTH} levels")
    try:
        body = json.loads(raw)
    except (ValueError, RecursionError):
        raise BadRequest("the request's body is not JSON") from None
    if not isinstance(body, dict):
        raise BadRequest("the request's body is not a JSON object")
    if "case" not in body:  # every POST of the page sends the case it shows
        raise BadRequest("the request sends no case")
    return body


def _depth(raw: bytes) -> int:
    """The deepest nesting of brackets and braces in JSON text ``raw``, strings skipped."""
    depth = deepest = 0
    in_string = escaped = False
    for byte in raw:
        if in_string:
            if escaped:
                escaped = False
            elif byte == 0x5C:  # backslash
                escaped = True
            elif byte == 0x22:  # quote
                in_string = False
        elif byte == 0x22:
            in_string = True
        elif byte in (0x5B, 0x7B):
            depth += 1
            deepest = max(deepest, depth)
        elif byte in (0x5D, 0x7D):
            depth -= 1
    return deepest


def _label_of(body: dict[str, Any]) -> str:
    """The name the messages use for the case (as the CLI uses the file's path), printable, short."""
    label = str(body.get("label") or "case")
    return "".join(ch for ch in label if ch.isprintable())[:120] or "case"


def _label(path: Path) -> str:
    """``cases/NAME.yaml`` for the project's cases (as the CLI is run from the project root)."""
    return f"{path.parent.name}/{path.name}" if path.parent.name == "cases" else path.name


def _data(case: Case) -> dict[str, Any]:
    return case.model_dump(exclude_none=True)


def _attachment(name: str) -> dict[str, str]:
    safe = "".join(ch for ch in name if ch.isalnum() or ch in "._-") or "file"
    return {"Content-Disposition": f'attachment; filename="{safe}"'}


def _plotly_js() -> Path:
    import plotly

    return Path(plotly.__file__).resolve().parent / "package_data" / "plotly.min.js"


def field_specs() -> list[dict[str, Any]]:
    """The form's fields: dotted name, kind (number | choice | table | label: shown, not edited), optional or
    not, choices, and the words the page shows: ``title`` (with the unit) and ``help``, the case model's
    own (``planning.model.case``: each field's title and description)."""
    from planning.sweep import numeric_fields

    specs: list[dict[str, Any]] = []
    for name in numeric_fields():
        model, leaf = _model_at(name)
        info = model.model_fields[leaf]
        specs.append({"name": name, "kind": "number", "optional": not info.is_required()})
    specs += [
        {"name": "press.mechanism", "kind": "label"},  # a case's mechanism is its file's (each has its own keys)
        {"name": "planner.motion_law", "kind": "choice", "choices": list(LAWS)},
        {"name": "planner.placement", "kind": "choice", "choices": ["free", "published"]},
        {"name": "planner.objective", "kind": "choice", "choices": list(OBJECTIVES)},
        {"name": "planner.mode", "kind": "choice", "choices": list(Mode.__args__)},
        {"name": "process.forming_force_kN", "kind": "table", "optional": True, "columns": ["height mm", "force kN"]},
        {"name": "robots.order", "kind": "choice", "choices": list(RobotOrder.__args__)},
    ]
    for robot in ROBOT_NAMES:
        name, columns = f"robots.{robot}.interference_mm", ["position mm", "height mm"]
        specs.append({"name": name, "kind": "table", "optional": False, "columns": columns})
    for spec in specs:
        model, leaf = _model_at(spec["name"])
        info = model.model_fields[leaf]
        spec["title"], spec["help"] = info.title or leaf, info.description or ""
    return specs


def _model_at(dotted: str) -> tuple[type, str]:
    model: Any = Case
    *parents, leaf = dotted.split(".")
    for name in parents:
        ann = model.model_fields[name].annotation
        model = next(a for a in getattr(ann, "__args__", (ann,)) if isinstance(a, type))
    return model, leaf


def solve_case(
    data: Any, label: str, session: Session, confirm: bool = True, worker: ColdSolves | None = None
) -> dict[str, Any]:
    """Validate and solve ``data`` from the session's last plan; the page's answer. ``confirm`` False: the
    fast answer from the last plan alone when it verifies (``confirmed`` False in the answer: the page
    then asks again with ``confirm``); else the cold solve's answer or better (``confirmed`` True). With a
    ``worker``, the fast request starts the cold solve there at once (``planning.web.workers``)."""
    from planning.reports.report import columns_at, result_dict, summary_text
    from planning.solver.optimize import solve_from
    from planning.solver.outcomes import Infeasible, PlanningError

    try:
        case = case_from_data(data, label)
    except CaseFileError as exc:
        return {"status": Outcome.BAD_INPUT, "message": str(exc), "field": exc.field}
    if case.pendulum:
        return _pendulum_answer(case, label, session)
    try:
        solution = None
        if not confirm and session.plan is not None:
            pending = _cold_started(worker, case, (data, label), session)
            solution = solve_from(case, session.plan)  # fast; another local optimum is possible
            if pending is not None:
                pending.fast = solution
        confirmed = solution is None
        if solution is None:
            solution = _cold_or_better(case, (data, label), session, worker)
    except PlanningError as exc:
        limit = exc.limit if isinstance(exc, Infeasible) else None
        return {"status": exc.outcome, "message": f"{label}: {exc}", "field": limit, "confirmed": True, **_warned(case)}
    session.plan = solution.plan
    if confirmed:  # the downloads' plan: the last confirmed one (a fast answer on screen is confirmed next)
        with session.guard:
            session.shown = (case_key(data), case, solution)
    result = result_dict(solution, case)
    columns = columns_at(solution.evaluation, case, solution.evaluation.rows(CHART_POINTS))
    curves = {name: _rounded(col) for name, col in columns.items()}
    return {
        "status": Outcome.VERIFIED,
        "confirmed": confirmed,
        "result": _finite(result),
        "curves": curves,
        "limit_lines": chart_limits(result, columns),
        "summary": summary_text(result),
        "mechanism": mechanism_drawing(case),
        "utilisation": utilisation(solution.verification, case),
        **_warned(case),
    }


def _cold_started(worker: ColdSolves | None, case: Case, sent: tuple, session: Session) -> PendingCold | None:
    """The cold solve of ``case`` (``sent``: the page's data and label it was read from) started in ``worker`` for
    the session's fast request (the session's older one withdrawn where it still waits), or None: no worker, an
    objective at the line's rate (its neighbour starts the search there and is not compared with a cold solve:
    solved here), or a case the prechecks refuse (the fast request says why; nothing to confirm)."""
    from planning.solver.precheck import precheck

    older, session.pending = session.pending, None
    if worker is None:
        return None
    if older is not None:
        worker.drop(older)
    if case.planner.objective != "max-spm":
        return None
    try:
        precheck(case)
    except PlanningError:
        return None
    session.pending = worker.start(str(id(session)), _sent_key(sent), sent)
    return session.pending


def _cold_or_better(case: Case, sent: tuple, session: Session, worker: ColdSolves | None) -> Any:
    """The cold solve's answer or better: the better of the worker's cold solve of this case (started by its fast
    request) and the fast answer, as ``solve`` with the neighbour gives; where there is none (no worker, another
    case, not started yet, the worker found no plan or is gone) ``solve`` here, the session's plan the neighbour. A
    case solved here before the worker ever ran starts the worker (its imports and NLPs made while the user looks
    at the plan)."""
    from planning.solver.optimize import better, solve

    pending, session.pending = session.pending, None
    if worker is not None and pending is not None and pending.key != _sent_key(sent):
        worker.drop(pending)  # another case's
    elif worker is not None and pending is not None:
        cold = worker.take(pending)
        if cold is not None:
            return better(cold, pending.fast)
    if worker is not None and case.planner.objective == "max-spm":
        worker.warm_up(sent)
    return solve(case, neighbour=session.plan)


def _sent_key(sent: tuple) -> str:
    """The key of the case the page sent (its data and label)."""
    return case_key({"label": sent[1], "case": sent[0]})


def _pendulum_answer(case: Case, label: str, session: Session) -> dict[str, Any]:
    """The page's answer for a pendulum case (``planning.solver.pendulum_rate.solve_swings``): a cold solve each
    time (no fast answer from the last plan yet), in the summary the rotary stroke's rate beside it (at a line's
    rate: the baseline's figure instead); no downloads yet."""
    from planning.reports.pendulum import pendulum_page_result, pendulum_summary
    from planning.reports.report import columns_at
    from planning.solver.outcomes import Infeasible, PlanningError
    from planning.solver.pendulum_rate import solve_swings

    try:
        solution = solve_swings(case)
    except PlanningError as exc:
        limit = exc.limit if isinstance(exc, Infeasible) else None
        return {"status": exc.outcome, "message": f"{label}: {exc}", "field": limit, "confirmed": True, **_warned(case)}
    session.plan = None  # a rotary solve's warm start cannot start from a swing
    with session.guard:
        session.shown = None
    result = pendulum_page_result(solution, case)
    columns = columns_at(solution.evaluation, case, solution.evaluation.rows(CHART_POINTS))
    return {
        "status": Outcome.VERIFIED,
        "confirmed": True,
        "result": _finite(result),
        "curves": {name: _rounded(col) for name, col in columns.items()},
        "limit_lines": chart_limits(result, columns),
        "summary": pendulum_summary(result),
        "mechanism": mechanism_drawing(case),
        "utilisation": utilisation(solution.evaluation.verification, case),
        **_warned(case),
    }


def utilisation(verification: Any, case: Case) -> list[dict[str, Any]]:
    """Each limit's use by the plan, in the case's order of limits: the check's value over its limit (a lower
    limit: the limit over the value), whether it binds."""
    from planning.model.limits import limits_of
    from planning.solver.verify import field_of_check

    order = {limit.id: k for k, limit in enumerate(limits_of(case))}
    rows = []
    for check in verification.checks:
        if check.id not in order or check.kind not in ("max", "min"):
            continue
        value, limit = abs(check.value), abs(check.limit)
        if limit == 0 or (check.kind == "min" and value == 0):
            continue
        share = value / limit if check.kind == "max" else limit / value
        if not math.isfinite(share):
            continue
        field = field_of_check(check.id)
        rows.append({"id": check.id, "name": check.name, "field": field, "pct": 100 * share, "binds": check.binds})
    return sorted(rows, key=lambda row: order[row["id"]])


def _warned(case: Case) -> dict[str, Any]:
    """The case's plausibility warnings (``planning.model.plausibility``): shown beside their fields."""
    from planning.model.plausibility import warnings_of

    return {"warnings": [{"field": w.field, "message": w.message} for w in warnings_of(case)]}


def chart_limits(result: dict[str, Any], columns: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    """The case's limits as the page's charts draw them: the figures' lines (``limit_lines``), each over
    the chart's samples (None where it does not apply; the same samples against time or crank angle), a
    limit at one crank angle with that point on both axes."""
    from planning.reports.limit_lines import limit_lines

    by_time = limit_lines(result, columns, "time")
    out = []
    for line, timed in zip(limit_lines(result, columns, "angle"), by_time, strict=True):
        item: dict[str, Any] = {"field": line.field, "label": line.label, "quantity": line.quantity}
        item["colour"] = line.colour
        item["point"] = line.point
        item["upper"] = _finite(_rounded(line.upper))
        item["lower"] = _finite(_rounded(line.lower)) if line.lower is not None else None
        if line.point:
            item["at"] = {"angle": float(line.x[0]), "time": float(timed.x[0])}
        out.append(item)
    return out


def mechanism_drawing(case: Case) -> dict[str, Any]:
    """The mechanism as the page draws it: every joint's position [mm] at crank angles from TDC every
    :data:`DRAWING_STEP_DEG`, the bars between joints (a triangle for a ternary link) and the fixed joints."""
    machine = case.machine
    angles = np.arange(0.0, 360.0 + DRAWING_STEP_DEG / 2, DRAWING_STEP_DEG)
    joints = machine.joints(np.radians(angles))
    return {
        "kind": machine.kind,
        "angles_deg": angles.tolist(),
        "joints": {name: [_rounded(np.round(x, 2)), _rounded(np.round(y, 2))] for name, (x, y) in joints.items()},
        "bars": [list(bar) for bar in machine.bars],
        "fixed": list(machine.fixed),
    }


class _BoundPool:
    """The bounds are computed in a worker process (``planning.web.workers``): a bound takes about half a second,
    and in the server's process it would hold IPOPT (one call at a time) while the next edit's solve waits."""

    def __init__(self) -> None:
        self.worker = WorkerProcess()

    def run(self, data: Any, label: str) -> dict[str, Any]:
        try:
            return self.worker.submit(bound_of, data, label).result()
        except Exception as exc:  # noqa: BLE001 - the bound is extra information: say why it is missing
            return {"message": f"no bound ({type(exc).__name__})"}


def close_app(app: Flask) -> None:
    """Stop the application's worker processes now (work under way is dropped)."""
    for worker in app.extensions["pressplan_workers"]:
        if worker is not None:
            worker.close()


def bound_of(data: Any, label: str) -> dict[str, Any]:
    """The case's certified upper bound (as ``pressplan laws`` computes it) and its grid bound, or why
    there is none."""
    from planning.reports.law_comparison import LAWS_UPPER_PIECES, LAWS_UPPER_POINTS
    from planning.solver.bound import time_optimal_bound
    from planning.solver.outcomes import PlanningError
    from planning.solver.upper_bound import upper_bound

    try:
        case = case_from_data(data, label)
        if case.pendulum:  # its certified bound (``planning.solver.pendulum_bound``); no grid bound
            from planning.solver.pendulum_bound import pendulum_bound

            return {"spm": None, "upper_spm": pendulum_bound(case).spm, "left_out": list(PENDULUM_BOUND_LEAVES_OUT)}
        upper = upper_bound(case, LAWS_UPPER_POINTS, LAWS_UPPER_PIECES)
        grid = time_optimal_bound(case)
    except (CaseFileError, PlanningError) as exc:
        return {"message": str(exc)}
    return {"spm": grid.spm, "upper_spm": upper.spm, "left_out": list(upper.left_out)}


PENDULUM_FILES = (  # the page's downloads and cams are off for a pendulum case
    "{label}: a pendulum plan's files and cams come from the CLI (pressplan solve, pressplan cam); "
    "the page's downloads are off for swings"
)


def _pendulum(data: Any) -> bool:
    """The case data the page sent plans pendulum strokes."""
    planner = data.get("planner") if isinstance(data, dict) else None
    return isinstance(planner, dict) and planner.get("mode") == "pendulum"


def case_key(data: Any) -> str:
    """A key of a case's data as the page sends it (the same edits give the same key)."""
    return hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()


def files_of(shown: tuple[str, Any, Any] | None, data: Any, label: str, name: str) -> tuple[Response, int] | Response:
    """One file of the confirmed plan on screen, as ``pressplan solve`` writes it (that output's writer
    alone; no solve here); 409 when the case sent is not the one whose confirmed plan is shown."""
    from planning.reports.outputs import writer_of

    if _pendulum(data):
        return jsonify({"status": Outcome.BAD_INPUT, "message": PENDULUM_FILES.format(label=label)}), 409
    if shown is None or shown[0] != case_key(data):
        message = f"{label}: no confirmed plan of this case on the page yet; wait for the plan, then download"
        return jsonify({"status": Outcome.BAD_INPUT, "message": message}), 409
    _, case, solution = shown
    write = writer_of(solution, case, name)
    if write is None:
        return jsonify({"status": Outcome.BAD_INPUT, "message": f"{name}: this plan has no such file"}), 404
    return attachment(write, name)


def _rounded(column: np.ndarray) -> list[float]:
    """Chart values to 7 significant digits (the page's charts need no more; the files keep all)."""
    return [float(f"{v:.7g}") for v in column.tolist()]


def _finite(value: Any) -> Any:
    """``value`` with NaN and infinities as None (JSON has neither)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value


def serve(
    case_path: Path | None,
    host: str,
    port: int,
    cases_dir: Path | None,
    recipes_dir: Path | None = None,
    compile_nlps: bool = True,
) -> None:
    """Run the server until Ctrl-C; prints the address. ``compile_nlps``: compile the NLPs the page's solves
    build, in the background (``planning.solver.background``), where a C compiler and the cache are there."""
    from planning.solver.background import BackgroundCompiler

    app = create_app(cases_dir, case_path, (host,), recipes_dir, cold_worker=True)
    compiler = BackgroundCompiler().start() if compile_nlps and BackgroundCompiler.available() else None
    print(f"pressplan: serving on http://{host}:{port}/ (Ctrl-C stops)", flush=True)
    if compiler is not None:
        print(COMPILING, flush=True)
    try:
        app.run(host=host, port=port, threaded=True, use_reloader=False)
    finally:  # Ctrl-C or SIGTERM (raised in this thread by the CLI): no worker process outlives the server
        close_app(app)
        if compiler is not None:
            compiler.close()


COMPILING = (
    "pressplan: the NLPs the page builds are compiled in the background, one at a time (20-60 s each, kept in the "
    "cache for later runs); a solve then takes about 0.6 times as long (--no-compile: they stay interpreted)"
)
