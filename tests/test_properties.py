"""Property tests on random presses (tests/random_cases.py): every run ends in a verified plan or a
clean answer (exit 2 or 3), never NaN; the same input gives the same output; relaxing a limit never
costs strokes. The normal run draws FAST_EXAMPLES cases; ``pytest -m slow`` adds SLOW_CASES more."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from planning.model.case_file import CaseFileError, case_from_data
from planning.reports.outputs import solution_writers
from planning.reports.report import result_dict, trajectory
from planning.solver.optimize import solve
from planning.solver.outcomes import PlanningError

from .random_cases import CASES, CASES_DRAW_SPEED_FREE, CASES_DRAW_SPEED_GIVEN, seeded_case

FAST_EXAMPLES = 200
SLOW_CASES = 2000
SLOW_CHUNK = 100
RELAXATION_EXAMPLES = 16
PROFILE = settings(
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


def outcome(data: dict) -> str:
    """Run one case through the API the CLI uses; assert the properties; return the outcome."""
    try:
        case = case_from_data(data, data["name"])
    except CaseFileError as exc:
        assert "\n" not in str(exc)
        return "bad input (exit 2)"
    try:
        sol = solve(case)
    except PlanningError as exc:
        assert exc.kind in ("infeasible", "unverified", "no verified plan") and "\n" not in str(exc)
        return f"{exc.kind} (exit 3)"
    assert sol.verification.passed
    json.dumps(result_dict(sol, case), allow_nan=False)  # raises on NaN or infinity
    tab = trajectory(sol, case)
    assert np.all(np.isfinite(tab))
    assert np.max(np.abs(tab[:, 7])) <= case.limits.slider_accel_mm_s2 * (1 + 1e-6)
    assert tab[-1, 1] - tab[0, 1] == pytest.approx(360.0, abs=1e-7)
    assert 0 < sol.plan.spm < math.inf
    return "verified"


@settings(PROFILE, max_examples=FAST_EXAMPLES // 2)
@given(data=CASES_DRAW_SPEED_GIVEN)
def test_random_press_with_draw_speed_ends_verified_or_clean(data):
    event(outcome(data))


@settings(PROFILE, max_examples=FAST_EXAMPLES // 2)
@given(data=CASES_DRAW_SPEED_FREE)
def test_random_press_free_draw_speed_ends_verified_or_clean(data):
    event(outcome(data))


@pytest.mark.slow
@pytest.mark.parametrize("chunk", range(SLOW_CASES // SLOW_CHUNK))
def test_many_random_presses(chunk):
    for seed in range(chunk * SLOW_CHUNK, (chunk + 1) * SLOW_CHUNK):
        outcome(seeded_case(10_000 + seed))


def _file_bytes(data: dict) -> dict[str, bytes]:
    """Everything solve writes except figures, as bytes; the solver's wall time (a measurement, not a
    result) is blanked in result.json and summary.txt."""
    case = case_from_data(data)
    sol = solve(case)
    out = {}
    for name, write in solution_writers(sol, case, plot_format=None).items():
        if name == "result.json":
            r = result_dict(sol, case)
            r["solver"]["wall_time_s"] = 0.0
            out[name] = json.dumps(r, sort_keys=True).encode()
        else:
            import tempfile
            from pathlib import Path

            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / name
                write(path)
                out[name] = re.sub(rb"starts, [0-9.]+ s", b"starts, <wall time> s", path.read_bytes())
    return out


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_same_input_same_output_bytes(seed):
    data = seeded_case(seed)
    assert _file_bytes(data) == _file_bytes(data)


@settings(PROFILE, max_examples=12)
@given(data=CASES, relax=st.sampled_from(["slider_accel_mm_s2", "transfer_time_s", "min_crank_speed_rpm"]))
def test_relaxing_a_limit_never_costs_strokes(data, relax):
    try:
        case = case_from_data(data)
        base = solve(case)
    except (CaseFileError, PlanningError):
        return
    relaxed = json.loads(json.dumps(data))
    if relax == "slider_accel_mm_s2":
        relaxed["limits"]["slider_accel_mm_s2"] *= 1.1
    elif relax == "transfer_time_s":
        relaxed["process"]["transfer_time_s"] *= 0.9
    else:
        relaxed["limits"]["min_crank_speed_rpm"] = 0.5
    if "draw_speed_rpm" not in relaxed["process"]:  # keep the draw speed the first plan used
        relaxed["process"]["draw_speed_rpm"] = float(base.plan.parameters.draw_speed) * 60 / (2 * math.pi)
    better = solve(case_from_data(relaxed), neighbour=base.plan)
    assert better.plan.spm >= base.plan.spm - 1e-9


RELAXATIONS = {  # each makes the set of feasible motions larger (or keeps it)
    "slider_accel_mm_s2": ("limits", "slider_accel_mm_s2", 1.1),
    "transfer_time_s": ("process", "transfer_time_s", 0.9),
    "die_speed_mm_s": ("limits", "die_speed_mm_s", 1.2),
    "draw_start_speed_mm_s": ("limits", "draw_start_speed_mm_s", 1.2),
    "min_crank_speed_rpm": ("limits", "min_crank_speed_rpm", 0.5),
    "safety_height_mm": ("process", "safety_height_mm", 0.97),
}


@settings(PROFILE, max_examples=RELAXATION_EXAMPLES)
@given(data=CASES, relax=st.sampled_from(sorted(RELAXATIONS)))
def test_relaxing_any_limit_never_turns_a_solved_case_into_exit_3(data, relax):
    """Solved alone (no neighbour plan to lean on), the looser case is never worse off than exit 3."""
    try:
        solve(case_from_data(data))
    except (CaseFileError, PlanningError):
        return
    relaxed = json.loads(json.dumps(data))
    section, key, factor = RELAXATIONS[relax]
    relaxed[section][key] = relaxed[section].get(key, 1.0) * factor
    event(relax)
    solve(case_from_data(relaxed))  # raises PlanningError (a failed test) when the looser case gets exit 3


@settings(PROFILE, max_examples=12)
@given(data=CASES, law=st.sampled_from(["seven-segment", "quintic", "logistic", "cycloidal"]))
def test_random_press_under_every_law_ends_verified_or_clean(data, law):
    data = json.loads(json.dumps(data))
    data.setdefault("planner", {})["motion_law"] = law
    event(f"{law}: {outcome(data)}")
