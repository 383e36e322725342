"""Parameter sweeps: the full grid over dotted case fields, each point solved and verified.

The grid is cut into contiguous blocks of at most :data:`BLOCK_POINTS` points. A block is solved in order,
each point solved cold and from its neighbour's plan (``solve(..., neighbour=...)``: the better verified
plan wins, so a point is its cold solve's answer or better, whatever its neighbours). The blocks go to local
worker processes or to a Dask distributed cluster; the cut depends on the grid alone, so both give the same
rows. Rows are appended to ``sweep.csv`` as blocks finish, so a sweep that is stopped resumes with the
points it lacks. A point that fails becomes a row that says why; it never stops the sweep. When all blocks
are in, a repair pass re-solves any point whose neighbour's plan is feasible for it and better (see
:func:`repair`), and the file is rewritten in grid order.

Before local workers fork, the first point is solved once in this process so that every NLP its solve builds
is inherited by the workers instead of built in each. ``sweep.json`` records the run's timeline
(``planning.timeline``): start-up, each worker's busy and idle time, each block, the second pass and the
writing.
"""

from __future__ import annotations

import csv
import difflib
import itertools
import json
import math
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel

from planning.model.case import ELECTRICAL_KEYS, Case, states_electrical
from planning.model.case_file import with_fields
from planning.model.outcome import Outcome
from planning.timeline import Timeline, stamp
from planning.tolerances import SAME_ANGLE_RAD, SAME_SPM, TIME_TOL_S

BLOCK_POINTS = 6
ROW_FIELDS = ("spm", "cycle_time_s", "status", "binding", "solve_time_s", "message")
# with a drive: what the motor must give at each point
DRIVE_ROW_FIELDS = (
    "peak_motor_torque_Nm",
    "rms_motor_torque_Nm",
    "peak_motor_power_kW",
    "energy_drawn_kJ",
    "energy_net_kJ",
)
# with the drive's electrical side (losses, storage, grid): what the plant must give at each point
POWER_ROW_FIELDS = ("grid_peak_kW", "bus_peak_kW", "mean_bus_power_kW", "grid_energy_kJ", "storage_swing_kJ")


class SweepError(ValueError):
    """A sweep that cannot start; ``str()`` is a one-line message."""


@dataclass(frozen=True)
class Vary:
    """One swept field: dotted ``field``, ``count`` values from ``start`` to ``stop`` (inclusive)."""

    field: str
    start: float
    stop: float
    count: int

    @property
    def values(self) -> np.ndarray:
        """The swept values, rounded to 12 significant digits (no 1.7000000000000002 in the table)."""
        return np.array([float(f"{v:.12g}") for v in np.linspace(self.start, self.stop, self.count)])


def numeric_fields(model: type[BaseModel] = Case, prefix: str = "") -> list[str]:
    """Dotted names of every numeric field of a case (the fields a sweep can vary)."""
    out = []
    for name, info in model.model_fields.items():
        if prefix == "" and name == "published":
            continue
        args = getattr(info.annotation, "__args__", (info.annotation,))
        nested = [a for a in args if isinstance(a, type) and issubclass(a, BaseModel)]
        if nested:
            out += numeric_fields(nested[0], f"{prefix}{name}.")
        elif (float in args or "float" in str(info.annotation)) and "list" not in str(info.annotation).lower():
            out.append(f"{prefix}{name}")
    return out


def parse_vary(text: str, valid: list[str] | None = None, what: str = "a numeric case field") -> Vary:
    """``FIELD=START:STOP:COUNT`` -> :class:`Vary`; :class:`SweepError` naming what is wrong. ``valid``: the
    fields it may name (default: a case's numeric fields), ``what`` they are."""
    if "=" not in text:
        raise SweepError(f"--vary: expected FIELD=START:STOP:COUNT (got {text!r})")
    field, spec = text.split("=", 1)
    field = field.strip()
    valid = numeric_fields() if valid is None else valid
    if field not in valid:
        hint = difflib.get_close_matches(field, valid, n=1, cutoff=0.5)
        did = f"; did you mean '{hint[0]}'?" if hint else f"; numeric fields: {', '.join(valid)}"
        raise SweepError(f"--vary: {field}: not {what}{did}")
    parts = spec.split(":")
    if len(parts) != 3:
        raise SweepError(f"--vary: {field}: expected START:STOP:COUNT (got {spec!r})")
    try:
        start, stop = float(parts[0]), float(parts[1])
        count = int(parts[2])
    except ValueError:
        raise SweepError(
            f"--vary: {field}: START and STOP must be numbers, COUNT a whole number (got {spec!r})"
        ) from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise SweepError(f"--vary: {field}: START and STOP must be finite (got {spec!r})")
    if not 1 <= count <= 100_000:
        raise SweepError(f"--vary: {field}: COUNT must be 1 ... 100000 (got {count})")
    return Vary(field, start, stop, count)


def points_of(varies: list[Vary]) -> list[tuple[float, ...]]:
    """Every combination of the swept values, the last field varying fastest."""
    return [tuple(float(v) for v in combo) for combo in itertools.product(*(v.values for v in varies))]


def point_data(base: dict[str, Any], fields: list[str], values: tuple[float, ...]) -> dict[str, Any]:
    """The case mapping of one grid point (a copy of ``base`` with the fields set)."""
    return with_fields(base, dict(zip(fields, values, strict=True)))


def solve_block(
    base: dict[str, Any],
    fields: list[str],
    points: list[tuple[int, tuple[float, ...]]],
    placement: str | None,
    label: str,
) -> list[dict[str, Any]]:
    """Solve a block of grid points in order, each from its neighbour's plan; one row per point."""
    from planning.model.case_file import CaseFileError, case_from_data
    from planning.solver.optimize import solve
    from planning.solver.outcomes import PlanningError

    rows = []
    previous = None  # the plan of the point before: the next point starts from it
    for index, values in points:
        row: dict[str, Any] = {"index": index, **dict(zip(fields, values, strict=True))}
        t, started = time.perf_counter(), time.time()
        try:
            case = case_from_data(point_data(base, fields, values), f"{label}[{index}]")
            if case.pendulum:  # a swing's cold multi-start (no neighbour's start yet: nothing to repair from)
                row.update(_pendulum_row(case), case=case)
            else:
                sol = solve(case, placement, neighbour=previous)
                previous = sol.plan
                row.update(_solved_row(sol, case), plan=sol.plan, case=case)
        except CaseFileError as exc:
            row.update(status=Outcome.BAD_INPUT, message=str(exc))
        except PlanningError as exc:
            row.update(status=exc.outcome, message=exc.reason)
        except Exception as exc:  # noqa: BLE001 - one failing point never stops the sweep
            row.update(status=Outcome.ERROR, message=f"{type(exc).__name__}: {exc}")
        row["solve_time_s"] = time.perf_counter() - t
        stamp(row, started)
        rows.append(row)
    return rows


def _pendulum_row(case: Case) -> dict[str, Any]:
    """A pendulum point's row: its verified plan's figures (``planning.solver.pendulum_rate.solve_swings``: the
    most strokes, or at the case's target rate)."""
    from planning.solver.pendulum_rate import solve_swings

    return _solved_row(solve_swings(case, compare=False), case)


def _solved_row(sol, case) -> dict[str, Any]:  # noqa: ANN001 - a Solution and its Case
    from planning.reports.report import binding

    row = {
        "spm": sol.plan.spm,
        "cycle_time_s": sol.plan.period,
        "status": Outcome.VERIFIED,
        "binding": ";".join(binding(sol)),
        "message": "",
    }
    if sol.drive is not None:  # the energies a stroke's (a pendulum cycle's over its two strokes)
        figures = sol.drive.as_dict()
        strokes = sol.plan.strokes_per_cycle
        row.update({k: figures[k] / strokes if k.endswith("_kJ") else figures[k] for k in DRIVE_ROW_FIELDS})
        if sol.drive.power is not None:
            power = sol.drive.power.as_dict()
            row.update({k: power[k] for k in POWER_ROW_FIELDS})
    return row


def _electrical(base: dict[str, Any], fields: list[str]) -> bool:
    """The sweep's cases have the drive's electrical side (the base case has, or a swept field is one of its
    keys: ``planning.model.case.ELECTRICAL_KEYS``, or the objective is the grid's peak, as ``Case.electrical``)."""
    drive = base.get("drive")
    swept = any(f.startswith(tuple(f"drive.{key}" for key in ELECTRICAL_KEYS)) for f in fields)
    grid_objective = (base.get("planner") or {}).get("objective") == "min-grid-peak"
    return bool(drive) and (states_electrical(drive) or swept or grid_objective)


def neighbours(index: int, shape: tuple[int, ...]) -> list[int]:
    """Grid indices one step away from ``index`` along each field."""
    pos = np.unravel_index(index, shape)
    out = []
    for axis in range(len(shape)):
        for step in (-1, 1):
            q = list(pos)
            q[axis] += step
            if 0 <= q[axis] < shape[axis]:
                out.append(int(np.ravel_multi_index(q, shape)))
    return out


def repair(
    base: dict[str, Any],
    fields: list[str],
    points: list[tuple[float, ...]],
    shape: tuple[int, ...],
    rows: dict[int, dict[str, Any]],
    placement: str | None,
    label: str,
    passes: int | None = None,
    workers: int = 1,
    scheduler: str | None = None,
    timeline: Timeline | None = None,
) -> int:
    """Where a neighbour's plan verifies for a point and beats it, re-solve the point from that plan.

    Each point is its cold solve's answer or better, but a neighbour's plan may be better still (the NLP is
    not convex: another local optimum). A plan of a neighbouring point that passes this point's verification
    is a feasible answer here, so the point is never left worse than it. Each pass finds, in this process,
    every point with such plans (a plan once tried for a point is not tried again), then re-solves those
    points on the ``workers`` (or the Dask ``scheduler``), each from the plans it found, keeping the best;
    passes repeat until no point improves (an improvement travels one neighbour per pass; at most
    ``passes``, by default as many as there are points). Returns how many re-solves improved a point;
    ``timeline``: the time of the finding (one process) is added to its ``second_pass_serial_s``.
    """
    from planning.model.case_file import CaseFileError, case_from_data
    from planning.solver.solution import Solution
    from planning.solver.verify import evaluate

    improved = 0
    cases: dict[int, Any] = {}  # each point's case, read once for every pass
    tried: dict[tuple[int, int], Any] = {}  # (point, id of a neighbour's plan) checked -> the plan (kept, so
    # that its id is not reused by a later plan)
    for _ in range(len(rows) + 1 if passes is None else passes):
        finding = time.time()
        work = []
        for i in sorted(rows):
            if i not in cases and rows[i].get("case") is not None:  # the point's solve read it
                cases[i] = rows[i]["case"]
            if i not in cases:
                try:
                    cases[i] = case_from_data(point_data(base, fields, points[i]), f"{label}[{i}]")
                except CaseFileError:
                    cases[i] = None
            case = cases[i]
            if case is None:
                continue
            current = rows[i].get("spm") if verified(rows[i]) else None
            plans = []
            for j in neighbours(i, shape):
                plan = rows.get(j, {}).get("plan")
                if plan is None or (current is not None and plan.spm <= current + SAME_SPM) or (i, id(plan)) in tried:
                    continue
                tried[(i, id(plan))] = plan
                same = np.allclose(plan.key_angles, case.key_angles, atol=SAME_ANGLE_RAD)
                # the robot's window first: the verification's own check, without its dense grid (a faster
                # neighbour in a sweep of the transfer time fails it, and only it)
                short = case.robots is None and plan.transfer_window() < case.process.transfer_time_s - TIME_TOL_S
                if same and not short:
                    evaluation = evaluate(plan, case)  # handed over with the plan: not evaluated again
                    if evaluation.verification.passed:
                        plans.append(Solution(plan, evaluation))
            if plans:
                work.append((case, placement, i, current, plans))
        if timeline is not None:
            timeline.add("second_pass_serial_s", time.time() - finding)
        changed = False
        for found in execute(resolve_from, work, workers, scheduler):
            for row in found:
                i = row.pop("index")
                rows[i].update(row)
                improved += 1
                changed = True
        if not changed:
            break
    return improved


def resolve_from(
    case: Case, placement: str | None, index: int, current: float | None, plans: list[Any]
) -> list[dict[str, Any]]:
    """Point ``index`` (its ``case``) re-solved from each of ``plans`` (neighbours' plans verified against
    it, as solutions): the best that beats ``current`` [SPM] as a row update (``index``, the figures, the
    plan), or none."""
    from planning.solver.optimize import solve
    from planning.solver.outcomes import PlanningError

    best = None
    for plan in plans:
        try:
            sol = solve(case, placement, neighbour=plan, follow=True)
        except PlanningError:
            continue
        if (current is None or sol.plan.spm > current + SAME_SPM) and (best is None or sol.plan.spm > best.plan.spm):
            best = sol
    if best is None:
        return []
    return [{"index": index, **_solved_row(best, case), "plan": best.plan}]


def blocks(pending: list[int], points: list[tuple[float, ...]]) -> list[list[tuple[int, tuple[float, ...]]]]:
    """Contiguous runs of pending point indices, cut every :data:`BLOCK_POINTS` grid points."""
    out: dict[int, list[tuple[int, tuple[float, ...]]]] = {}
    for i in pending:
        out.setdefault(i // BLOCK_POINTS, []).append((i, points[i]))
    return [out[k] for k in sorted(out)]


@dataclass
class SweepResult:
    """``rows`` (all points, by index), how many were ``resumed`` from an earlier run, how many were
    ``repaired`` from a neighbour's better plan, and the run's ``timeline`` (``planning.timeline``)."""

    rows: list[dict[str, Any]]
    resumed: int
    fields: list[str]
    repaired: int = 0
    timeline: dict[str, Any] | None = None


def _read_spec(path: Path, out: Path) -> Any:
    """The sweep definition an earlier run wrote (None when there is none)."""
    if not path.exists():
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise SweepError(f"{out}: sweep.json cannot be read ({_reason(exc)}); choose another --out") from None


def _earlier_rows(path: Path, out: Path, count: int) -> dict[int, dict[str, Any]]:
    """Rows of an earlier run of this sweep by grid index; a table that is not this sweep's is an error."""
    try:
        rows = _read_rows(path)
    except (OSError, ValueError, csv.Error) as exc:
        raise SweepError(f"{out}: sweep.csv cannot be read ({_reason(exc)}); choose another --out") from None
    earlier = {}
    for n, row in enumerate(rows, start=2):
        if not row.get("status"):
            continue
        text = row.get("index")
        if text is None or not text.isdigit() or int(text) >= count:
            raise SweepError(
                f"{out}: sweep.csv line {n}: index {text!r} is not a point of this sweep; choose another --out"
            )
        earlier[int(text)] = row
    return earlier


def _reason(exc: Exception) -> str:
    return getattr(exc, "strerror", None) or " ".join(str(exc).split())[:100]


def _read_rows(path: Path) -> list[dict[str, Any]]:
    if not path.exists():
        return []
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def run_sweep(
    base: dict[str, Any],
    label: str,
    varies: list[Vary],
    out: Path,
    workers: int = 2,
    scheduler: str | None = None,
    placement: str | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    meanwhile: Callable[[], object] | None = None,
    finish: Callable[[SweepResult], None] | None = None,
) -> SweepResult:
    """Solve the grid into ``out/sweep.csv`` (resuming what an earlier run of the same sweep wrote);
    ``meanwhile``: see :func:`execute`; ``finish``: called with the result before the timeline closes
    (the caller's figure)."""
    timeline = Timeline()
    fields = [v.field for v in varies]
    points = points_of(varies)
    out.mkdir(parents=True, exist_ok=True)
    spec = {
        "fields": fields,
        "grid": [[v.start, v.stop, v.count] for v in varies],
        "case": base,
        "placement": placement,
    }
    spec_path, csv_path = out / "sweep.json", out / "sweep.csv"
    earlier_spec = _read_spec(spec_path, out)
    if isinstance(earlier_spec, dict):
        earlier_spec.pop("timeline", None)  # a run's own record, not the sweep's definition
    if earlier_spec not in (None, spec):
        raise SweepError(f"{out}: holds a different sweep (sweep.json); choose another --out")
    spec_path.write_text(json.dumps(spec, indent=2) + "\n", encoding="utf-8")
    earlier = _earlier_rows(csv_path, out, len(points))
    done = set(earlier)
    pending = [i for i in range(len(points)) if i not in done]
    columns = ["index", *fields, *ROW_FIELDS, *(DRIVE_ROW_FIELDS if base.get("drive") else ())]
    columns += POWER_ROW_FIELDS if _electrical(base, fields) else ()
    new_file = not csv_path.exists() or csv_path.stat().st_size == 0
    failed = sum(1 for r in earlier.values() if not verified(r))
    finished = len(done)
    fresh: dict[int, dict[str, Any]] = {}
    with open(csv_path, "a", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        if new_file:
            writer.writeheader()
        cut = blocks(pending, points)
        if cut and workers > 1 and not scheduler:  # the NLPs built here, inherited by the forked workers
            solve_block(base, fields, cut[0][:1], placement, label)
        work = [(base, fields, blk, placement, label) for blk in cut]
        for rows in execute(solve_block, work, workers, scheduler, meanwhile):
            for row in rows:
                writer.writerow({k: _cell(row.get(k)) for k in columns})
                fresh[row["index"]] = row
                finished += 1
                failed += not verified(row)
            fh.flush()
            os.fsync(fh.fileno())
            if progress:
                progress(finished, len(points), failed)
    shape = tuple(v.count for v in varies)
    for i, r in earlier.items():  # rows of an earlier run: their plans are not kept
        fresh.setdefault(i, {**r, "index": i, "spm": float(r["spm"]) if r.get("spm") else None})
    timeline.mark("second_pass_start")
    improved = repair(base, fields, points, shape, fresh, placement, label, None, workers, scheduler, timeline)
    timeline.mark("second_pass_end")
    tmp = csv_path.with_suffix(".csv.tmp")
    with open(tmp, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for i in sorted(fresh):
            writer.writerow({k: _cell(fresh[i].get(k)) for k in columns})
    os.replace(tmp, csv_path)
    rows = sorted(_read_rows(csv_path), key=lambda r: int(r["index"]))
    result = SweepResult(rows, len(done), fields, improved)
    if finish is not None:
        finish(result)
    timeline.mark("end")
    result.timeline = timeline.as_dict(list(fresh.values()), [[i for i, _ in blk] for blk in cut])
    spec_path.write_text(json.dumps({**spec, "timeline": result.timeline}, indent=2) + "\n", encoding="utf-8")
    return result


def _cell(value: Any) -> Any:
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, Outcome):
        return value.value
    return "" if value is None else value


def verified(row: dict[str, Any]) -> bool:
    """Whether a sweep's or a trade-off's row (solved now or read back from its file) holds a verified plan."""
    return Outcome.of(row.get("status")).succeeded


def execute(
    task: Callable[..., list[dict[str, Any]]],
    work: list[tuple],
    workers: int = 2,
    scheduler: str | None = None,
    meanwhile: Callable[[], object] | None = None,
) -> Iterator[list[dict[str, Any]]]:
    """``task(*args)`` for every ``args`` of ``work``, results as they finish: in this process (1
    worker), a pool of local processes, or a Dask distributed cluster at ``scheduler``. Ctrl-C and
    SIGTERM end every worker process with the parent's. ``meanwhile``: called in this process once the
    work is with the workers (the local ones forked), while it would only wait (e.g. loading the
    plotting library for the figure that follows)."""
    if not work:
        return
    if scheduler:
        try:
            from dask.distributed import Client, as_completed
        except ImportError:
            raise SweepError("--scheduler needs dask.distributed (pip install 'pressplan[cluster]')") from None
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise SweepError(f"--scheduler: cannot reach {scheduler} ({exc})") from None
        try:
            futures = [client.submit(task, *args, pure=False) for args in work]
            if meanwhile is not None:
                meanwhile()
            for fut in as_completed(futures):
                yield fut.result()
        finally:
            client.close()
        return
    if workers <= 1:
        for args in work:
            yield task(*args)
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from planning.solver.ahead import signals_held, worker_signals

    ctx = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn")
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=worker_signals)
    try:
        with signals_held():  # the workers start here: no Ctrl-C before they ignore it
            futures = [pool.submit(task, *args) for args in work]
        if meanwhile is not None:
            meanwhile()
        for fut in as_completed(futures):
            yield fut.result()
    except BaseException:  # Ctrl-C, SIGTERM, a failed write: no worker outlives the run
        for process in list(getattr(pool, "_processes", {}).values()):
            process.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
