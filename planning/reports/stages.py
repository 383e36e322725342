"""The stage table: per stage of the motion law (transfer, feed, draw, return), where it starts and ends,
how long it takes, its peak crank speed, and which limits bind in it.

A stage is the run of the law's segments with one stage name (``feed:accel1`` ... ``feed:decel4`` is the
feed); a run through TDC (the return's end and its start in the next cycle) is one stage, its end angle
past 360 deg. Which limits bind where is read off the dense samples (``trajectory.csv``'s columns) with
the limits' own lines (``planning.reports.limit_lines``): a limit the verification finds binding
(``Check.binds``) is placed in the stage where the curve comes closest to its line, and in any other
stage that comes as close within :data:`BINDING_SHARE`; the motor's peak torque likewise against its
envelope at the motor's speed. A binding limit with no curve to place it on (the robot's transfer time,
the RMS torque, a limit of the whole cycle) is listed apart, as binding over the cycle.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from planning.model.limits.base import BINDING_SHARE
from planning.model.units import RPM
from planning.reports.limit_lines import limit_lines
from press.dynamics import envelope_torque

PEAK_TORQUE_FIELD = "drive.motor.peak_torque_Nm"
STAGE_ORDER = ("transfer", "feed", "draw", "return")  # the table starts with the transfer


def stage_runs(segments: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The law's stages from ``result.json``'s ``segments`` (from TDC): name, start and end crank angle
    [deg from TDC; the end past 360 for a stage through TDC], start time [s from TDC], duration [s]."""
    runs: list[dict[str, Any]] = []
    for seg in segments:
        stage = seg["name"].partition(":")[0]
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
    start = next((k for k, r in enumerate(runs) if r["name"] == STAGE_ORDER[0]), 0)
    return runs[start:] + runs[:start]


def stage_table(result: dict[str, Any], columns: dict[str, np.ndarray]) -> dict[str, Any]:
    """``{"stages": [...], "binding_over_cycle": [...]}`` for ``result.json``: each stage of
    :func:`stage_runs` with ``peak_crank_speed_rpm`` and ``binding`` (case fields), from the dense
    ``columns``; the binding limits placed on no stage by case field."""
    angle = np.asarray(columns["crank_angle_deg"], dtype=float)
    speed = np.asarray(columns["crank_speed_rpm"], dtype=float)
    runs = stage_runs(result["segments"])
    masks = [_in_arc(angle, r["start_angle_deg"], r["end_angle_deg"]) for r in runs]
    inner = [_inside(m) for m in masks]  # a curve continuous across a boundary binds where it stays, not there
    closeness = _closeness(result, columns)  # field -> per sample: 1 on the limit's line, lower away from it
    placed: dict[int, list[str]] = {k: [] for k in range(len(runs))}
    over_cycle = []
    for name in _binding_fields(result):
        near = closeness.get(name)
        if near is None:
            over_cycle.append(name)
            continue
        point = np.count_nonzero(np.isfinite(near)) == 1  # a limit at one crank angle: its stage
        best = [_nanmax(near[m if point else i]) for m, i in zip(masks, inner, strict=True)]
        top = max(best)
        for k, value in enumerate(best):
            if value >= top - BINDING_SHARE:
                placed[k].append(name)
    stages = []
    for k, (run, mask) in enumerate(zip(runs, masks, strict=True)):
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


def _inside(mask: np.ndarray) -> np.ndarray:
    """``mask`` without its first and last sample of each run (a stage's ends, shared with its neighbours)."""
    edges = mask & ~(np.roll(mask, 1) & np.roll(mask, -1))
    return mask & ~edges


def _nanmax(values: np.ndarray) -> float:
    finite = values[np.isfinite(values)]
    return float(np.max(finite)) if finite.size else -np.inf


def _binding_fields(result: dict[str, Any]) -> list[str]:
    """The case fields of the checks that bind (``result.json``'s verification), in its order; the storage
    schedule's bounds apart (``planning.solver.verify.SCHEDULE_CHECKS``)."""
    from planning.solver.verify import SCHEDULE_CHECKS, field_of_check

    fields = []
    for check in result["verification"]["checks"]:
        if check["kind"] == "equal" or check["margin"] > BINDING_SHARE * max(abs(check["limit"]), 1e-12):
            continue
        if check["id"] in SCHEDULE_CHECKS:
            continue
        name = field_of_check(check["id"]) or check["name"]
        if name not in fields:
            fields.append(name)
    return fields


def _closeness(result: dict[str, Any], columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Per case field with a curve: ``1 - |distance to the limit's line| / |limit|`` at each sample (NaN
    where it does not apply); the lines on the slide's height (where the key points and the die zone
    begin, not limits a curve presses on) left out."""
    n = len(columns["crank_angle_deg"])
    out: dict[str, np.ndarray] = {}
    for line in limit_lines(result, columns, "angle"):
        if line.quantity == "slider_height_mm":
            continue
        q = np.asarray(columns[line.quantity], dtype=float)
        if line.point:
            near = np.full(n, np.nan)
            k = min(int(np.searchsorted(columns["crank_angle_deg"], line.x[0])), n - 1)  # first at or after
            near[k] = 1.0 - abs(abs(q[k]) - abs(line.upper[0])) / abs(line.upper[0])
        else:
            lines = [line.upper] + ([line.lower] if line.lower is not None else [])
            with np.errstate(invalid="ignore"):
                near = np.fmax.reduce([1.0 - np.abs(q - y) / np.abs(y) for y in lines])
        out[line.field] = near
    drive = result.get("drive")
    if drive is not None and "motor_torque_Nm" in columns:
        motor = drive["motor"]
        n_motor = np.asarray(columns["motor_speed_rpm"], dtype=float) * RPM
        envelope = envelope_torque(n_motor, motor["peak_torque_Nm"], motor["base_speed_rpm"] * RPM)
        out[PEAK_TORQUE_FIELD] = np.abs(np.asarray(columns["motor_torque_Nm"], dtype=float)) / envelope
    return out
