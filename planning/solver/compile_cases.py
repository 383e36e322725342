"""``pressplan compile``: the NLPs a case takes, compiled into the cache (``planning.solver.compiled``).

The case is solved (its NLPs built, as any solve builds them), every SX problem built in the process compiles its
derivative functions (``planning.solver.ipopt.NLPSolver.compile``) and the case is solved again with them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from planning.model.case import Case
from planning.solver.compiled import cache_dir
from planning.solver.ipopt import kept_solvers
from planning.solver.optimize import solve
from planning.solver.outcomes import PlanningError
from planning.solver.pendulum_rate import solve_swings


@dataclass(frozen=True)
class CompileReport:
    """What :func:`compile_nlps` did: ``compiled`` problems compiled now, ``present`` ones found compiled in the
    cache, ``interpreted`` ones left so (no compiler, no cache, or the compiler failed; said), the compiler's
    ``seconds``, the case's solve before and after [s] (``solve_s``, ``compiled_solve_s``) and the cache folder."""

    compiled: int
    present: int
    interpreted: int
    seconds: float
    solve_s: float
    compiled_solve_s: float
    folder: Path | None


def compile_nlps(case: Case) -> CompileReport:
    """Solve ``case`` (building the NLPs it takes; a case without a plan builds them too), compile their
    derivative functions into the cache (``planning.solver.compiled``) and solve it again with them."""
    planner = solve_swings if case.pendulum else solve

    def timed() -> float:
        t_start = time.perf_counter()
        try:
            planner(case)
        except PlanningError:
            pass  # its NLPs were built all the same
        return time.perf_counter() - t_start

    with kept_solvers() as solvers:
        before = timed()
        results = [solver.compile() for solver in solvers]
    done = [s for s in results if s is not None]
    after = timed()
    return CompileReport(
        compiled=sum(1 for s in done if s > 0),
        present=sum(1 for s in done if s == 0),
        interpreted=sum(1 for s in results if s is None),
        seconds=sum(done),
        solve_s=before,
        compiled_solve_s=after,
        folder=cache_dir(),
    )
