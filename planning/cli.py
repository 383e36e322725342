"""The ``pressplan`` command: a thin layer over the Python API.

Exit status: 0 success, 2 bad input (case file, arguments, output folder), 3 no feasible or no
verified plan. Every error is one line on stderr; no traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

EXIT_OK, EXIT_INPUT, EXIT_INFEASIBLE = 0, 2, 3


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, exit 2
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message}\n")


def _parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="pressplan", description="Plan the crank speed of a crank-slider servo press for maximum SPM.")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    c = sub.add_parser("check", help="key points and process checks of a case (no solve)")
    c.add_argument("case", help="case file (YAML)")
    c.add_argument("--json", action="store_true", help="print JSON instead of the table")
    s = sub.add_parser("solve", help="solve, verify and write the fastest cycle")
    s.add_argument("case", help="case file (YAML)")
    s.add_argument("--out", help="output folder (default: out/<case name>)")
    s.add_argument("--placement", choices=("free", "published"), help="where theta1/theta4 may fall (default: case)")
    s.add_argument("--json", action="store_true", help="print result.json instead of the summary")
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from planning.case_file import CaseFileError, read_case

    try:
        case = read_case(args.case)
    except CaseFileError as exc:
        return _fail(str(exc), EXIT_INPUT)
    if args.command == "check":
        return _check(case, args)
    return _solve(case, args)


def _fail(message: str, code: int) -> int:
    print(f"pressplan: {message}", file=sys.stderr)
    return code


def _check(case, args) -> int:
    from planning.check import check_case, check_text

    report = check_case(case)
    print(json.dumps(report, indent=2) if args.json else check_text(report))
    return EXIT_OK if all(c["passed"] for c in report["checks"]) else EXIT_INFEASIBLE


def _solve(case, args) -> int:
    from planning.case import output_name
    from planning.optimize import PlanningError, solve
    from planning.outputs import OutputError, ensure_writable, solution_writers, write_atomic
    from planning.report import result_dict, summary_text

    out = Path(args.out) if args.out else Path("out") / output_name(case)
    try:
        ensure_writable(out)
    except OutputError as exc:
        return _fail(str(exc), EXIT_INPUT)
    try:
        solution = solve(case, args.placement)
    except PlanningError as exc:
        return _fail(f"{args.case}: {exc}", EXIT_INFEASIBLE)
    if not solution.verification.passed:  # solve() returns only verified plans; belt and braces
        return _fail(f"{args.case}: unverified plan not written", EXIT_INFEASIBLE)
    try:
        files = write_atomic(out, solution_writers(solution, case))
    except OutputError as exc:
        return _fail(str(exc), EXIT_INPUT)
    result = result_dict(solution, case)
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        print(summary_text(result))
        print(f"  wrote {', '.join(str(f) for f in files)}")
    return EXIT_OK


def run() -> None:
    """Console-script entry point."""
    sys.exit(main())


if __name__ == "__main__":
    run()
