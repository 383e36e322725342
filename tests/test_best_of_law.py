"""The best plan of its law, every time (issue 37): a cold solve is at least what a sweep's neighbours find.

On random presses of every mechanism (crank-slider, offset crank-slider, link drive, knuckle joint), a
five-point transfer-time sweep around the press, walked from one end to the other and back, each point solved
from the plan before it (``solve(case, neighbour=...)``: the neighbour's plan and a start from it compete with
the cold solve): at no point does that path end more than :data:`SAME` above the point's own cold solve. The
normal run takes one press of each kind (:data:`QUICK`); the slow tier seven more of each (the gap one of them
had, 1.5e-4, closed by refining the slide acceleration's sampled limit segment by segment). The link-drive
case of the outside trial (``tests/data/cases/link2500.yaml``) solves cold to the plan its sweep found, and at
a fixed draw speed."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from planning.model.case_file import CaseFileError, case_from_data, read_case
from planning.solver.optimize import solve
from planning.solver.outcomes import PlanningError

from .random_cases import build_case, seeded_linkage_case

ROOT = Path(__file__).resolve().parents[1]
LINK2500 = ROOT / "tests" / "data" / "cases" / "link2500.yaml"
SAME = 1e-6  # relative: the neighbour's path at most this far above the cold solve
SWEEP = (-0.25, -0.125, 0.0, 0.125, 0.25)  # the transfer times, relative to the press's own
KINDS = ("crank-slider", "offset", "link-drive", "knuckle-joint")
SEEDS = range(8)
# the normal run's press of each kind: one whose sweep takes seconds (the link drives of seeds 0, 2, 4 and 7
# take 20-30 s, in the slow tier)
QUICK = {"crank-slider": 0, "offset": 0, "link-drive": 1, "knuckle-joint": 0}


def press(kind: str, seed: int) -> dict:
    """A random press of ``kind`` (``tests/random_cases.py``)."""
    if kind in ("crank-slider", "offset"):
        u = np.random.default_rng(1000 + seed).random(15)
        offset = round(0.24 * u[14] - 0.12, 3) if kind == "offset" else 0.0
        return build_case(list(u[:14]), name=f"{kind}-{seed}", offset_share=offset)
    return seeded_linkage_case(seed, kind)


def _points(data: dict) -> list:
    """The sweep's cases (None where a transfer time makes the case invalid)."""
    out = []
    for share in SWEEP:
        point = json.loads(json.dumps(data))
        point["process"]["transfer_time_s"] = round(data["process"]["transfer_time_s"] * (1 + share), 4)
        try:
            out.append(case_from_data(point))
        except CaseFileError:
            out.append(None)
    return out


def _spm(case, neighbour=None):  # noqa: ANN001, ANN202 - a Case and a Plan; a Solution or None
    try:
        solution = solve(case, neighbour=neighbour)
    except PlanningError:
        return None
    return solution


def _the_cold_solve_is_the_sweeps_best(kind: str, seed: int) -> None:
    try:
        points = _points(press(kind, seed))
    except CaseFileError:
        pytest.skip("the random press is no press (bad input)")
    cold = [None if case is None else _spm(case) for case in points]
    for order in (range(len(points)), range(len(points) - 1, -1, -1)):
        before = None
        for i in order:
            if points[i] is None:
                continue
            walked = _spm(points[i], before.plan if before is not None else None)
            if walked is None:
                continue
            before = walked
            assert cold[i] is not None, f"point {i}: the sweep found a plan, the cold solve none"
            assert walked.plan.spm <= cold[i].plan.spm * (1 + SAME), (i, walked.plan.spm, cold[i].plan.spm)


@pytest.mark.parametrize(  # the crank-slider's in the fast tier, the linkages' and the offset's (4-5 s) in the slow
    ("kind", "seed"),
    [(k, s) if k == "crank-slider" else pytest.param(k, s, marks=pytest.mark.slow) for k, s in QUICK.items()],
)
def test_a_cold_solve_is_what_a_sweep_finds(kind, seed):
    _the_cold_solve_is_the_sweeps_best(kind, seed)


@pytest.mark.slow
@pytest.mark.parametrize(("kind", "seed"), [(k, s) for k in KINDS for s in SEEDS if QUICK[k] != s])
def test_a_cold_solve_is_what_a_sweep_finds_on_more_presses(kind, seed):
    _the_cold_solve_is_the_sweeps_best(kind, seed)


def test_the_outside_trials_link_drive_solves_cold_to_its_sweeps_plan():
    """The trial's link drive: its sweep found 13.627 strokes/min at 1.5 s (the draw at 14.27 rpm, the return
    ending before the die exit's crossing, the robot's window in the dwell); a cold solve gave 12.640. And a
    draw speed fixed at 14.2 rpm, at which a verified plan exists, solves."""
    free = solve(read_case(LINK2500))
    assert free.plan.spm >= 13.626
    fixed = solve(read_case(LINK2500, {"process.draw_speed_rpm": 14.2}))
    assert fixed.plan.parameters.draw_speed == pytest.approx(14.2 * 2 * np.pi / 60, rel=1e-12)
    assert fixed.plan.spm >= 13.6


@pytest.mark.slow  # 7-13 s: the normal run keeps under 5 minutes (its kind runs there too)
def test_a_crank_jerk_limit_near_zero_still_plans_under_the_improved_s_curve():
    """At 0.01 rad/s^3 the improved S-curve's NLP cannot move; the crank at constant speed (zero jerk, a motion
    of every law with halves) is its plan: 6.700 strokes/min at the draw speed."""
    case = read_case(ROOT / "cases" / "wang2023-side-panel.yaml", {"limits.crank_jerk_rad_s3": 0.01})
    solution = solve(case)
    assert solution.plan.motion_law == "improved-s-curve"
    assert solution.plan.spm == pytest.approx(6.7, rel=1e-9)
    assert solution.verification.check("crank_jerk").value <= 0.01
