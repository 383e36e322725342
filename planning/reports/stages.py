"""The stage table: per stage of the motion law (transfer, feed, draw, return), where it starts and ends,
how long it takes, its peak crank speed, and which limits bind in it.

A stage is the run of the law's segments with one stage name (``feed:accel1`` ... ``feed:decel4`` is the
feed); a run through TDC (the return's end and its start in the next cycle) is one stage, its end angle
past 360 deg. Which limits bind where is what the verification recorded: a check that binds
(``Check.binds``) is placed in every stage where its quantity came within ``BINDING_SHARE`` of its
extreme (``Check.peak``, on the dense samples); a binding check with no place on the cycle (the robot's
transfer time, the RMS torque, the motor's top speed, a figure of the whole cycle) is listed apart, as
binding over the cycle.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from planning.model.plan import stage_of
from planning.model.units import RPM
from planning.solver.verify import Evaluation
from planning.tolerances import KNOT_TIME_S

STAGE_ORDER = ("dwell", "window", "feed", "draw", "return")  # the table starts with the dwell (or the window)


def stage_runs(segments: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The law's stages from ``result.json``'s ``segments`` (from TDC): name, start and end crank angle
    [deg from TDC; the end past 360 for a stage through TDC], start time [s from TDC], duration [s]."""
    runs: list[dict[str, Any]] = []
    for seg in segments:
        if seg["duration_s"] <= KNOT_TIME_S:  # a stage of no length (a dwell the plan does not use): no row
            continue
        stage = stage_of(seg["name"])
        if runs and runs[-1]["name"] == stage:
            runs[-1]["end_angle_deg"] = seg["end_angle_deg"]
            runs[-1]["duration_s"] += seg["duration_s"]
            continue
        runs.append(
            {
                "name": stage,
                "start_angle_deg": seg["start_angle_deg"],
                "end_angle_deg": seg["end_angle_deg"],
                "start_time_s": seg["start_time_s"],
                "duration_s": seg["duration_s"],
            }
        )
    if len(runs) > 1 and runs[0]["name"] == runs[-1]["name"]:  # through TDC: one stage
        first = runs.pop(0)
        runs[-1]["end_angle_deg"] = first["end_angle_deg"] + 360.0
        runs[-1]["duration_s"] += first["duration_s"]
    first = next((name for name in STAGE_ORDER if any(r["name"] == name for r in runs)), None)
    start = next((k for k, r in enumerate(runs) if r["name"] == first), 0)
    return runs[start:] + runs[:start]


def stage_table(segments: list[dict[str, Any]], evaluation: Evaluation, rows: np.ndarray) -> dict[str, Any]:
    """``{"stages": [...], "binding_over_cycle": [...]}`` for ``result.json``: each stage of :func:`stage_runs`
    (``segments`` as ``result.json`` writes them) with ``peak_crank_speed_rpm`` (on the evaluation's samples
    ``rows``) and ``binding`` (case fields: the binding checks that peaked in the stage); the binding checks
    of the whole cycle (no place on it) by case field."""
    dense = evaluation.samples
    angle = np.degrees(dense.theta[rows])
    speed = dense.omega[rows] / RPM
    runs = stage_runs(segments)
    step = evaluation.verification.step_s
    placed: dict[int, list[str]] = {k: [] for k in range(len(runs))}
    over_cycle: list[str] = []
    for field, check in _binding(evaluation):
        if check.peak is None:
            over_cycle.append(field)
            continue
        for k, run in enumerate(runs):
            if field not in placed[k] and _peaks_in(check.peak.spans, run, dense.plan.period, step):
                placed[k].append(field)
    stages = []
    for k, run in enumerate(runs):
        mask = _in_arc(angle, run["start_angle_deg"], run["end_angle_deg"])
        if not mask.any():  # a stage shorter than a step: the sample nearest its start
            distance = np.abs((angle - run["start_angle_deg"] + 180.0) % 360.0 - 180.0)
            mask = distance == np.min(distance)
        peak = float(np.max(speed[mask]))
        stages.append({**run, "peak_crank_speed_rpm": peak, "binding": placed[k]})
    return {"stages": stages, "binding_over_cycle": over_cycle}


def _in_arc(angle: np.ndarray, start: float, end: float) -> np.ndarray:
    """Samples with crank angle in [start, end) [deg], ``end`` up to 360 past ``start`` (through TDC): a
    sample on a boundary belongs to the stage it begins."""
    return (angle - start) % 360.0 < (end - start)


def _peaks_in(spans: tuple[tuple[float, float], ...], run: dict[str, Any], period: float, step: float) -> bool:
    """Whether a check that peaks over ``spans`` [s from TDC] peaks in the stage ``run``: a span of samples
    lies in the stage or reaches more than a sampling ``step`` [s] into it (a curve continuous across a
    boundary binds where it stays, not in the first sample past it); a single instant (a limit at one crank
    angle, a sharp peak) belongs to the stage it lies in, a boundary to the stage it begins."""
    start = run["start_time_s"]
    end = start + run["duration_s"]
    for a, b in spans:
        for shift in (0.0, period):  # a stage through TDC ends past the period
            a_, b_ = a + shift, b + shift
            if a_ == b_ or (a_ >= start and b_ <= end):
                if start - KNOT_TIME_S <= a_ < end - KNOT_TIME_S:
                    return True
            elif min(b_, end) - max(a_, start) > step:
                return True
    return False


def _binding(evaluation: Evaluation) -> list[tuple[str, Any]]:
    """The checks that bind, with their case fields, in the verification's order; a field once (its first
    check); the storage schedule's bounds and the robots' own moves apart (``Verification.binding``)."""
    from planning.solver.verify import field_of_check

    out: dict[str, Any] = {}
    for check in evaluation.verification.binding():
        out.setdefault(field_of_check(check.id) or check.name, check)
    return list(out.items())
