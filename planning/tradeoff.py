"""The motor-sizing curve: at each line rate the gentlest verified plan beside the baseline it beats.

The fastest plan (max-SPM) is solved once, in this process, and the rate NLP is built before the
workers fork; then each rate, a task of its own, goes to the next free worker and is solved cold from
the fastest plan (``planning.solver.objectives.solve_at_rate``): the same answer as
``pressplan solve`` at that rate. The blocks run on local worker processes or a Dask
cluster through the sweep's machinery (``planning.sweep.execute``).
A rate above what the limits allow becomes a row that says why.
"""

from __future__ import annotations

import csv
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from planning.model.case import Case, Placement
from planning.model.outcome import Outcome
from planning.solver.solution import ENERGY, GRID_PEAK
from planning.sweep import SweepError, _cell, execute, verified
from planning.timeline import Timeline, stamp

# the drive's figures of a cycle that are energies (a stroke's in the rows)
ENERGY_FIELDS = ("energy_drawn_kJ", "energy_returned_kJ", "energy_net_kJ", "supply_energy_kJ")
# one row per rate: the plan's figures, the baseline's, the savings
FIGURE_FIELDS = (
    "rms_motor_torque_Nm",
    "peak_motor_torque_Nm",
    "peak_motor_power_kW",
    "energy_drawn_kJ",
    "energy_returned_kJ",
    "energy_net_kJ",
    "supply_energy_kJ",
    "energy_kJ",  # the energy the objectives weigh: at the bus, losses counted, with the electrical side
    "transfer_window_s",
)
COLUMNS = (
    "target_spm",
    "status",
    *FIGURE_FIELDS,
    *(f"baseline_{k}" for k in FIGURE_FIELDS),
    "saving_rms_pct",
    "saving_energy_pct",
    "improved_on_baseline",
    "solve_time_s",
    "message",
)
# with the drive's electrical side (``Case.electrical``; min-grid-peak's): the grid's peak and its saving
GRID_COLUMNS = ("grid_peak_kW", "baseline_grid_peak_kW", "saving_grid_peak_pct")
MAX_RATES = 1000


def columns(case: Case) -> tuple[str, ...]:
    """The columns of ``tradeoff.csv`` for ``case``: :data:`COLUMNS`, and :data:`GRID_COLUMNS` before the
    solve's status and time where the grid's side is computed."""
    if not case.electrical:
        return COLUMNS
    at = COLUMNS.index("improved_on_baseline")
    return COLUMNS[:at] + GRID_COLUMNS + COLUMNS[at:]


@dataclass(frozen=True)
class Rates:
    """``count`` rates from ``start`` to ``stop`` [strokes/min]; ``stop`` None: the fastest rate."""

    start: float
    stop: float | None
    count: int

    def values(self, fastest_spm: float) -> np.ndarray:
        """The rates, rounded to 12 significant digits."""
        stop = fastest_spm if self.stop is None else self.stop
        return np.array([float(f"{v:.12g}") for v in np.linspace(self.start, stop, self.count)])


def parse_rates(text: str) -> Rates:
    """``START:STOP:COUNT`` (``STOP`` may be ``max``, the fastest rate the limits allow) -> :class:`Rates`."""
    parts = text.split(":")
    if len(parts) != 3:
        raise SweepError(f"--spm: expected START:STOP:COUNT, STOP a rate or 'max' (got {text!r})")
    try:
        start = float(parts[0])
        stop = None if parts[1].strip().lower() == "max" else float(parts[1])
        count = int(parts[2])
    except ValueError:
        raise SweepError(
            f"--spm: START and STOP must be numbers (STOP may be 'max'), COUNT a whole number (got {text!r})"
        ) from None
    for value in (start, stop):
        if value is not None and not (math.isfinite(value) and 0 < value <= 1e4):
            raise SweepError(f"--spm: rates must lie in (0, 10000] strokes/min (got {text!r})")
    if not 1 <= count <= MAX_RATES:
        raise SweepError(f"--spm: COUNT must be 1 ... {MAX_RATES} (got {count})")
    return Rates(start, stop, count)


def rate_block(case: Case, placement: Placement | None, fastest: Any, rates: list[tuple[int, float]]) -> list[dict]:
    """Solve the ``rates`` (index, rate), each as a cold solve of the case at that rate (its baseline and
    objective from the fastest plan's starts): one answer per case, whatever block a rate falls in. A
    neighbouring rate's plan as a further start cost about as much as the cold starts and rarely found
    more (2.5e-5 relative on the side panel at 5 strokes/min), so it is not tried."""
    from planning.solver.objectives import solve_at_rate
    from planning.solver.outcomes import PlanningError
    from planning.solver.pendulum_rate import solve_pendulum_at_rate

    rows = []
    for index, rate in rates:
        row: dict[str, Any] = {"index": index, "target_spm": rate}
        t, started = time.perf_counter(), time.time()
        try:
            at_rate = case.with_objective(None, rate)
            if case.pendulum:
                solution = solve_pendulum_at_rate(at_rate, fastest)
            else:
                solution = solve_at_rate(at_rate, placement, fastest=fastest)
            row.update(solved_row(solution, at_rate))
        except PlanningError as exc:
            row.update(status=exc.outcome, message=exc.reason)
        row["solve_time_s"] = time.perf_counter() - t
        stamp(row, started)
        rows.append(row)
    return rows


def solved_row(sol: Any, case: Case) -> dict[str, Any]:
    """The figures of a solution at a rate and of its baseline (the drive's figures each carries; the energies a
    stroke's, a pendulum cycle's over its two strokes)."""
    a = sol.at_rate
    row: dict[str, Any] = {"status": Outcome.VERIFIED, "message": "", "improved_on_baseline": a.improved}
    for prefix, solution in (("", sol), ("baseline_", a.baseline)):
        strokes = solution.plan.strokes_per_cycle
        figures = {**solution.drive.as_dict(), "transfer_window_s": solution.plan.transfer_window()}
        figures.update({k: figures[k] / strokes for k in ENERGY_FIELDS})
        figures["energy_kJ"] = solution.energy_kJ
        row.update({f"{prefix}{k}": figures[k] for k in FIGURE_FIELDS})
    row["saving_rms_pct"] = sol.saving_pct("rms_motor_torque_Nm")
    row["saving_energy_pct"] = sol.saving_pct(ENERGY)
    if sol.drive.power is not None and a.baseline.drive.power is not None:
        row["grid_peak_kW"] = sol.drive.power.grid_peak_kW
        row["baseline_grid_peak_kW"] = a.baseline.drive.power.grid_peak_kW
        row["saving_grid_peak_pct"] = sol.saving_pct(GRID_PEAK)
    return row


@dataclass
class TradeoffResult:
    """``rows`` in rate order, the ``fastest`` max-SPM solution, the ``objective`` and the run's ``timeline``."""

    rows: list[dict[str, Any]]
    fastest: Any
    objective: str
    timeline: dict[str, Any] | None = None  # planning.timeline (the outputs' writing apart)

    def thermal_statement(self, case: Case) -> str:
        """What the motor's thermal limit allows: whether it sets the fastest rate, and the RMS there."""
        from planning.model.limits.motor import MotorRMSTorqueLimit
        from planning.reports.report import binding

        fast = self.fastest.plan
        rms = self.fastest.drive.rms_motor_torque_Nm
        rated = case.drive.motor.rated_torque_Nm
        names = binding(self.fastest)
        if any(c.id == MotorRMSTorqueLimit.id for c in self.fastest.verification.binding()):
            return (
                f"the motor's thermal limit sets the highest rate: {fast.spm:.3f} strokes/min "
                f"(RMS torque {rms:.0f} N m = rated {rated:g} N m)"
            )
        return (
            f"the motor's thermal limit allows every rate the other limits allow: at the highest, "
            f"{fast.spm:.3f} strokes/min (set by {', '.join(names) or 'the key points'}), the RMS torque is "
            f"{rms:.0f} N m, {100 * rms / rated:.1f} % of rated"
        )


def run_tradeoff(
    case: Case,
    rates: Rates,
    workers: int = 2,
    scheduler: str | None = None,
    placement: Placement | None = None,
    meanwhile: Callable[[], object] | None = None,
    progress: Callable[[int, int, int], None] | None = None,
) -> TradeoffResult:
    """One plan per rate at ``case.planner.objective`` (min-rms-torque, min-energy or min-grid-peak); ``meanwhile``: see
    ``planning.sweep.execute``."""
    timeline = Timeline()
    fastest = _fastest_and_nlps(case, placement)
    values = rates.values(fastest.plan.spm)
    order = list(enumerate(values.tolist()))[::-1]  # from the fastest rate down
    # each rate a task of its own (each is solved cold, independent of the others): the workers take the
    # next rate as they finish, so none idles while another holds several
    work = [(case, placement, fastest, [rate]) for rate in order]
    rows: dict[int, dict[str, Any]] = {}
    for block in execute(rate_block, work, workers, scheduler, meanwhile):
        for row in block:
            rows[row["index"]] = row
        if progress is not None:
            progress(len(rows), len(order), sum(not verified(r) for r in rows.values()))
    timeline.mark("end")
    ordered = [rows[i] for i in sorted(rows)]
    return TradeoffResult(ordered, fastest, case.planner.objective, timeline.as_dict(ordered))


def _fastest_and_nlps(case: Case, placement: Placement | None) -> Any:
    """The case's max-SPM solution (a pendulum's swings without the rotary comparison), its rate NLP built
    here, once, inherited by forked workers."""
    if case.pendulum:
        from planning.solver.pendulum import solve_pendulum
        from planning.solver.pendulum_rate import rate_nlp

        rate_nlp(case)
        return solve_pendulum(case.with_objective("max-spm"), compare=False)
    from planning.solver.halves_nlp import halves_nlp_for
    from planning.solver.optimize import solve

    fastest = solve(case.with_objective("max-spm"), placement)
    halves_nlp_for(case, drive=True, rate=True)
    if case.planner.objective == "min-grid-peak":
        halves_nlp_for(case, drive=True, rate=True, peak=True)
    return fastest


def write_rows(path: Path, rows: list[dict[str, Any]], columns: tuple[str, ...]) -> None:
    """``rows`` as CSV with ``columns`` (floats in full precision, empty cells for missing values)."""
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: _cell(row.get(k)) for k in columns})


def table_text(result: TradeoffResult, case: Case) -> str:
    """The console table: per rate the RMS torque and the energy, optimised against the baseline."""
    grid = case.electrical
    lines = [
        f"{case.name}: {result.objective} at the line's rate ({case.planner.motion_law}); "
        f"rated torque {case.drive.motor.rated_torque_Nm:g} N m, peak {case.drive.motor.peak_torque_Nm:g} N m",
        f"  {'SPM':>8} {'RMS kN m':>9} {'baseline':>9} {'saving':>7} {'energy kJ':>10} {'baseline':>9} {'saving':>7}"
        + (f" {'grid kW':>8} {'baseline':>9} {'saving':>7}" if grid else ""),
    ]
    for r in result.rows:
        if not verified(r):
            lines.append(f"  {r['target_spm']:8.3f}  {r['status']}: {r['message']}")
            continue
        lines.append(
            f"  {r['target_spm']:8.3f} {r['rms_motor_torque_Nm'] / 1e3:9.2f} "
            f"{r['baseline_rms_motor_torque_Nm'] / 1e3:9.2f} "
            f"{r['saving_rms_pct']:6.1f}% {r['energy_kJ']:10.1f} {r['baseline_energy_kJ']:9.1f} "
            f"{r['saving_energy_pct']:6.1f}%"
            + (
                f" {r['grid_peak_kW']:8.0f} {r['baseline_grid_peak_kW']:9.0f} {r['saving_grid_peak_pct']:6.1f}%"
                if grid
                else ""
            )
        )
    lines.append("  " + result.thermal_statement(case))
    return "\n".join(lines)
