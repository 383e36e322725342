"""The ``pressplan`` command: a thin layer over the Python API.

Exit status: 0 success, 2 bad input (case file, arguments, output folder), 3 no feasible or no
verified plan, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM). Every error is one line on stderr;
no traceback. Outcomes become exit statuses in one place, :func:`_exit_code`.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from planning.model.case import OBJECTIVES
from planning.model.laws import LAWS
from planning.model.outcome import Outcome
from planning.reports.arguments import whole
from planning.reports.new_case import MECHANISMS
from planning.reports.outputs import options as output_options
from planning.reports.outputs.figures import PLOT_FORMATS
from planning.tolerances import TINY_RATE

# the exit statuses, from the one outcome type (planning.model.outcome)
EXIT_OK, EXIT_INPUT, EXIT_INFEASIBLE = (o.exit_code for o in (Outcome.VERIFIED, Outcome.BAD_INPUT, Outcome.NO_PLAN))
SERVE_FIRST = "wang2023-side-panel.yaml"  # the case the page opens with when none is given


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, exit 2
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message}\n")


def _parser() -> argparse.ArgumentParser:
    ap = _Parser(
        prog="pressplan",
        description="Plan the crank speed of a servo press (crank-slider, in line or offset, link drive or knuckle "
        "joint) for the most strokes per minute, verified.",
    )
    ap.add_argument("--version", action="version", version=f"pressplan {_version()}")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for add in (_case_commands, _batch_commands, _bound_command, _line_command, _other_commands):
        add(sub)
    return ap


def _case_commands(sub) -> None:  # noqa: ANN001 - argparse's sub-parsers
    """``new``, ``check``, ``solve`` and ``compare``."""
    n = sub.add_parser("new", help="write a first case file, commented field by field, to edit")
    n.add_argument("file", help="the case file to write (YAML; not over an existing file)")
    n.add_argument("--mechanism", choices=MECHANISMS, default="crank-slider", help="the press (default crank-slider)")
    n.add_argument("--drive", action="store_true", help="with a drive: section (motor, masses, forming force)")
    n.add_argument(
        "--robots",
        action="store_true",
        help="with an unloader and a loader on their interference curves instead of one safety height",
    )
    c = sub.add_parser("check", help="key points and process checks of a case (no solve)")
    _case_argument(c)
    c.add_argument("--json", action="store_true", help="print JSON instead of the table")
    s = sub.add_parser("solve", help="solve, verify and write the fastest cycle")
    _case_argument(s)
    s.add_argument("--out", help="output folder (default: out/<case name>)")
    s.add_argument("--placement", choices=("free", "published"), help="where theta1/theta4 may fall (default: case)")
    s.add_argument("--law", choices=tuple(LAWS), default=None, help="motion law (default: case, improved-s-curve)")
    s.add_argument("--objective", choices=OBJECTIVES, default=None, help="what to optimise (default: case, max-spm)")
    s.add_argument(
        "--spm", type=_rate, default=None, help="the line's rate for min-rms-torque / min-energy / min-grid-peak"
    )
    s.add_argument("--json", action="store_true", help="print result.json instead of the summary")
    for option in output_options():  # what the outputs take (planning.reports.outputs)
        s.add_argument(option.flag, **option.kwargs)
    m = sub.add_parser(
        "compare",
        help="the published solution beside ours, and checked against itself (needs published.solution)",
        description="Solve the case with the published and with free placement, re-simulate the published "
        "solution (published.solution: x1_s ... J_rpm_s2, the paper's vector X) and compare the three.",
    )
    m.add_argument("case", help="case file (YAML) with published.solution (the paper's X vector; see the README)")
    m.add_argument("--out", help="output folder (default: out/<case name>)")
    m.add_argument("--json", action="store_true", help="print comparison.json instead of the table")


def _batch_commands(sub) -> None:  # noqa: ANN001 - argparse's sub-parsers
    """``sweep`` and ``tradeoff``: many solves, on local workers or a Dask cluster."""
    w = sub.add_parser("sweep", help="solve a grid over case fields (resumable, parallel, Dask)")
    w.add_argument("case", help="case file (YAML)")
    w.add_argument(
        "--vary",
        action="append",
        required=True,
        metavar="FIELD=START:STOP:COUNT",
        help="a dotted numeric case field and its values, e.g. process.transfer_time_s=1:3:21",
    )
    w.add_argument("--law", choices=tuple(LAWS), default=None, help="motion law (default: case)")
    w.add_argument("--placement", choices=("free", "published"), help="where theta1/theta4 may fall")
    w.add_argument("--workers", type=whole(1, 256), default=2, help="local worker processes (default 2)")
    w.add_argument("--scheduler", help="address of a Dask distributed scheduler (instead of local workers)")
    w.add_argument("--out", required=True, help="output folder (sweep.csv, sweep.json, sweep_spm.png)")
    w.add_argument("--progress", action="store_true", help=PROGRESS_HELP)
    t = sub.add_parser("tradeoff", help="the least RMS torque, energy or grid peak at each line rate, beside waiting")
    t.add_argument("case", help="case file (YAML) with a drive: section")
    t.add_argument("--spm", required=True, metavar="START:STOP:COUNT", help="rates, e.g. 6:max:7 (max: the fastest)")
    t.add_argument(
        "--objective",
        choices=OBJECTIVES[1:],
        default=None,
        help="min-rms-torque, min-energy or min-grid-peak (default: case, else min-rms-torque)",
    )
    t.add_argument("--law", choices=tuple(LAWS), default=None, help="motion law (default: case)")
    t.add_argument("--placement", choices=("free", "published"), help="where theta1/theta4 may fall")
    t.add_argument("--workers", type=whole(1, 256), default=2, help="local worker processes (default 2)")
    t.add_argument("--scheduler", help="address of a Dask distributed scheduler (instead of local workers)")
    t.add_argument("--out", required=True, help="output folder (tradeoff.csv, tradeoff.json, tradeoff.png)")
    t.add_argument("--progress", action="store_true", help=PROGRESS_HELP)


def _bound_command(sub) -> None:  # noqa: ANN001 - argparse's sub-parsers
    """``bound``: the time-optimal bound, the certified upper bound, the bracket."""
    b = sub.add_parser(
        "bound",
        help="the time-optimal bound on a mesh (from below), the certified upper bound (--certified), the bracket",
        description="The time-optimal bound: the shortest cycle any crank motion within the limits can take, "
        "on a grid of crank angles. 'idle time in the robot's window' is the time the bound waits there: the "
        "transfer time minus the time its crank needs to cross the window (window_slack_s in --json).",
    )
    _case_argument(b)
    b.add_argument(
        "--points", type=whole(2, 1_000_000), default=1440, metavar="N", help="grid intervals (default 1440)"
    )
    b.add_argument(
        "--certified",
        action="store_true",
        help="also the certified upper bound: strokes/min no motion within the limits can exceed (a convex "
        "relaxation; the grid bound approaches the optimum from below and is no upper bound)",
    )
    b.add_argument(
        "--upper-points",
        type=whole(2, 1_000_000),
        default=None,
        metavar="N",
        help="the certified bound's grid intervals (default 1440)",
    )
    b.add_argument(
        "--bracket",
        action="store_true",
        help="the bracket: a verified motion (the optimal law, its layout refined) below the certified upper "
        "bound, refined until their gap is within --tolerance or the refinements run out (it chooses the upper "
        "bound's grids: --upper-points is not used)",
    )
    b.add_argument(
        "--tolerance",
        type=float,
        default=None,
        metavar="PCT",
        help="the bracket's gap to reach [%%] (default 0.05); implies --bracket",
    )
    b.add_argument("--json", action="store_true", help="print JSON")


def _line_command(sub) -> None:  # noqa: ANN001 - argparse's sub-parsers
    """``line``: a press line on one master."""
    ln = sub.add_parser(
        "line",
        help="plan a press line: its presses and robots on one master, the line's strokes per minute, verified",
        description="Plan a line file (its stations' cases, the transfers between them): the line's period, what "
        "binds it, each press's plan at the line's rate and its phase offset on the master, each robot's "
        "schedule; every press's plan and every robot's schedule verified (docs/line.md).",
    )
    ln.add_argument("line", help="line file (YAML): stations, transfers, feeder, exit")
    ln.add_argument("--out", help="output folder (default: out/<line name>)")
    ln.add_argument("--no-plots", action="store_true", help="skip line_timing.png")
    ln.add_argument("--json", action="store_true", help="print line_result.json instead of the summary")
    _set_option(ln, "replace a line field (feeder.time_s) or a station's case field (draw.limits.die_height_mm)")
    ln.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="FIELD=START:STOP:COUNT",
        help="sweep a line's or a station's numeric field (repeatable: a grid): line_sweep.csv and line_sweep.png",
    )
    ln.add_argument("--workers", type=whole(1, 256), default=2, help="local worker processes of a sweep (default 2)")
    ln.add_argument("--scheduler", help="a sweep on a Dask distributed cluster at this address (tcp://host:8786)")
    ln.add_argument("--progress", action="store_true", help=PROGRESS_HELP)


def _other_commands(sub) -> None:  # noqa: ANN001 - argparse's sub-parsers
    """``laws``, ``serve`` and ``plot``."""
    lw = sub.add_parser("laws", help="every motion law on the case, beside the time-optimal bound")
    _case_argument(lw)
    lw.add_argument("--out", help="output folder (default: out/<case name>)")
    lw.add_argument("--json", action="store_true", help="print laws.json instead of the table")
    lw.add_argument("--format", choices=PLOT_FORMATS, default="png", help="figure format (default png)")
    sv = sub.add_parser("serve", help="a local web page to plan a motion interactively (extra 'web')")
    sv.add_argument("case", nargs="?", help="case file (YAML) to open first (default: the published case)")
    sv.add_argument("--port", type=whole(1, 65535), default=8050, help="port (default 8050)")
    sv.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1: this machine only)")
    sv.add_argument(
        "--cases", default="cases", help="folder whose *.yaml the page offers (default: cases, else the project's)"
    )
    sv.add_argument("--recipes", help="folder where the page saves cases under a name and reopens them (made)")
    sv.add_argument(
        "--no-compile",
        action="store_true",
        help="leave the NLPs interpreted (by default those the page builds are compiled in the background with the "
        "C compiler into the cache, as `pressplan compile` does, where there is one)",
    )
    cm = sub.add_parser(
        "cam",
        help="the plan as a controller's cam (CSV, CODESYS, TwinCAT, PLCopen XML), proved as the controller runs it",
        description="Write the plan of a case (solved here) or of an output folder of `pressplan solve` (its "
        "plan.json) as a cam for a press controller, run it as the controller interpolates it through the dense "
        "verification, and refuse it (exit 3) when a limit breaks. Prints the proof: the slide's deviation from "
        "the plan, each limit's margin, the highest master speed that keeps every limit.",
    )
    cm.add_argument("source", help="a case file (YAML), or an output folder of `pressplan solve`")
    _set_option(cm, "replace a dotted case field for this run (a case file only; repeatable)")
    cm.add_argument("--out", help="output folder (default: the folder given, or out/<case name>)")
    cm.add_argument("--json", action="store_true", help="print cam_proof.json instead of the proof")
    from planning.reports.outputs._cam import COMMAND_OPTIONS

    for option in COMMAND_OPTIONS:
        cm.add_argument(option.flag, **option.kwargs)
    co = sub.add_parser(
        "compile",
        help="compile the NLPs a case takes to machine code, kept for every later solve (needs a C compiler)",
        description="Solve the case, compile the derivative functions of the NLPs it took (their Jacobian and "
        "Hessian, evaluated at every iteration) with the C compiler into a cache ($PRESSPLAN_CACHE, default "
        "$XDG_CACHE_HOME/pressplan or ~/.cache/pressplan; off: none), and solve it again: every later solve of those "
        "NLPs (solve, sweep's workers, the web page) loads them. 20-70 s a problem (a linkage's some minutes); the "
        "same numbers, the solves 1.3-1.8x faster (a whole CLI run about 1.3x).",
    )
    _case_argument(co)
    pl = sub.add_parser("plot", help="redraw the figures of a finished output folder (no solve)")
    pl.add_argument("folder", help="output folder of `pressplan solve`")
    pl.add_argument("--format", choices=PLOT_FORMATS, default="png", help="figure format (default png)")


def _version() -> str:
    """The installed package's version (a source tree not installed: unknown)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("pressplan")
    except PackageNotFoundError:
        return "unknown (not installed)"


def _case_argument(parser: argparse.ArgumentParser) -> None:
    """The case file and ``--set FIELD=VALUE`` (repeatable): a case field replaced for this run."""
    parser.add_argument("case", help="case file (YAML)")
    _set_option(
        parser, "replace a dotted case field for this run, e.g. --set limits.crank_jerk_rad_s3=2000 (repeatable)"
    )


def _set_option(parser: argparse.ArgumentParser, text: str) -> None:
    """``--set FIELD=VALUE``, repeatable, with its help ``text``."""
    parser.add_argument("--set", action="append", type=_setting, default=[], metavar="FIELD=VALUE", help=text)


def _setting(text: str) -> tuple[str, object]:
    """An argparse type: ``FIELD=VALUE`` -> (dotted field, value read as a YAML scalar: 1.8, 2e3, free; or a table
    of rows, ``[[0, 700], [600, 700], [750, 0]]``, for a field that holds one: an interference curve, a forming
    force)."""
    from planning.model.case_file import CaseFileError, load_yaml

    field, sep, value = text.partition("=")
    field = field.strip()
    if not sep or not field or any(not part for part in field.split(".")):
        raise argparse.ArgumentTypeError(f"expected FIELD=VALUE with a dotted case field, got {text!r}")
    try:
        parsed = load_yaml(value, f"--set {field}")
    except CaseFileError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    table = isinstance(parsed, list) and bool(parsed) and all(isinstance(row, list) for row in parsed)
    if isinstance(parsed, dict) or (isinstance(parsed, list) and not table):
        raise argparse.ArgumentTypeError(f"--set {field}: one value or a table of rows, not a section or a list")
    return field, parsed


def _rate(text: str) -> float:
    """An argparse type: a rate in strokes/min, 0 < rate <= 10000."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a rate in strokes/min, got {text!r}") from None
    if not (math.isfinite(value) and 0 < value <= 1e4):
        raise argparse.ArgumentTypeError(f"must be above 0 and at most 10000 strokes/min, got {text}")
    return value


class CommandError(Exception):
    """A command that cannot go on: ``str()`` is its one-line message, ``code`` its exit status."""

    def __init__(self, message: str, code: int = EXIT_INPUT):
        super().__init__(message)
        self.code = code


def _exit_code(exc: Exception, case_path: str | None) -> tuple[str, int] | None:
    """The one place where outcomes become exit statuses: ``(message, code)`` for a known error."""
    from planning.model.case import CaseError
    from planning.model.case_file import CaseFileError
    from planning.reports.folder import OutputError
    from planning.reports.outputs._cam import CamOptionError
    from planning.reports.plan_file import PlanFileError
    from planning.solver.outcomes import PlanningError
    from planning.sweep import SweepError

    if isinstance(exc, CommandError):
        return str(exc), exc.code
    if isinstance(exc, (CaseFileError, OutputError, SweepError, CamOptionError, PlanFileError)):
        return str(exc), EXIT_INPUT
    if isinstance(exc, CaseError):  # a case changed by an option (--law) that no longer holds together
        return exc.line(case_path), EXIT_INPUT
    if isinstance(exc, PlanningError):  # no feasible or no verified plan
        return f"{case_path}: {exc}", exc.outcome.exit_code
    if isinstance(exc, OSError):  # a file or folder the command needs cannot be used
        where = exc.filename if exc.filename is not None else case_path
        return f"{where}: {exc.strerror or exc}", EXIT_INPUT
    return None


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    command = {
        "check": _check,
        "solve": _solve,
        "compare": _compare,
        "sweep": _sweep,
        "tradeoff": _tradeoff,
        "bound": _bound,
        "laws": _laws,
        "plot": _plot,
        "serve": _serve,
        "new": _new,
        "cam": _cam,
        "line": _line,
        "compile": _compile,
    }[args.command]
    try:
        if args.command in ("plot", "serve", "new", "cam", "line"):
            return command(args)
        case = _read(args)
        if case.pendulum and args.command not in PENDULUM_COMMANDS:
            raise CommandError(
                f"{args.case}: planner.mode: pendulum: pressplan {args.command} plans rotary strokes only (yet); "
                f"{', '.join(sorted(PENDULUM_COMMANDS | {'cam', 'plot'}))} take a pendulum stroke"
            )
        return command(case, args)
    except Exception as exc:
        named = getattr(args, "case", None) or getattr(args, "source", None) or getattr(args, "line", None)
        known = _exit_code(exc, named)
        if known is None:
            raise
        return _fail(*known)


PENDULUM_COMMANDS = frozenset(
    {"check", "solve", "bound", "sweep", "laws", "tradeoff", "compile"}
)  # the commands that take planner.mode: pendulum


def _read(args: argparse.Namespace):  # noqa: ANN202 - a Case (its module loads on use)
    """The case of ``args.case`` with the ``--set`` fields; an error in a field set there says so."""
    from planning.model.case_file import CaseFileError, read_case

    overrides = dict(getattr(args, "set", None) or [])
    if len(overrides) != len(getattr(args, "set", None) or []):
        raise CommandError("--set: each field at most once")
    try:
        return read_case(args.case, overrides)
    except CaseFileError as exc:
        if exc.field is not None and any(
            exc.field == f or exc.field.startswith(f + ".") or f.startswith(exc.field + ".") for f in overrides
        ):
            raise CaseFileError(f"{exc} (from --set)", exc.field) from None
        raise


def _fail(message: str, code: int) -> int:
    print(f"pressplan: {message}", file=sys.stderr)
    return code


def _check(case, args) -> int:
    from planning.reports.check import check_case, check_text

    report = check_case(case)
    print(json.dumps(report, indent=2) if args.json else check_text(report))
    return EXIT_OK if all(c["passed"] for c in report["checks"]) else EXIT_INFEASIBLE


def _output_folder(case, args, owned: tuple[str, ...]) -> Path:
    """``--out`` or ``out/<case name>``, checked before any solving: writable, and not holding the case
    file under a name the command writes (``owned``)."""
    from planning.model.case import output_name
    from planning.reports.folder import check_case_outside, ensure_writable

    out = Path(args.out) if args.out else Path("out") / output_name(case)
    ensure_writable(out)
    check_case_outside(out, args.case, owned)
    return out


def _solve(case, args) -> int:
    from planning.reports.outputs import Written, writers_of
    from planning.reports.report import summary_text
    from planning.solver.optimize import solve

    case = _with_objective(_with_law(case, args), args)
    if case.pendulum:
        return _solve_pendulum(case, args)
    out = _output_folder(case, args, _solve_files())
    solution = solve(case, args.placement)
    figures = not args.no_plots
    if figures:
        _load_plots()  # here, where a signal is held through the import, not inside the writers
    options = {o.kwargs["dest"]: getattr(args, o.kwargs["dest"]) for o in output_options()}
    written = Written(solution, case, options, side_by_side_workers=True)
    writers = writers_of(written, figures)
    text = summary_text(written.result)
    if written.cam is not None:
        from planning.reports.cam_export import proof_lines

        text += "\n\n" + "\n".join(proof_lines(written.cam))
    return _write_and_report(out, writers, written.result, text, args, _solve_files())


def _solve_pendulum(case, args) -> int:
    """``pressplan solve`` of a pendulum stroke (``planning.reports.pendulum``): its own files, the cam table and,
    with ``--cam``, the proved cams (on a master turning once a cycle of two swings)."""
    from planning.reports.cam_export import proof_lines
    from planning.reports.outputs import Written
    from planning.reports.pendulum import pendulum_result, pendulum_summary, pendulum_writers
    from planning.solver.pendulum_rate import solve_swings

    if args.placement == "published":
        raise CommandError(f"{args.case}: --placement published: not with planner.mode: pendulum")
    owned = _solve_files()
    out = _output_folder(case, args, owned)
    solution = solve_swings(case)
    figures = not args.no_plots
    if figures:
        _load_plots()
    writers = pendulum_writers(solution, case, args.plot_format if figures else None)
    written = Written(solution, case, {o.kwargs["dest"]: getattr(args, o.kwargs["dest"]) for o in output_options()})
    writers.update(_pendulum_cam_writers(written, with_table=True))
    result = pendulum_result(solution, case)
    text = pendulum_summary(result)
    if written.cam is not None:
        text += "\n\n" + "\n".join(proof_lines(written.cam))
    return _write_and_report(out, writers, result, text, args, owned)


def _solve_files() -> tuple[str, ...]:
    """What ``pressplan solve`` owns in its folder, either stroke's: a rotary solve's files (the registry's) and a
    pendulum solve's, so that a solve of the other stroke into the same folder leaves none of them behind."""
    from planning.reports.outputs import owned_files
    from planning.reports.pendulum import PENDULUM_FILES

    return tuple(dict.fromkeys(owned_files() + PENDULUM_FILES))


def _pendulum_cam_writers(written, with_table: bool) -> dict:  # noqa: ANN001 - a Written
    """The cam outputs' writers for a pendulum plan (the registry's cam outputs read its plan and case only)."""
    from planning.reports.outputs import BY_NAME

    tables = (BY_NAME["cam_table.csv"], BY_NAME["robot_cams.csv"]) if with_table else ()  # (robot_cams: with robots)
    chosen = _cam_outputs() + tables
    return {name: w for output in chosen for name, w in output.writers(written).items()}


def _cam(args) -> int:
    """``pressplan cam``: the cam of a case's plan (solved here) or of a folder's ``plan.json``, proved."""
    from planning.reports.cam_export import proof_dict, proof_lines
    from planning.reports.outputs import Written, writers_of
    from planning.reports.outputs._cam import OPTIONS

    source = Path(args.source)
    if source.is_dir():
        from planning.reports.plan_file import read_plan

        if args.set:
            raise CommandError("--set: changes a case file's fields; a folder's plan is solved already")
        case, solution = read_plan(source)
        out = Path(args.out) if args.out else source
    else:
        from planning.solver.optimize import solve

        args.case = args.source
        case = _read(args)
        out = _output_folder(case, args, ())
        if case.pendulum:  # the swings' cams: the crank goes forward and back on a master turning once a cycle
            from planning.solver.pendulum_rate import solve_swings

            solution = solve_swings(case, compare=False)
        else:
            solution = solve(case)
    options = {o.kwargs["dest"]: getattr(args, o.kwargs["dest"]) for o in OPTIONS}
    written = Written(solution, case, options)
    owned = tuple(pattern for output in _cam_outputs() for pattern in output.files)
    if case.pendulum:
        writers = _pendulum_cam_writers(written, with_table=False)
    else:
        writers = {name: w for name, w in writers_of(written, figures=False).items() if name in owned}
    args.case = None if source.is_dir() else args.source
    data, text = proof_dict(written.cam), "\n".join(proof_lines(written.cam))
    return _write_and_report(out, writers, data, text, args, owned)


def _cam_outputs() -> tuple:
    """The cam outputs of the registry (their files are the ones ``pressplan cam`` owns)."""
    from planning.reports.outputs import OUTPUTS

    return tuple(o for o in OUTPUTS if o.name.startswith("cam_") and o.name != "cam_table.csv")


def _with_law(case, args):  # noqa: ANN001, ANN202 - a Case and the parsed arguments
    """The case under ``--law``; what the case lacks for it named with the ``--set`` that adds it."""
    from planning.model.case import CaseError

    if args.law is None:
        return case
    try:
        return case.with_law(args.law)
    except CaseError as exc:
        add = f" (add it: --set {exc.field}=VALUE)" if exc.field.startswith("limits.") else ""
        raise CommandError(f"{args.case}: --law {args.law}: {exc.line()}{add}") from None


def _with_objective(case, args):  # noqa: ANN001, ANN202 - a Case and the parsed arguments
    """The case with ``--objective`` and ``--spm`` applied; a rate without an objective at a rate is an
    error; a problem with what the user typed names the option (``--spm``), else the case's field."""
    from planning.model.case import CaseError

    objective = args.objective or case.planner.objective
    if args.spm is not None and objective == "max-spm":
        raise CommandError(
            "--spm: the max-spm objective has no target rate (add --objective min-rms-torque or min-energy)"
        )
    try:
        return case.with_objective(args.objective, args.spm)
    except CaseError as exc:
        if exc.field == "planner.target_spm" and args.objective is not None:
            raise CommandError(
                f"--objective {args.objective}: needs the line's rate: add --spm RATE (strokes/min)"
            ) from None
        if exc.field == "planner.objective" and args.objective is not None:
            raise CommandError(f"{args.case}: --objective {args.objective}: {exc.message}") from None
        raise CommandError(f"{args.case}: {exc.line()}") from None


def _compare(case, args) -> int:
    from planning.model.laws.improved_scurve import ImprovedSCurve
    from planning.reports.compare import comparison, comparison_markdown, comparison_text
    from planning.reports.folder import COMPARE_FILES, write_json
    from planning.solver.optimize import solve

    if case.published is None or case.published.solution is None:
        raise CommandError(f"{args.case}: published.solution: the case has no published solution to compare")
    if case.robots is not None:  # the published solution is the one-height model's (its transfer time)
        raise CommandError(f"{args.case}: robots: the published solution has one safety height and one transfer time")
    if case.free_draw:  # the published solution's draw is at one crank speed, under the improved S-curve
        raise CommandError(
            f"{args.case}: process.draw_slide_speed_mm_s: the published solution draws at a constant crank speed "
            "(process.draw_speed_rpm); compare takes a case that draws as it does"
        )
    # the paper's notation describes its own law: compare under the improved S-curve
    case = case.with_law(ImprovedSCurve.name)
    out = _output_folder(case, args, COMPARE_FILES)
    ours_published = solve(case, "published")
    ours_free = solve(case, "free")
    data = comparison(case, ours_published, ours_free)
    writers = {
        "comparison.json": lambda p: write_json(p, data),
        "comparison.md": lambda p: p.write_text(comparison_markdown(data), encoding="utf-8"),
    }
    return _write_and_report(out, writers, data, comparison_text(data), args, COMPARE_FILES)


def _write_and_report(out: Path, writers: dict, data: dict, text: str, args, owned: tuple[str, ...]) -> int:
    """Replace the command's files in ``out`` as a whole (never the case file), then print ``data`` as
    JSON or ``text`` with the files written."""
    from planning.reports.folder import write_atomic

    files = write_atomic(out, writers, owned, keep=args.case)
    if args.json:
        print(json.dumps(data, indent=2))
    else:
        print(text)
        print(f"  wrote {', '.join(str(f) for f in files)}")
    return EXIT_OK


PROGRESS_HELP = "show progress (points done, points/s, the expected end) even when stderr is not a terminal"
PROGRESS_EVERY_S = 1.0  # [s] without a terminal, a progress line at most this often (and the last one)


class ProgressBar:
    """A sweep's or a trade-off's progress on stderr: a bar redrawn in place on a terminal, or (``always``)
    a line at most every :data:`PROGRESS_EVERY_S` without one; points done, points/s, the expected end."""

    def __init__(self, what: str, always: bool) -> None:
        self.what, self.tty = what, sys.stderr.isatty()
        self.shown = self.tty or always
        self.started = time.perf_counter()
        self.last = -math.inf
        self.drawn = False

    def update(self, done: int, total: int, failed: int) -> None:
        if not self.shown:
            return
        now = time.perf_counter()
        if not self.tty and done < total and now - self.last < PROGRESS_EVERY_S:
            return
        self.last = now
        rate = done / max(now - self.started, TINY_RATE)
        left = (total - done) / rate if rate > 0 else math.inf
        bar = "#" * int(30 * done / total)
        line = f"{self.what} [{bar:<30}] {done}/{total} points, {failed} without a plan, {rate:.1f} points/s, " + (
            f"done in about {left:.0f} s" if done < total else "all solved"
        )
        print(("\r" + line) if self.tty else line, end="" if self.tty else "\n", file=sys.stderr, flush=True)
        self.drawn = True

    def close(self) -> None:
        if self.tty and self.drawn:
            print(file=sys.stderr)


def _load_plots() -> None:
    """Load the plotting module (matplotlib: about a second; while a sweep's workers solve, not before
    them); a Ctrl-C or SIGTERM meanwhile ends the run once the import is done (``ipopt.signals_held``)."""
    from planning.solver.ipopt import signals_held

    with signals_held():
        import planning.reports.plots  # noqa: F401


def _sweep(case, args) -> int:
    import planning.solver.optimize  # noqa: F401 - loaded once here, inherited by forked workers
    from planning.reports.folder import ensure_writable
    from planning.sweep import parse_vary, run_sweep

    varies = [parse_vary(v) for v in args.vary]
    if len({v.field for v in varies}) != len(varies):
        raise CommandError("--vary: each field at most once")
    out = Path(args.out)
    ensure_writable(out)
    base = _with_law(case, args).model_dump(exclude_none=True)
    bar = ProgressBar("sweep", args.progress)

    def figure(result) -> None:  # noqa: ANN001 - a SweepResult
        _load_plots()  # loaded already while the workers solved, unless there were none
        from planning.reports.plots import save, sweep_figure

        if len(varies) <= 2:
            title = f"{case.name}: strokes per minute over {' x '.join(v.field for v in varies)}"
            save(sweep_figure(result.rows, result.fields, title), out / "sweep_spm.png")

    result = run_sweep(
        base, args.case, varies, out, args.workers, args.scheduler, args.placement, bar.update, _load_plots, figure
    )
    bar.close()
    rows = result.rows
    from planning.sweep import verified as holds

    verified = sum(holds(r) for r in rows)
    print(
        f"{case.name}: {len(rows)} points, {verified} verified, {len(rows) - verified} without a plan"
        f"{f' ({result.resumed} from an earlier run)' if result.resumed else ''}"
        f"{f', {result.repaired} improved from a neighbour' if result.repaired else ''}; wrote {out / 'sweep.csv'}"
    )
    return EXIT_OK


def _tradeoff(case, args) -> int:
    import planning.solver.optimize  # noqa: F401 - loaded once here, inherited by forked workers
    from planning.model.case import CaseError
    from planning.reports.folder import TRADEOFF_FILES, write_atomic
    from planning.tradeoff import columns, parse_rates, run_tradeoff, table_text, write_rows

    rates = parse_rates(args.spm)
    if case.pendulum and args.placement == "published":
        raise CommandError(f"{args.case}: --placement published: not with planner.mode: pendulum")
    if case.drive is None:
        raise CommandError(f"{args.case}: drive: the trade-off weighs the motor: the case needs a drive: section")
    case = _with_law(case, args)
    objective = args.objective or (case.planner.objective if case.planner.objective != "max-spm" else "min-rms-torque")
    try:
        case = case.with_objective(objective, rates.start)
    except CaseError as exc:
        raise CommandError(f"{args.case}: {exc.line()}") from None
    out = _output_folder(case, args, TRADEOFF_FILES)
    bar = ProgressBar("tradeoff", args.progress)
    result = run_tradeoff(case, rates, args.workers, args.scheduler, args.placement, _load_plots, bar.update)
    bar.close()
    _load_plots()  # loaded already while the workers solved, unless there were none
    from planning.reports.plots import save, tradeoff_figure

    title = f"{case.name}: {objective} at the line's rate ({case.planner.motion_law})"
    record = {"case": case.name, "objective": objective, "spm": args.spm, "timeline": result.timeline}
    writers = {
        "tradeoff.csv": lambda p: write_rows(p, result.rows, columns(case)),
        "tradeoff.json": lambda p: p.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8"),
        "tradeoff.png": lambda p: save(tradeoff_figure(result.rows, case, title), p),
    }
    files = write_atomic(out, writers, TRADEOFF_FILES, keep=args.case)
    print(table_text(result, case))
    print(f"  wrote {', '.join(str(f) for f in files)}")
    return EXIT_OK


def _bound(case, args) -> int:
    if case.pendulum:
        return _pendulum_bound(case, args)
    from planning.solver.bound import time_optimal_bound
    from planning.solver.bracket import BRACKET_TOL_PCT

    tolerance = BRACKET_TOL_PCT if args.tolerance is None else args.tolerance
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise CommandError(f"--tolerance {args.tolerance}: the gap must be a positive percentage", EXIT_INPUT)
    upper = result = None
    if args.bracket or args.tolerance is not None:
        bound, result = _bound_and_bracket(case, args.points, tolerance)
        upper = result.upper
    elif args.certified or args.upper_points is not None:
        bound, upper = _bound_and_upper(case, args.points, args.upper_points)
    else:
        bound = time_optimal_bound(case, args.points)
    data = {"case": case.name, **bound.as_dict()}
    if result is not None:
        data["bracket"] = result.as_dict()
    if upper is not None:
        data["upper_bound"] = upper.as_dict()
    if args.json:
        print(json.dumps(data, indent=2))
        return EXIT_OK
    print(
        f"{case.name}: time-optimal bound {bound.spm:.3f} strokes/min, cycle {bound.cycle_time_s:.4f} s "
        f"({bound.points} intervals{_more_than_asked(bound.points, args.points)}; peak crank speed "
        f"{data['peak_crank_speed_rpm']:.2f} rpm, "
        + (f"draw {bound.draw_speed_rpm:.3f} rpm, " if not case.free_draw else "the draw at its slide speed, ")
        + (f"idle time for the robots {bound.window_slack_s:.3f} s" if case.robots else "")
        + (f"idle time in the robot's window {bound.window_slack_s:.3f} s" if case.robots is None else "")
        + (f"; crank jerk <= {bound.crank_jerk_limit_rad_s3:g} rad/s^3" if bound.crank_jerk_limit_rad_s3 else "")
        + (f"; the hold's {case.standstill_s:g} s added, the crank free to stop)" if case.standstill_s else ")")
    )
    if upper is not None:
        left = f"; left out: {', '.join(upper.left_out)}" if upper.left_out else ""
        print(
            f"  certified upper bound {upper.spm:.3f} strokes/min, cycle at least {upper.cycle_time_s:.4f} s: no "
            f"motion within the limits makes more (convex relaxation, {upper.points} intervals"
            + (f" x {upper.pieces} pieces" if upper.pieces > 1 else "")
            + f"{left})"
        )
    if result is not None:
        print(bracket_text(result))
    return EXIT_OK


def _bound_and_bracket(case, points, tolerance):  # noqa: ANN001, ANN202 - a Case, ints; a Bound and a Bracket
    """The time-optimal bound, made in the bracket's worker (``planning.solver.ahead``) while the bracket plans its
    motion, and the bracket. Where both fail, the bound's error, as when it was computed first."""
    from planning.solver.ahead import Ahead
    from planning.solver.bound import time_optimal_bound
    from planning.solver.bracket import bracket
    from planning.solver.outcomes import PlanningError

    with Ahead() as ahead:
        following = ahead.start(time_optimal_bound, case, points)
        try:
            result = bracket(case, tolerance, ahead)
        except PlanningError:
            following.take()  # the bound's error first
            raise
        return following.take(), result


def _bound_and_upper(case, points, upper_points):  # noqa: ANN001, ANN202 - a Case, ints; a Bound, an UpperBound
    """The time-optimal bound here while the certified upper bound is made in a forked worker
    (``planning.solver.ahead``); the bound's error first, as when the two were computed in turn."""
    from planning.solver.ahead import Ahead
    from planning.solver.bound import time_optimal_bound
    from planning.solver.upper_bound import UPPER_POINTS, upper_bound

    with Ahead() as ahead:
        following = ahead.start(upper_bound, case, upper_points or UPPER_POINTS)
        return time_optimal_bound(case, points), following.take()


def _pendulum_bound(case, args) -> int:
    """``pressplan bound`` of a pendulum stroke: its certified upper bound (``planning.solver.pendulum_bound``);
    with ``--bracket`` the plan beside it."""
    from planning.solver.pendulum_bound import pendulum_bound

    bound = pendulum_bound(case)
    data = {"case": case.name, "mode": "pendulum", "upper_bound_spm": bound.spm, "cycle_time_s": bound.cycle_time_s}
    data["arc_times_s"] = dict(zip(("forward", "backward"), bound.arc_times_s, strict=True))
    data["set_by"] = bound.sets_it
    windows = (
        f"the robot's two windows of {case.process.transfer_time_s:g} s and "
        if case.robots is None
        else f"set by {bound.sets_it}; "
    )
    lines = [
        f"{case.name}: certified upper bound {bound.spm:.3f} strokes/min in pendulum strokes, two swings at least "
        f"{bound.cycle_time_s:.4f} s: no swing within the limits makes more ({windows}"
        f"theta1 .. theta4 at least {bound.arc_times_s[0]:.4f} s forward, "
        f"{bound.arc_times_s[1]:.4f} s backward; the jerk limit, the least crank speed, the torques and the turns left "
        "out)"
    ]
    if args.bracket or args.tolerance is not None:
        from planning.solver.pendulum import solve_pendulum

        plan = solve_pendulum(case, compare=False).plan
        gap = 100 * (bound.spm / plan.spm - 1)
        data["bracket"] = {"lower_spm": plan.spm, "upper_spm": bound.spm, "gap_pct": gap}
        lines.append(f"  the verified plan {plan.spm:.3f} strokes/min: no swing makes more than {gap:.2f} % more")
    print(json.dumps(data, indent=2) if args.json else "\n".join(lines))
    return EXIT_OK


def bracket_text(result) -> str:  # noqa: ANN001 - a Bracket
    """The bracket in two lines: between what, how wide, and whether the tolerance was met."""
    d = result.as_dict()
    segments = "/".join(str(n) for _, n in d["verified_segments"])
    allowed = (
        f"; crank jerk up to {d['jerk_allowance_rad_s3']:.0f} rad/s^3 allowed, the case sets no limit"
        if d["jerk_allowance_rad_s3"] is not None
        else ""
    )
    left = result.upper.left_out
    verdict = (
        f"within the tolerance {d['tolerance_pct']:g} %"
        if d["met"]
        else f"NOT within the tolerance {d['tolerance_pct']:g} %: refinements ran out or stalled"
        + (f"; the upper bound leaves out {', '.join(left)}" if left else "")
    )
    return (
        f"  bracket: {d['verified_spm']:.4f} SPM verified ... {d['upper_spm']:.4f} SPM certified upper bound, gap "
        f"{d['gap_pct']:.3f} % ({verdict}; {len(d['rounds'])} rounds)\n"
        f"  verified motion: optimal law, {segments} segments, peak crank jerk "
        f"{d['verified_peak_crank_jerk_rad_s3']:.0f} rad/s^3{allowed}; upper bound on {d['upper_points']} intervals"
    )


def _more_than_asked(used: int, asked: int) -> str:
    from planning.solver.bound import MIN_INTERVALS_PER_ARC

    return f": at least {MIN_INTERVALS_PER_ARC} between key angles, more than the {asked} asked" if used > asked else ""


def _laws(case, args) -> int:
    from planning.reports.folder import LAWS_FILES, write_json
    from planning.reports.law_comparison import compare_laws, laws_markdown, laws_text
    from planning.reports.plots import laws_figure, save
    from planning.reports.report import TRAJECTORY_COLUMNS

    out = _output_folder(case, args, LAWS_FILES)
    if case.pendulum:
        from planning.reports.pendulum import pendulum_laws, pendulum_laws_text

        data = pendulum_laws(case)
        writers = {"laws.json": lambda p: write_json(p, data)}
        return _write_and_report(out, writers, data, pendulum_laws_text(data), args, LAWS_FILES)
    data, tables = compare_laws(case, side_by_side_workers=True)
    if not tables:  # each law's own reason, on the one line
        reasons = "; ".join(f"{r['law']}: {r['message']}" for r in data["laws"])
        raise CommandError(f"{args.case}: no motion law gives a verified plan ({reasons})", EXIT_INFEASIBLE)
    curves = {law: dict(zip(TRAJECTORY_COLUMNS, table.T, strict=True)) for law, table in tables.items()}
    title = f"{case.name}: crank motion of each law ({data['placement']} placement)"
    writers = {
        "laws.json": lambda p: write_json(p, data),
        "laws.md": lambda p: p.write_text(laws_markdown(data), encoding="utf-8"),
        f"laws_overlay.{args.format}": lambda p: save(laws_figure(curves, title), p),
    }
    return _write_and_report(out, writers, data, laws_text(data), args, LAWS_FILES)


def _compile(case, args) -> int:
    from planning.solver.compile_cases import compile_nlps

    report = compile_nlps(case)
    if report.compiled + report.present == 0:
        print(f"{case.name}: nothing compiled: its NLPs stay interpreted")
        return EXIT_OK
    print(
        f"{case.name}: {report.compiled} NLP(s) compiled in {report.seconds:.1f} s, {report.present} found compiled, "
        f"{report.interpreted} left interpreted, in {report.folder}; a solve took {report.solve_s:.2f} s "
        f"before (its NLPs built), {report.compiled_solve_s:.2f} s after"
    )
    return EXIT_OK


def _new(args) -> int:
    from planning.reports.new_case import write_new_case

    path = Path(args.file)
    if path.suffix.lower() not in (".yaml", ".yml"):
        raise CommandError(f"{path}: a case file ends in .yaml")
    try:
        write_new_case(path, args.mechanism, args.drive, args.robots)
    except FileExistsError:
        raise CommandError(f"{path}: exists already (choose another name; nothing was written)") from None
    kind = f"a {args.mechanism} case{' with a drive' if args.drive else ''}{' with robots' if args.robots else ''}"
    print(f"{path}: {kind}, commented field by field, to edit. Next: pressplan check {path}")
    return EXIT_OK


def _line(args) -> int:
    """``pressplan line``: read the line and its stations' cases, plan, verify, write the line's files (with
    ``--vary``: a sweep over the line)."""
    from planning.model.case_file import CaseFileError
    from planning.model.line_file import read_line
    from planning.reports.folder import ensure_writable
    from planning.reports.line import LINE_FILES, summary_text, writers
    from planning.reports.line import result as line_result
    from planning.solver.line import solve_line

    sets = dict(args.set)
    if len(sets) != len(args.set):
        raise CommandError("--set: each field at most once")
    try:
        line = read_line(args.line, sets)
    except CaseFileError as exc:
        named = exc.field is not None and any(_names(f, exc.field) for f in sets)
        raise CaseFileError(f"{exc} (from --set)" if named else str(exc), exc.field) from None
    out = Path(args.out) if args.out else Path("out") / line.name
    ensure_writable(out)
    if args.vary:
        return _line_sweep(line, sets, args, out)
    solution = solve_line(line, side_by_side_workers=True)
    if not args.no_plots:
        _load_plots()
    args.case = args.line  # the file no output replaces
    files = writers(solution, not args.no_plots, sets)
    return _write_and_report(out, files, line_result(solution, sets), summary_text(solution), args, LINE_FILES)


def _names(setting: str, field: str) -> bool:
    """Whether a line's error in ``field`` comes from the ``--set`` of ``setting``: the same field, the same
    station's case field, or a sibling (a transfer's time set beside its path)."""
    parent = setting.rpartition(".")[0]
    return setting == field or setting.endswith("." + field) or (bool(parent) and field.startswith(parent + "."))


def _line_sweep(line, sets: dict, args, out: Path) -> int:  # noqa: ANN001 - a Line and the parsed arguments
    """``pressplan line --vary``: the grid's lines planned on the workers, ``line_sweep.csv`` and its figure."""
    from planning.line_sweep import LINE_SWEEP_FILES, check_corners, parse_line_vary, run_line_sweep, write_rows
    from planning.model.outcome import Outcome
    from planning.reports.folder import write_atomic

    varies = [parse_line_vary(v, args.line) for v in args.vary]
    fields = [v.field for v in varies]
    if len(set(fields)) != len(fields) or set(fields) & set(sets):
        raise CommandError("--vary: each field at most once (and not also in --set)")
    check_corners(args.line, sets, varies)  # a value no line takes: refused before any point is solved
    bar = ProgressBar("line sweep", args.progress)
    rows = run_line_sweep(args.line, sets, varies, args.workers, args.scheduler, bar.update)
    bar.close()
    writers = {"line_sweep.csv": lambda p: write_rows(p, rows, fields)}
    if len(varies) <= 2:
        _load_plots()
        from planning.reports.plots import save, sweep_figure

        title = f"{line.name}: the line's strokes per minute over {' x '.join(fields)}"
        writers["line_sweep.png"] = lambda p: save(sweep_figure(rows, fields, title), p)
    files = write_atomic(out, writers, LINE_SWEEP_FILES, keep=args.line)
    verified = sum(Outcome.of(r["status"]).succeeded for r in rows)
    for row in rows:
        values = ", ".join(f"{f} = {row[f]:g}" for f in fields)
        what = f"{row['spm']:.3f} strokes/min, bottleneck {row['bottleneck']}" if "spm" in row else row["message"]
        print(f"  {values}: {what}")
    print(f"{line.name}: {len(rows)} points, {verified} verified; wrote {', '.join(str(f) for f in files)}")
    return EXIT_OK


def _plot(args) -> int:
    from planning.reports.folder import write_atomic
    from planning.reports.outputs.figures import redraw

    folder = Path(args.folder)
    if not (folder / "result.json").is_file():
        raise CommandError(f"{folder}: no result.json here (run `pressplan solve` first)")
    files = write_atomic(folder, redraw(folder, args.format, side_by_side_workers=True))
    print(f"wrote {', '.join(str(f) for f in files)}")
    return EXIT_OK


def _serve(args) -> int:
    try:
        from planning.web.server import serve
    except ImportError as exc:
        raise CommandError(f"serve needs the web extra: pip install -e '.[web]' ({exc.name} is missing)") from None
    case_path = None
    if args.case is not None:
        from planning.model.case_file import read_case

        read_case(args.case)  # a bad case file is the usual one line, exit 2
        case_path = Path(args.case).resolve()
    cases = Path(args.cases)
    if not cases.is_dir() and args.cases == "cases":  # not run from the project root: the project's own cases
        cases = Path(__file__).resolve().parents[1] / "cases"
    if case_path is None and (cases / SERVE_FIRST).is_file():  # the published case first, as in the README
        case_path = (cases / SERVE_FIRST).resolve()
    folder = cases if cases.is_dir() else None
    serve(case_path, args.host, args.port, folder, _recipes_folder(args.recipes), not args.no_compile)
    return EXIT_OK


def _recipes_folder(name: str | None) -> Path | None:
    """The recipes' folder of ``serve --recipes``, made when missing; a file of that name is bad input."""
    if name is None:
        return None
    folder = Path(name)
    if folder.exists() and not folder.is_dir():
        raise CommandError(f"--recipes {name}: not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CommandError(f"--recipes {name}: cannot be made ({exc.strerror})") from None
    return folder.resolve()


def run() -> None:
    """The command (``planning.__main__``, the console script, sets the signals' handlers before this module loads):
    Ctrl-C ends with one line and exit 130, SIGTERM with exit 143 (``planning.interrupts``); numpy's
    RuntimeWarnings are never printed (every result is checked for finiteness where it matters). The objects
    made by the imports, and those left at the end, are frozen out of the cyclic garbage collector's sight
    (``gc.freeze``): its collections during the run and the interpreter's exit do not walk them (together about 50
    of the 600 ms a cold solve's process takes); reference counting frees as before, files are closed by then, and
    the clean-up in ``finally`` blocks and at exit runs as before."""
    import warnings

    from planning.interrupts import install, stopping

    warnings.simplefilter("ignore", RuntimeWarning)
    install()  # set already where the run began in planning.__main__; here for ``python -m planning.cli``
    sys.exit(stopping(_frozen_main))


def _frozen_main() -> int:
    """:func:`main` between two ``gc.freeze`` (:func:`run`)."""
    import gc

    gc.freeze()  # the modules imported so far live as long as the process: no collection walks them again
    code = main()
    gc.freeze()
    return code


if __name__ == "__main__":
    run()
