"""Property tests on random presses (tests/random_cases.py): every run ends in a verified plan or a
clean answer (exit 2 or 3), never NaN, and at least :data:`VERIFIED_SHARE` of a fixed random set of
presses end verified, every exit 3 naming the case field it could not meet; the same input gives the
same output; relaxing a limit never costs strokes, solved cold. ``pytest -m slow`` adds SLOW_CASES more."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

from planning.model.case_file import CaseFileError, case_from_data
from planning.reports.outputs import solution_writers
from planning.reports.report import result_dict, trajectory
from planning.solver.optimize import solve
from planning.solver.outcomes import PlanningError
from planning.solver.upper_bound import upper_bound

from .random_cases import CASES, build_case, seeded_case, seeded_offset_case

RANDOM_SET = 100  # presses of each kind (draw speed given, or left to the planner) in the normal run
VERIFIED_SHARE = 0.9  # of them at least this share end in a verified plan
OFFSET_SET = 40  # offset crank-sliders: the first quarter in the normal run, the others in the slow tier
RANDOM_PARTS = 5  # each set in parts of 20 presses (tests the workers share)
QUICK_PARTS = 1  # of them in the normal run; the others in the slow tier (CI runs both)
UPPER_BOUND_SET = 4  # verified presses of each part checked against the certified upper bound (40 in all)
UPPER_BOUND_LAWS_SET = 30  # random presses whose every law and bracket motion the slow run checks against it
SLOW_CASES = 2000
SLOW_CHUNK = 100
RELAXATION_EXAMPLES = 6
PROFILE = settings(
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


# a dotted case field, as every exit-3 message names the one it could not meet
CASE_FIELD = re.compile(r"\b(?:limits|process|drive|key_points|planner|press)\.[a-z_.]+[a-zA-Z]|\bkey_points\b")


def outcome(data: dict, spms: list[float] | None = None) -> str:
    """Run one case through the API the CLI uses; assert the properties; return the outcome (``spms``:
    appended the verified plan's strokes/min, or 0.0)."""
    if spms is not None:
        spms.append(0.0)
    try:
        case = case_from_data(data, data["name"])
    except CaseFileError as exc:
        assert "\n" not in str(exc)
        return "bad input (exit 2)"
    try:
        sol = solve(case)
    except PlanningError as exc:
        assert exc.outcome.without_plan and "\n" not in str(exc)
        assert CASE_FIELD.search(str(exc)), f"exit 3 without the case field it could not meet: {exc}"
        return f"{exc.outcome} (exit {exc.outcome.exit_code})"
    json.dumps(result_dict(sol, case), allow_nan=False)  # raises on NaN or infinity
    tab = trajectory(sol, case)
    assert all(np.all(np.isfinite(column)) for column in tab.values())
    assert np.max(np.abs(tab["slider_accel_mm_s2"])) <= case.limits.slider_accel_mm_s2 * (1 + 1e-6)
    assert tab["crank_angle_deg"][-1] - tab["crank_angle_deg"][0] == pytest.approx(360.0, abs=1e-7)
    assert 0 < sol.plan.spm < math.inf
    if spms is not None:
        spms[-1] = sol.plan.spm
    return "verified"


def random_set(draw_speed_given: bool) -> list[dict]:
    """A fixed random set of presses: :data:`RANDOM_SET` seeds, the draw speed given or left to the planner."""
    last = 0.25 if draw_speed_given else 0.75  # the builder's last number decides (< 0.5: given)
    return [
        build_case(list(np.random.default_rng(seed).random(13)) + [last], name=f"random-{seed}")
        for seed in range(RANDOM_SET)
    ]


@pytest.mark.parametrize(
    "part",
    [pytest.param(k, marks=[] if k < QUICK_PARTS else [pytest.mark.slow]) for k in range(RANDOM_PARTS)],
    ids=lambda k: f"part {k + 1}",
)  # the workers share them
@pytest.mark.parametrize("draw_speed_given", [True, False], ids=["draw speed given", "draw speed free"])
def test_random_presses_end_verified(draw_speed_given, part):
    """Every press ends verified or clean (the properties of :func:`outcome`), and most end verified: a
    planner that failed every case would fail here. On the first :data:`UPPER_BOUND_SET` verified presses
    of each part the certified upper bound (coarse grid, still an upper bound) is above the verified plan."""
    size = RANDOM_SET // RANDOM_PARTS
    presses = random_set(draw_speed_given)[part * size : (part + 1) * size]
    spms: list[float] = []
    outcomes = [outcome(data, spms) for data in presses]
    verified = outcomes.count("verified")
    assert verified >= VERIFIED_SHARE * len(outcomes), sorted(set(outcomes))
    checked = [(data, spm) for data, spm in zip(presses, spms, strict=True) if spm]
    for data, spm in checked[:UPPER_BOUND_SET]:
        assert upper_bound(case_from_data(data), 180, 1).spm >= spm, data["name"]
    assert len(checked) >= UPPER_BOUND_SET


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(UPPER_BOUND_LAWS_SET))
def test_no_law_and_no_bracket_motion_above_the_upper_bound(seed):
    """Issue 28 on 30 random presses (slow: about 10 s each): every law's verified plan (as ``pressplan
    laws`` solves them) and the bracket's verified motion (its first round) are at most the certified upper
    bound; the press must give at least one verified plan."""
    from planning.reports.law_comparison import compare_laws
    from planning.solver.bracket import bracket

    data = seeded_case(seed)
    try:
        case = case_from_data(data, data["name"])
    except CaseFileError:
        pytest.skip("bad input (exit 2)")
    table, _ = compare_laws(case)
    upper = table["upper_bound"]["spm"]
    plans = [row["spm"] for row in table["laws"] if row.get("spm")]
    assert plans and all(spm <= upper for spm in plans), (upper, plans)
    motion = bracket(case, math.inf)  # one round: the first verified motion and the first upper bound
    assert motion.verified.plan.spm <= motion.upper.spm


@pytest.mark.parametrize(
    "quarter",
    [pytest.param(k, id=f"quarter {k + 1}", marks=[] if k == 0 else [pytest.mark.slow]) for k in range(4)],
)
def test_random_offset_presses_end_verified(quarter):
    """Offset crank-sliders (the slide's line up to 12 % of the crank radius to either side) through the same
    properties: the offset formula in the NLPs, the verification and the asymmetric inverse height."""
    seeds = range(quarter * OFFSET_SET // 4, (quarter + 1) * OFFSET_SET // 4)
    outcomes = [outcome(seeded_offset_case(seed)) for seed in seeds]
    assert outcomes.count("verified") >= VERIFIED_SHARE * len(outcomes), sorted(set(outcomes))


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
    for name, write in solution_writers(sol, case, figures=False).items():
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


# Seeds of the relaxation test: the first ones of the seeded set, and presses where a relaxed limit once cost
# strokes cold (10, 15 and 45 ended in exit 3 with min_crank_speed_rpm 0.5; 27 lost 6 % with it and 0.6 %
# with a shorter transfer time: refining the sampled slider acceleration squeezed the draw, whose speed the
# test holds at the bound; 55 loses most to another local optimum, 8.6e-4)
RELAXATION_SEEDS = (0, 1, 2, 3, 4, 5, 10, 15, 27, 45, 55)


@pytest.mark.parametrize("seed", RELAXATION_SEEDS)
def test_relaxing_a_limit_never_costs_strokes(seed):
    """Each relaxation of a solved press, solved on its own (cold: no neighbour's plan to fall back on),
    makes at least as many strokes, to :data:`RELAXED_SPM_TOL`: the planner is a multi-start of a local
    method on a nonconvex problem, and two local optima of a press and its relaxation can differ by that
    much (a survey of seeds 0 ... 119 x 3 relaxations: 9 of 360 below, by 7e-8 ... 8.6e-4, 8 of them relaxing
    the minimum crank speed from 1 to 0.5 rpm)."""
    data = seeded_case(seed)
    try:
        base = solve(case_from_data(data))
    except (CaseFileError, PlanningError):
        pytest.skip("the press itself has no plan")
    for relax in ("slider_accel_mm_s2", "transfer_time_s", "min_crank_speed_rpm"):
        relaxed = json.loads(json.dumps(data))
        if relax == "slider_accel_mm_s2":
            relaxed["limits"]["slider_accel_mm_s2"] *= 1.1
        elif relax == "transfer_time_s":
            relaxed["process"]["transfer_time_s"] *= 0.9
        else:
            relaxed["limits"]["min_crank_speed_rpm"] = 0.5
        if "draw_speed_rpm" not in relaxed["process"]:  # keep the draw speed the first plan used
            relaxed["process"]["draw_speed_rpm"] = float(base.plan.parameters.draw_speed) * 60 / (2 * math.pi)
        better = solve(case_from_data(relaxed))  # raises PlanningError (a failed test) on exit 3
        assert better.plan.spm >= base.plan.spm * (1 - RELAXED_SPM_TOL), relax


@pytest.mark.slow  # 7-13 s: the normal run keeps under 5 minutes (its kind runs there too)
def test_a_neighbours_plan_that_holds_is_never_lost():
    """``solve(case, neighbour=plan)`` keeps a neighbouring case's plan that verifies here as a candidate
    (``planning.solver.max_spm.adopt``). On this corner of the random presses (every number at the end of
    its range) the cold solve of a 10 % higher slider-acceleration limit finds a poorer local optimum
    (8.74 against 8.98 strokes/min), and the NLP started from the neighbour's values ends there too: only
    keeping the neighbour's plan itself gives the answer."""
    data = build_case([0.0] * 14)
    base = solve(case_from_data(data))
    relaxed = json.loads(json.dumps(data))
    relaxed["limits"]["slider_accel_mm_s2"] *= 1.1
    warm = solve(case_from_data(relaxed), neighbour=base.plan)
    assert warm.plan.spm >= base.plan.spm


RELAXED_SPM_TOL = 1e-3  # relative: two local optima of a press and of its relaxation (see the test)

RELAXATIONS = {  # each makes the set of feasible motions larger (or keeps it)
    "slider_accel_mm_s2": ("limits", "slider_accel_mm_s2", 1.1),
    "transfer_time_s": ("process", "transfer_time_s", 0.9),
    "die_speed_mm_s": ("limits", "die_speed_mm_s", 1.2),
    "draw_start_speed_mm_s": ("limits", "draw_start_speed_mm_s", 1.2),
    "min_crank_speed_rpm": ("limits", "min_crank_speed_rpm", 0.5),
    "safety_height_mm": ("process", "safety_height_mm", 0.97),
}


@pytest.mark.slow  # hypothesis draws presses until six solve: 10 s
@settings(PROFILE, max_examples=RELAXATION_EXAMPLES)
@given(data=CASES, relax=st.sampled_from(sorted(RELAXATIONS)))
def test_relaxing_any_limit_never_turns_a_solved_case_into_exit_3(data, relax):
    """Solved alone (no neighbour plan to lean on), the looser case is never worse off than exit 3 (a press
    that has no plan itself says nothing: hypothesis draws another)."""
    try:
        solve(case_from_data(data))
    except (CaseFileError, PlanningError):
        assume(False)
    relaxed = json.loads(json.dumps(data))
    section, key, factor = RELAXATIONS[relax]
    relaxed[section][key] = relaxed[section].get(key, 1.0) * factor
    event(relax)
    solve(case_from_data(relaxed))  # raises PlanningError (a failed test) when the looser case gets exit 3


@pytest.mark.slow  # 12 presses under four laws: 7 s
@settings(PROFILE, max_examples=12)
@given(data=CASES, law=st.sampled_from(["seven-segment", "quintic", "logistic", "cycloidal"]))
def test_random_press_under_every_law_ends_verified_or_clean(data, law):
    data = json.loads(json.dumps(data))
    data.setdefault("planner", {})["motion_law"] = law
    event(f"{law}: {outcome(data)}")
