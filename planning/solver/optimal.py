"""The optimal law: the fastest jerk-limited cycle, planned as a free profile (``planning.solver.free_nlp``).

Initial guess: a seven-segment plan of the case under the same jerk limit (the first start of its NLP
that converges, neither verified nor confirmed as the optimum: a start needs no more), sampled on the
phases' grids (the bound's profile has no jerk limit and is a poorer start); a neighbouring case's
optimal plan (a sweep, a looser limit) starts first and, when it holds here, is a candidate answer. The
minimum crank speed is held :data:`MIN_SPEED_BACKOFF` above its limit at the samples. The plans are
verified densely like every other.
"""

from __future__ import annotations

import numpy as np

from planning.model.case import Case
from planning.model.free_profile import PHASES
from planning.model.laws.optimal import OptimalLaw
from planning.model.plan import Plan
from planning.solver.free_nlp import free_nlp_for
from planning.solver.max_spm import converged_plan, solve_max_spm
from planning.solver.outcomes import Infeasible
from planning.solver.search import Search, prepare
from planning.solver.solution import Solution
from planning.solver.verify import assess

SEED_LAW = "seven-segment"  # a jerk-limited law whose plan starts the NLP
# relative: the sampled minimum crank speed is held this much above the limit (the speed is cubic between
# the samples and may dip below them; the slowest point, near TDC, is usually at the limit)
MIN_SPEED_BACKOFF = 1e-2


def seed_values(seed: Plan) -> dict[str, float]:
    """A plan of another law as the optimal NLP's values: its profile sampled on each phase's uniform
    grid between the key points, the jerk of each segment from the change of acceleration across it."""
    prof, period = seed.profile, seed.period
    t1, t2, t3, t4 = (float(t) for t in seed.key_times())
    spans = {"return": (t3, t4), "transfer": (t4, t1 + period), "feed": (t1 + period, t2 + period)}
    values = {"draw_speed": float(seed.parameters.draw_speed), "die_up_time": seed.nlp_values["die_up_time"]}
    values["die_down_time"] = max(seed.nlp_values["die_down_time"] - seed.nlp_values["closing_time"], 0.0)
    for phase, n in PHASES:
        a, b = spans[phase]
        h = (b - a) / n
        t = a + h * np.arange(n + 1)
        wrapped = t >= period
        th, om, al, _ = prof.at_time(np.where(wrapped, t - period, t))
        th = th + np.where(wrapped | (phase == "feed"), 2 * np.pi, 0.0)
        values[f"{phase}_step"] = h
        for k in range(n):
            values[f"{phase}_jerk_{k}"] = float((al[k + 1] - al[k]) / h)
        for k in range(1, n + 1):
            values |= {f"{phase}_angle_{k}": float(th[k]), f"{phase}_speed_{k}": float(om[k])}
            values[f"{phase}_accel_{k}"] = float(al[k])
    return values


def from_neighbour_optimal(case: Case, neighbour: Plan) -> Solution | None:
    """The answer from ``neighbour`` alone (its plan when it holds here, one start from its values), or
    None: fast, not confirmed (``planning.solver.optimize.solve``)."""
    _require_jerk_limit(case)
    search = _search(case)
    return search.answer() if _from(search, neighbour) else None


def _search(case: Case) -> Search:
    """The optimal law's search: prechecks, parameters, bounds, scales; the minimum crank speed backed off."""
    search = prepare(case, "free", free_nlp_for(case))
    search.parameters = search.parameters.copy()
    search.parameters[search.parameter("min_crank_speed")] *= 1 + MIN_SPEED_BACKOFF
    return search


def _from(search: Search, neighbour: Plan) -> bool:
    """A neighbouring case's optimal plan: a candidate when it holds here, and a start; whether either
    verified."""
    case = search.case
    if neighbour.motion_law != OptimalLaw.name or not neighbour.nlp_values:
        return False
    if np.allclose(neighbour.key_angles, case.key_angles, rtol=0, atol=1e-12):
        verification, drive = assess(neighbour, case)  # a neighbouring case's plan that holds here is an answer
        if verification.passed:
            search.consider(Solution(neighbour, verification, drive), neighbour.period)
    search.attempt(neighbour.nlp_values, "free")
    return search.best is not None


def _require_jerk_limit(case: Case) -> None:
    if case.limits.crank_jerk_rad_s3 is None:
        raise Infeasible(
            "the optimal law needs limits.crank_jerk_rad_s3 (the jerk it may use)", limit="limits.crank_jerk_rad_s3"
        )


def solve_optimal(case: Case, neighbour: Plan | None = None) -> Solution:
    """The fastest verified cycle of ``case`` under the optimal law (needs ``limits.crank_jerk_rad_s3``).

    ``neighbour``: an optimal plan of a neighbouring case (a sweep, an edit on the web page, a looser
    limit). When it holds here it is a candidate; its values start the NLP, and when that start verifies
    the seed law is not solved at all (a warm re-solve)."""
    _require_jerk_limit(case)
    search = _search(case)
    if neighbour is not None and _from(search, neighbour):
        return search.answer()
    seeded = case.with_law(SEED_LAW)
    seed = converged_plan(seeded) or solve_max_spm(seeded, "free").plan
    search.iterations += seed.solver.iterations
    search.starts += seed.solver.starts
    search.multi_start([seed_values(seed)], "free", confirm=False)
    return search.answer()
