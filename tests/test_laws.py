"""The motion laws: closed forms of every shape, one half of every law against its dense evaluation,
continuity, splitting, and every law on every case (solved and verified)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planning.model.case_file import read_case
from planning.model.laws import LAWS, SHAPED_LAWS
from planning.model.laws.shapes import Cycloidal, Logistic, Quintic
from planning.model.outcome import Outcome
from planning.model.profile import Profile, max_abs_jerk, split_segment
from planning.solver.optimize import solve
from tests.conftest import solved

SHAPES = [Quintic(), Cycloidal(), Logistic(4.0), Logistic(5.0), Logistic(6.0), Logistic(2.0)]
U = np.linspace(0.0, 1.0, 200_001)
CASES = sorted((Path(__file__).resolve().parents[1] / "cases").glob("*.yaml"))


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: f"{s.name}{getattr(s, 'flexible', '')}")
def test_shape_boundary_values_and_symmetry(shape):
    s, S, s1, s2 = shape.terms(U)
    assert s[0] == pytest.approx(0, abs=1e-15) and s[-1] == pytest.approx(1, abs=1e-14)
    assert s1[0] == pytest.approx(0, abs=1e-14) and s1[-1] == pytest.approx(0, abs=1e-13)
    assert S[0] == pytest.approx(0, abs=1e-15) and S[-1] == pytest.approx(0.5, abs=1e-14)
    assert np.max(np.abs(s + s[::-1] - 1)) < 1e-13  # point symmetry about u = 1/2
    assert np.all(np.diff(s) >= -1e-15)  # monotone: the speed never overshoots its end value


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: f"{s.name}{getattr(s, 'flexible', '')}")
def test_shape_derivatives_are_consistent(shape):
    """S' = s, s' and s'' match central differences of s and s' (step 5e-6: error O(h^2) ~ 1e-9)."""
    s, S, s1, s2 = shape.terms(U)
    h = U[1] - U[0]
    assert np.max(np.abs((S[2:] - S[:-2]) / (2 * h) - s[1:-1])) < 1e-8
    assert np.max(np.abs((s[2:] - s[:-2]) / (2 * h) - s1[1:-1])) < 1e-7
    assert np.max(np.abs((s1[2:] - s1[:-2]) / (2 * h) - s2[1:-1])) < 1e-5 * max(1.0, np.max(np.abs(s2)))


@pytest.mark.parametrize("shape", SHAPES[:5], ids=lambda s: f"{s.name}{getattr(s, 'flexible', '')}")
def test_closed_form_peaks(shape):
    """The stated peaks of s' and |s''| equal the maxima on a 200 001-point grid."""
    _, _, s1, s2 = shape.terms(U)
    assert float(shape.peak_rate()) == pytest.approx(np.max(s1), rel=1e-9)
    assert float(shape.peak_jerk()) == pytest.approx(np.max(np.abs(s2)), rel=1e-8)


def test_known_closed_forms():
    assert Quintic().peak_rate() == 15 / 8 and Quintic().peak_jerk() == pytest.approx(5.773502691896258)
    assert Cycloidal().peak_rate() == 2 and Cycloidal().peak_jerk() == pytest.approx(2 * math.pi)
    assert LAWS["improved-s-curve"].peak_rate() == pytest.approx(18 / 11)  # 3/2 J T, J = dv / (11/3 T^2), T = D/4
    assert LAWS["seven-segment"].peak_rate(1.0) == 2.0  # no plateau: triangular acceleration


@pytest.mark.parametrize("shape", SHAPES[:5], ids=lambda s: f"{s.name}{getattr(s, 'flexible', '')}")
def test_shapes_agree_in_numpy_and_casadi(shape):
    u = ca.SX.sym("u")
    f = ca.Function("f", [u], list(shape.terms(u)))
    for x in (0.0, 0.13, 0.5, 0.91):
        sym = [float(v) for v in f(x)]
        num = [float(v) for v in shape.terms(np.array(x))]
        assert sym == pytest.approx(num, rel=1e-13, abs=1e-14)


def half_profile(law: str, v0: float, dv: float, D: float, param: float | None) -> Profile:
    return Profile(tuple(LAWS[law].half("half", D, dv, param)), 0.0, v0)


LAW_PARAMS = [
    (law, p)
    for law in SHAPED_LAWS
    for p in ([0.2, 0.6, 1.0] if law == "seven-segment" else [4.0, 6.0] if law == "logistic" else [None])
]


@pytest.mark.parametrize("law,param", LAW_PARAMS, ids=lambda x: str(x))
def test_one_half_of_every_law(law, param):
    """Speed change, angle D (v0 + dv/2), zero acceleration at both ends, and the closed-form peak
    acceleration and jerk of the law, against the dense evaluation of its segments."""
    v0, dv, D = 1.3, 2.1, 0.37
    prof = half_profile(law, v0, dv, D, param)
    t = np.linspace(0, prof.duration, 100_001)
    th, om, al, je = prof.at_time(t)
    assert prof.duration == pytest.approx(D, rel=1e-15)
    assert om[-1] == pytest.approx(v0 + dv, rel=1e-13)
    assert th[-1] == pytest.approx(D * (v0 + dv / 2), rel=1e-13)
    assert al[0] == pytest.approx(0, abs=1e-12) and al[-1] == pytest.approx(0, abs=1e-11)
    rate = float(LAWS[law].peak_rate(param)) * dv / D
    assert np.max(np.abs(al)) == pytest.approx(rate, rel=1e-6)
    jerk = float(LAWS[law].peak_jerk(param)) * dv / D**2
    assert max_abs_jerk(prof) == pytest.approx(jerk, rel=1e-12)
    assert np.max(np.abs(je)) == pytest.approx(jerk, rel=1e-3)  # the grid may miss the exact peak


@pytest.mark.parametrize("law", list(SHAPED_LAWS))
def test_stated_continuity(law):
    """A jerk-continuous law starts and ends its halves at zero jerk (it joins constant speed and the
    opposite half smoothly); an acceleration-continuous one has a jerk step somewhere."""
    param = LAWS[law].parameter.start if LAWS[law].parameter else None
    prof = half_profile(law, 1.0, 2.0, 0.4, param)
    t = prof.knot_times
    _, _, _, je = prof.at_time(np.concatenate([t[:-1], [t[-1] - 1e-12]]))
    inner = prof.at_time(t[1:-1] - 1e-12)[3] if t.size > 2 else np.array([])
    steps = np.concatenate([np.abs(je[[0, -1]]), np.abs(je[1:-1] - inner)])
    if LAWS[law].continuity == "jerk":
        assert np.max(steps) < 1e-6
    else:
        assert LAWS[law].continuity == "acceleration" and np.max(steps) > 1e-3


@settings(max_examples=40, deadline=None)
@given(
    law=st.sampled_from(["quintic", "cycloidal", "logistic", "seven-segment", "improved-s-curve"]),
    cut=st.floats(0.01, 0.99),
)
def test_splitting_a_half_keeps_its_motion(law, cut):
    """A half cut in two (as at TDC) moves exactly as the whole."""
    param = LAWS[law].parameter.start if LAWS[law].parameter else None
    whole = half_profile(law, 0.8, 1.7, 0.5, param)
    segs = []
    for seg in whole.segments:
        tau = cut * float(seg.duration)
        segs += list(split_segment(seg, tau))
    pieces = Profile(tuple(segs), 0.0, 0.8)
    t = np.linspace(0, whole.duration, 2001)
    for a, b in zip(whole.at_time(t)[:3], pieces.at_time(t)[:3], strict=True):
        assert np.max(np.abs(a - b)) < 1e-11


# a draw at constant slide speed is the optimal law's alone (tests/test_slide_draw.py)
SLOW_LAWS = ("side-panel-servo", "link-drive", "knuckle-joint")  # 1.5-3 s a law
WITH_HALVES = [  # the robots' case, the servo-limited side panel and the linkages in the slow tier
    pytest.param(p, marks=pytest.mark.slow) if read_case(p).robots is not None or p.stem.startswith(SLOW_LAWS) else p
    for p in CASES
    if not read_case(p).free_draw
]


@pytest.mark.parametrize("law", [law for law in SHAPED_LAWS if law != "improved-s-curve"])
@pytest.mark.parametrize("path", WITH_HALVES, ids=lambda p: getattr(p, "stem", None))
def test_every_law_solves_every_case(path, law):
    """Every law with halves gives a verified plan on every case under both placements, free never worse
    (the improved S-curve: tests/test_cases.py; the optimal law: tests/test_optimal.py)."""
    published, sol = solved(path, "published", law), solved(path, "free", law)
    assert published.plan.motion_law == law and sol.plan.motion_law == law
    assert sol.plan.spm >= published.plan.spm - 1e-9
    assert sol.plan.profile.segments[0].name.split(":")[0] in ("transfer", "return", "feed")


def test_laws_command_and_the_readme_table(tmp_path, capsys):
    """`pressplan laws` on the published case: a verified row per law, all below the bound, the files
    written; the table in docs/results.md is this command's laws.md (numbers within their printed digits)."""
    from planning.cli import main

    from .conftest import PUBLISHED_CASE, ROOT

    assert main(["laws", str(PUBLISHED_CASE), "--out", str(tmp_path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {p.name for p in tmp_path.iterdir()} == {"laws.json", "laws.md", "laws_overlay.png"}
    rows = {r["law"]: r for r in data["laws"]}
    assert set(rows) == set(LAWS) and all(r["status"] == Outcome.VERIFIED for r in rows.values())
    assert all(r["spm"] <= data["upper_bound"]["spm"] for r in rows.values())  # certified: no motion above
    assert all(0 < r["share_of_upper_bound_pct"] <= 100.0 for r in rows.values())
    best = max(rows.values(), key=lambda r: r["spm"])
    assert data["bracket"]["verified_spm"] == best["spm"] and data["bracket"]["gap_pct"] >= 0
    readme = (ROOT / "docs" / "results.md").read_text(encoding="utf-8")
    block = readme.split("<!-- laws:begin -->")[1].split("<!-- laws:end -->")[0]
    printed = {cells[0]: cells for cells in _table_rows(block)}
    fresh = {cells[0]: cells for cells in _table_rows((tmp_path / "laws.md").read_text(encoding="utf-8"))}
    assert printed.keys() == fresh.keys() and len(printed) == len(LAWS) + 2  # the grid and the upper bound
    for name, cells in fresh.items():
        for a, b in zip(cells[1:], printed[name][1:], strict=True):
            if a.replace(".", "").isdigit():
                unit = 10.0 ** -len(a.split(".")[1]) if "." in a else 1.0
                assert abs(float(a) - float(b)) <= unit * (1 + 1e-9), (name, a, b)  # the last digit may differ by 1
            else:
                assert a == b


def _table_rows(markdown: str) -> list[list[str]]:
    rows = [line.strip().strip("|").split("|") for line in markdown.splitlines() if line.startswith("|")]
    return [[c.strip() for c in r] for r in rows[2:]]


@pytest.mark.parametrize("law", ["quintic", "cycloidal"])
def test_jerk_continuous_laws_give_jerk_continuous_plans(case, law):
    """Across every knot of a solved cycle the crank jerk of a jerk-continuous law does not step (it
    changes by at most 2e-9 s times its rate, far below 1e-5 rad/s^3)."""
    prof = solve(case.with_law(law)).plan.profile
    t = prof.knot_times[1:-1]
    jump = prof.at_time(t + 1e-9)[3] - prof.at_time(t - 1e-9)[3]
    assert np.max(np.abs(jump)) < 1e-5
    steps = solve(case).plan.profile  # the improved S-curve's jerk does step: the check can fail
    t = steps.knot_times[1:-1]
    assert np.max(np.abs(steps.at_time(t + 1e-9)[3] - steps.at_time(t - 1e-9)[3])) > 1.0


def test_solve_and_sweep_take_a_law(tmp_path, capsys):
    from planning.cli import main

    from .conftest import PUBLISHED_CASE

    assert main(["solve", str(PUBLISHED_CASE), "--law", "quintic", "--no-plots", "--out", str(tmp_path / "s")]) == 0
    result = json.loads((tmp_path / "s" / "result.json").read_text())
    assert result["motion_law"] == "quintic" and result["verified"] and result["paper_solution"] is None
    assert "C3" in (tmp_path / "s" / "cam_table.csv").read_text().splitlines()[5]
    args = ["sweep", str(PUBLISHED_CASE), "--law", "seven-segment", "--vary", "process.transfer_time_s=1.8:2.2:3"]
    assert main([*args, "--workers", "1", "--out", str(tmp_path / "w")]) == 0
    rows = (tmp_path / "w" / "sweep.csv").read_text().splitlines()
    assert len(rows) == 4 and all(",verified," in r for r in rows[1:])
    spm_at_2s = float(rows[2].split(",")[2])  # transfer time 2.0 s: the case itself, under seven-segment
    assert spm_at_2s == pytest.approx(solve(read_case(PUBLISHED_CASE).with_law("seven-segment")).plan.spm, abs=1e-6)
    capsys.readouterr()


def test_laws_go_on_when_the_bound_has_no_answer(monkeypatch, tmp_path, capsys):
    """The bound is a yardstick: when it has no answer the laws are still compared and written."""
    import planning.reports.law_comparison as comparison
    from planning.cli import main
    from planning.solver.outcomes import NoPlanFound

    from .conftest import PUBLISHED_CASE

    def no_bound(case, points=1440, pieces=2):
        raise NoPlanFound("the time-optimal bound did not converge (Maximum_Iterations_Exceeded)")

    monkeypatch.setattr(comparison, "time_optimal_bound", no_bound)
    monkeypatch.setattr(comparison, "upper_bound", no_bound)
    out = tmp_path / "laws"
    assert main(["laws", str(PUBLISHED_CASE), "--out", str(out), "--json"]) == 0
    data = json.loads((out / "laws.json").read_text())
    assert data["bound"] is None and "did not converge" in data["bound_failure"]
    assert all(r["status"] == Outcome.VERIFIED and r["share_of_bound_pct"] is None for r in data["laws"])
    assert data["upper_bound"] is None and data["bracket"] is None
    assert all(r["share_of_upper_bound_pct"] is None for r in data["laws"])
    text = (out / "laws.md").read_text()
    assert "| – |" in text and "time-optimal bound (grid)" not in text and "certified upper bound" not in text
