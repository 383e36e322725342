"""The search over starts of one compiled NLP, shared by every solve: :class:`Search` and :func:`prepare`.

A search holds one case, its compiled NLP (``planning.solver.nlp``; either transcription), the case's
parameters and the variables' bounds and scales, and the best verified plan so far. Each start
(:meth:`Search.attempt`) is solved, made a plan, verified densely (``planning.solver.verify``); where only
limits the NLP holds at samples fail between them, their sampled limits are tightened by the measured
overshoot (the slide's acceleration segment by segment: :meth:`Search._shares`) and the start re-solved
warm; where an NLP row that can overstate its figure is active while the exact figure leaves room, that row
is loosened once by the room. A start whose first optimum (before any refinement) an earlier start of the same
problem reached takes that start's refined plan (:class:`Optimum`): the refinements from one optimum repeat
themselves; the searches of one solve may share them (a neighbour's start and the cold solve's starts). Starts
run until two agree on the optimum (:meth:`Search.multi_start`; with ``confirm`` False until one verifies); on two
cores the next start's first solve is made ahead in a forked worker meanwhile (:class:`StartsAhead`: the same
call, the same result to the last bit).
Without a verified plan the answer is a typed outcome (``planning.solver.outcomes``). The max-SPM solve of
the laws (``planning.solver.max_spm``), the optimal law (``planning.solver.optimal``) and the objectives at a
rate (``planning.solver.objectives``) all run on it.
"""

from __future__ import annotations

import itertools
import math
import time
import weakref
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from planning.model.case import Case, Placement
from planning.model.limits import BY_ID
from planning.model.limits.base import Check, Dense
from planning.model.plan import Plan, SolverInfo
from planning.solver.ahead import Ahead, Call, core_free
from planning.solver.halves_nlp import halves_nlp_for
from planning.solver.ipopt import NLPResult, NLPStatus
from planning.solver.nlp import CycleNLP
from planning.solver.outcomes import Attempt, NoPlanFound, Unverified
from planning.solver.parameters import share_name
from planning.solver.precheck import precheck
from planning.solver.solution import Solution
from planning.solver.verify import Verification, evaluate, field_of_check, schedule_matters, with_least_energy
from planning.tolerances import (
    AGREE_S,
    BINDING_SHARE,
    LIMIT_REL_TOL,
    REFINE_MARGIN,
    ROW_ACTIVE,
    SAME_ANGLE_RAD,
    SAME_SCORE,
    SAME_START_REL,
)

REFINEMENTS = 8  # re-solves with a lowered sampled limit


@dataclass
class Search:
    """The state of one solve: the ``case`` and its compiled ``nlp``, the case's ``parameters`` (the NLP's
    layout), the variable bounds ``lbx``/``ubx`` and ``scale``, the draw speed's range [rad/s], the best
    verified solution so far (``best``, ``best_score``), how the starts ended (``attempts``) and the totals
    the answer reports. ``fixed_period``: the cycle time held at the parameter ``target_period`` (a target
    rate); ``score``: what "better" means, lower is better (None: the period); ``stop_on``: check ids of
    which a failure ends the search (``stopped``)."""

    case: Case
    placement: Placement
    nlp: CycleNLP
    parameters: np.ndarray
    lbx: np.ndarray
    ubx: np.ndarray
    scale: np.ndarray
    draw_speed_range: tuple[float, float]
    t_start: float
    best: Solution | None = None
    attempts: list[Attempt] = field(default_factory=list)
    iterations: int = 0
    starts: int = 0
    fixed_period: bool = False
    score: Callable[[Solution], float] | None = None
    best_score: float = math.inf
    stop_on: frozenset[str] = frozenset()
    stopped: bool = False
    optima: list[Optimum] = field(default_factory=list)  # the attempts' first optima (shared by one solve's searches)
    ahead: StartsAhead | None = None  # during a multi-start: the next start's first solve, made in a worker

    def parameter(self, name: str) -> int:
        """The position of the NLP parameter ``name`` in :attr:`parameters`."""
        return self.nlp.layout.index(name)

    def score_of(self, solution: Solution) -> float:
        """The solution's score: :attr:`score`, or its period [s]."""
        return solution.plan.period if self.score is None else self.score(solution)

    def plan_of(self, values: dict[str, float], placement: Placement, status: str) -> Plan:
        """The plan of the NLP's variable ``values`` (the transcription's own ``make_plan``)."""
        info = SolverInfo(self.iterations, time.perf_counter() - self.t_start, self.starts, status)
        return self.nlp.make_plan(self.case, values, placement, info)

    def attempt(self, x0: dict[str, float], placement: Placement) -> tuple[dict[str, float], float] | None:
        """Solve from ``x0``; refine sampled limits and loosen overstated rows as the module docstring says
        (at most :data:`REFINEMENTS` re-solves, warm). Returns the best verified values and score, or None."""
        q = self.parameters.copy()
        values = x0
        multipliers = None
        found: tuple[dict[str, float], float] | None = None
        kept: Solution | None = None  # the plan of found
        loosened = False
        self.starts += 1
        first: tuple[tuple, np.ndarray] | None = None
        for _ in range(REFINEMENTS + 2):
            res = self._solve(values, q, placement, multipliers)
            self.iterations += res.iterations
            if self.fixed_period and res.status == NLPStatus.STOPPED_AT_LIMIT:
                # at a target rate the optimum may sit where a half of the law degenerates (a monotone speed
                # change: peak = end speed); IPOPT then crawls, and a fresh start from its last iterate ends it
                res = self.nlp.solve(self.nlp.values_of(res), q, self.lbx, self.ubx, placement, self.scale, None, True)
                self.iterations += res.iterations
            if not res.success and multipliers is not None:
                # a warm re-solve (a refined limit) that failed: once more without the old multipliers, from
                # the same values (IPOPT's warm start can misjudge a slightly tighter problem as infeasible)
                res = self.nlp.solve(values, q, self.lbx, self.ubx, placement, self.scale, None, self.fixed_period)
                self.iterations += res.iterations
            values, multipliers = self.nlp.values_of(res), res.multipliers
            if not res.success:
                block, amount = self.nlp.worst_block(placement, res.g, self.fixed_period)
                self.attempts.append(Attempt(res.return_status, block.name, amount, case_field=block.field))
                return self._remember(first, found, kept)
            if first is None:  # the attempt's first optimum: one an earlier attempt reached refines the same way
                first = (self._problem_key(q, placement), res.x)
                if (known := self._known(*first)) is not None:
                    return known
            plan = self.plan_of(values, placement, res.return_status)
            evaluation = evaluate(plan, self.case, least_energy=False)  # the answer's in full
            verification = evaluation.verification
            if verification.passed:
                solution = Solution(plan, evaluation)
                score = self.score_of(solution)
                self.consider(solution, score)
                if found is None or score < found[1]:
                    found, kept = (values, score), solution
                room = None if loosened else self._room(res, verification)
                if room is None:
                    return self._remember(first, found, kept)
                index, factor = room
                q[index] *= factor * (1 - REFINE_MARGIN)
                loosened = True
                continue
            bad = verification.failures()
            self.attempts.append(Attempt(check=bad[0], case_field=field_of_check(bad[0].id)))
            if any(c.id in self.stop_on for c in bad):
                self.stopped = True
                return self._remember(first, found, kept)
            if any(c.id not in self.nlp.refinable for c in bad):
                q = self._densify(bad, q)
                if q is None:
                    return self._remember(first, found, kept)
                multipliers = None  # the denser NLP from the same values, its sampled limits as they were
                continue
            for c in bad:  # tighten the NLP's sampled limit by the measured overshoot
                refine = self.nlp.refinable[c.id]
                if c.refine_by is not None:  # the limit says which parameter and where it goes (the grid's)
                    name, factor, ceiling = c.refine_by
                    k = self.parameter(name)
                    q[k] = min(q[k], ceiling) * factor * (1 - REFINE_MARGIN)
                elif shares := self._shares(c, plan, evaluation.samples):  # where it failed, by segment
                    for index, factor in shares.items():
                        q[index] *= factor * (1 - REFINE_MARGIN)
                elif refine.upward:  # a lower limit (the optimal law's minimum crank speed) goes up
                    q[refine.index] *= (c.limit / max(c.value, 0.5 * c.limit)) * (1 + REFINE_MARGIN)
                else:
                    q[refine.index] *= (c.limit / c.value) * (1 - REFINE_MARGIN)
        return self._remember(first, found, kept)

    def _solve(
        self, values: dict[str, float], q: np.ndarray, placement: Placement, multipliers: tuple | None
    ) -> NLPResult:
        """One IPOPT solve from ``values`` (``multipliers``: a warm re-solve's), taken from the solves made ahead
        where one is this very call (:class:`StartsAhead`)."""
        args = (values, q, self.lbx, self.ubx, placement, self.scale, multipliers, self.fixed_period)
        made = self.ahead.take(self.nlp, args) if self.ahead is not None and multipliers is None else None
        return made if made is not None else self.nlp.solve(*args)

    def _problem_key(self, q: np.ndarray, placement: Placement) -> tuple:
        """What makes one NLP problem and its search: the compiled NLP (the object: compared by identity), its
        parameters ``q``, bounds and scales, the placement, whether the period is held, the checks that stop the
        search and the score (two attempts with the same key and first optimum refine alike)."""
        arrays = (q, self.lbx, self.ubx, self.scale)
        settings = (placement, self.fixed_period, self.stop_on, self.score)
        return (self.nlp, *settings, *(np.asarray(a, dtype=float).tobytes() for a in arrays))

    def _known(self, key: tuple, x: np.ndarray) -> tuple[dict[str, float], float] | None:
        """What an earlier attempt found (verified values and score) from the same first optimum ``x`` of the
        same problem (``key``), its plan now a candidate of this search too; None where none did. From one
        optimum the refinements are the same re-solves: they would find the same plan again."""
        for other in self.optima:
            if _same_key(other.key, key) and _same_start(x, other.x):
                self.consider(other.solution, other.found[1])
                return other.found
        return None

    def _remember(
        self,
        first: tuple[tuple, np.ndarray] | None,
        found: tuple[dict[str, float], float] | None,
        kept: Solution | None,
    ) -> tuple[dict[str, float], float] | None:
        """Keep the attempt's first optimum with what it ``found`` and that verified plan ``kept`` (an attempt
        that found none, or that stopped the search, is not kept: it runs again); returns ``found``."""
        if first is not None and found is not None and kept is not None and not self.stopped:
            self.optima.append(Optimum(*first, found, kept))
        return found

    def _shares(self, check: Check, plan: Plan, dense: Dense) -> dict[int, float]:
        """``{parameter index: factor}``: the shares of ``check``'s limit (``planning.solver.parameters.
        share_name``) to lower, each by the factor that brings its segment's highest value in ``dense`` to the
        limit, for every segment of ``plan`` where the limit fails and the segment after it (whose first sample
        closes the segment's last interval); empty where the limit has no shares here."""
        limit = BY_ID.get(check.id)
        segments = self.nlp.layout.shared_segments
        if not getattr(limit, "shared", False) or not segments:
            return {}
        values = limit.dense_values(dense)
        where = plan.segment_indices(dense.t)
        factors: dict[int, float] = {}
        for k in np.unique(where[values > check.limit * (1 + LIMIT_REL_TOL)]):  # the segments that fail
            name = plan.profile.segments[k].name
            if name not in segments:
                continue
            factor = check.limit / float(np.max(values[where == k]))
            i = segments.index(name)
            for s in segments[i : i + 2]:
                index = self.parameter(share_name(s))
                factors[index] = min(factors.get(index, 1.0), factor)
        return factors

    def _densify(self, bad: list, q: np.ndarray) -> np.ndarray | None:
        """Turn to the NLP's denser variant (``CycleNLP.denser``) when it holds every failed check at its
        samples; the search keeps it from here on (its parameters, bounds and scales; the parameters the
        search has set carried over by name). The attempt's parameters ``q`` for it, or None where it did not."""
        if self.nlp.denser is None:
            return None
        denser = self.nlp.denser()
        if any(c.id not in denser.refinable for c in bad):
            return None
        old = self.nlp.layout
        fresh = denser.layout.values(self.case)
        carried = [(denser.layout.index(name), i) for i, name in enumerate(old.names) if name in denser.layout.names]
        to, frm = (np.array(ix, dtype=int) for ix in zip(*carried, strict=True))
        fresh[to] = self.parameters[frm]
        local = fresh.copy()
        local[to] = q[frm]
        if old.drive:  # the forming force at the draw's samples, last in both
            fresh[denser.layout.forming], local[denser.layout.forming] = q[old.forming], q[old.forming]
        self.nlp, self.parameters = denser, fresh
        self.lbx, self.ubx = denser.variable_bounds(self.case, denser.layout, *self.draw_speed_range, fresh)
        self.scale = denser.variable_scales(self.case)
        return local

    def _room(self, res: NLPResult, verification: Verification) -> tuple[int, float] | None:
        """``(parameter index, limit / exact value)`` of the first limit whose NLP row can overstate its
        figure (``Limit.overestimated``; the RMS torque's trapezoid) where that row is active at ``res`` and
        the exact figure of the verified plan stays more than :data:`BINDING_SHARE` below the limit."""
        for limit in self.nlp.layout.limits:
            block = self.nlp.block_of(limit.id)
            if not limit.overestimated or limit.id not in self.nlp.refinable or block is None:
                continue
            check = verification.check(limit.id)
            if res.g[block.start] < 1 - ROW_ACTIVE or check is None:
                continue
            if check.margin > BINDING_SHARE * check.limit:
                return self.nlp.refinable[limit.id].index, check.limit / check.value
        return None

    def key(self, values: dict[str, float]) -> np.ndarray:
        """``values`` as the NLP's variable vector (to compare starts)."""
        values = self.nlp.completed(values)
        return np.array([values[k] for k, _ in self.nlp.variables])

    def consider(self, solution: Solution, score: float) -> None:
        """Keep ``solution`` (verified) when its ``score`` beats the best so far."""
        if self.best is None or score < self.best_score - SAME_SCORE:
            self.best, self.best_score = solution, score

    def multi_start(
        self, x0s: list[dict[str, float]], placement: Placement, confirm: bool = True, ran: tuple[Ran, ...] = ()
    ) -> dict[str, float] | None:
        """Run the starts in order until the two best verified ones agree on the score (the optimum
        is confirmed; ``confirm`` False: until one verifies) or the starts run out; the values of the
        best verified start. ``ran``: starts of this placement already solved (the drive's probe): they
        are not run again, and what they found counts. While a start runs whose result cannot end the
        search by agreement (none found yet; a check of :attr:`stop_on` still may), the next one's first solve is
        begun ahead (:meth:`begin_ahead`)."""
        found = sorted((r.found for r in ran if r.found is not None), key=lambda item: item[1])
        tried = [self.key(r.start) for r in ran]
        todo = []
        for x0 in x0s:
            key = self.key(x0)
            if not any(_same_start(key, other) for other in tried):  # the same start again would repeat its answer
                tried.append(key)
                todo.append(x0)
        own = self.ahead is None  # made ahead for this multi-start only, else for the solve that began it
        self.ahead = self.ahead or StartsAhead()
        try:
            for i, x0 in enumerate(todo):
                if self.stopped:
                    break
                if confirm and not found and i + 1 < len(todo):  # the next start runs (but after a stopping check)
                    self.begin_ahead(todo[i + 1], placement)
                out = self.attempt(x0, placement)
                if out is None:
                    continue
                found.append(out)
                found.sort(key=lambda item: item[1])
                if not confirm or (len(found) >= 2 and found[1][1] - found[0][1] <= AGREE_S):
                    break
        finally:
            if own:
                self.stop_ahead()
        return found[0][0] if found else None

    def begin_ahead(self, x0: dict[str, float], placement: Placement) -> None:
        """The first solve of the start ``x0`` (as :meth:`attempt` will make it) begun in a worker
        (:class:`StartsAhead`; until :meth:`stop_ahead`)."""
        self.ahead = self.ahead or StartsAhead()
        q = self.parameters.copy()
        self.ahead.start(self.nlp, (x0, q, self.lbx, self.ubx, placement, self.scale, None, self.fixed_period))

    def stop_ahead(self) -> None:
        """Stop the worker of :meth:`begin_ahead` (what it has not handed over is dropped)."""
        if self.ahead is not None:
            self.ahead.close()
        self.ahead = None

    def answer(self) -> Solution:
        """The best verified plan with the solver's totals; else the typed error: a converged plan
        that failed the dense check is the finding (:class:`Unverified`), otherwise :class:`NoPlanFound`."""
        if self.best is None:
            found = [a for a in self.attempts if a.check is not None]
            if found:
                raise Unverified("no plan meets the limits: " + found[0].describe(), found[0].check)
            last = self.attempts[-1].describe() if self.attempts else "no start"
            raise NoPlanFound(
                f"the solver found none from {self.starts} starts, which does not prove the limits "
                f"cannot be met; last: {last}",
                tuple(self.attempts),
            )
        if schedule_matters(self.case):  # verified with the storage's lazy schedule: now with its least-energy one
            evaluation = with_least_energy(self.best.evaluation)
            if not evaluation.verification.passed:
                failed = evaluation.verification.failures()[0]
                raise Unverified("no plan meets the limits: " + Attempt(check=failed).describe(), failed)
            self.best = replace(self.best, evaluation=evaluation)
        plan = self.best.plan
        if self.placement == "free" and plan.placement == "published":
            # the published structure is one of the free structures: report it as the free answer
            plan = replace(plan, placement="free")
        info = SolverInfo(self.iterations, time.perf_counter() - self.t_start, self.starts, plan.solver.status)
        return replace(self.best, plan=replace(plan, solver=info))


# the NLPs whose solves a worker may make, by a token of their own (a forked worker holds the same objects under the
# same tokens; never an object's id, which a later object may take)
_SOLVABLE: weakref.WeakValueDictionary[int, CycleNLP] = weakref.WeakValueDictionary()
_TOKENS = itertools.count()


def _token(nlp: CycleNLP) -> int:
    """``nlp``'s token in :data:`_SOLVABLE` (given on first use, never given again)."""
    if "_ahead_token" not in vars(nlp):
        nlp._ahead_token = next(_TOKENS)
        _SOLVABLE[nlp._ahead_token] = nlp
    return nlp._ahead_token


def _solve_there(token: int, args: tuple) -> NLPResult:
    """In the worker: ``CycleNLP.solve(*args)`` of the NLP of ``token`` (a ``KeyError`` where the worker was forked
    before it was built: the call is then made by the search itself)."""
    return _SOLVABLE[token].solve(*args)


class StartsAhead:
    """The first IPOPT solves of a multi-start's coming starts, made in one forked worker (``planning.solver.ahead``)
    while this process runs the start before: the same call on the same inputs, so the same result to the last bit
    (and the same answers); a start takes its solve when its turn comes (:meth:`take`). Where the worker cannot fork
    (one core, threads running: a sweep's, a trade-off's or the web page's workers, whose cores are busy), no core is
    free (``planning.solver.ahead.core_free``: other processes hold them), or the worker lacks the NLP, nothing is
    made ahead: the search solves as before. The worker is stopped by
    :meth:`close` (a start the search never reached is dropped there)."""

    def __init__(self) -> None:
        self._ahead: Ahead | None = None
        self._forked_with: frozenset[int] = frozenset()  # the NLPs the worker holds
        self._calls: list[tuple[CycleNLP, tuple, Call]] = []

    def start(self, nlp: CycleNLP, args: tuple) -> None:
        """``nlp.solve(*args)`` begun in the worker (forked now where it does not hold ``nlp``; nothing where it
        was begun already)."""
        if not core_free() or any(other is nlp and _same_call(begun, args) for other, begun, _ in self._calls):
            return
        token = _token(nlp)
        if self._ahead is None or token not in self._forked_with:
            self.close()
            self._ahead, self._forked_with = Ahead(), frozenset(_SOLVABLE.keys())
        self._calls.append((nlp, args, self._ahead.start(_solve_there, token, args)))

    def take(self, nlp: CycleNLP, args: tuple) -> NLPResult | None:
        """The result of ``nlp.solve(*args)`` where it was begun ahead (made here where the worker failed), else
        None."""
        for k, (other, begun, call) in enumerate(self._calls):
            if other is nlp and _same_call(begun, args):
                del self._calls[k]
                return call.take()
        return None

    def close(self) -> None:
        """Stop the worker (a solve under way there is dropped)."""
        if self._ahead is not None:
            self._ahead.close()
        self._ahead, self._calls = None, []


def _same_call(a: tuple, b: tuple) -> bool:
    """Two argument tuples of ``CycleNLP.solve`` the same to the last bit (arrays, dicts of floats, the rest)."""
    if len(a) != len(b):
        return False
    for x, y in zip(a, b, strict=True):
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            if not (isinstance(x, np.ndarray) and isinstance(y, np.ndarray) and np.array_equal(x, y)):
                return False
        elif x != y:
            return False
    return True


def _same_key(a: tuple, b: tuple) -> bool:
    """Two problem keys (:meth:`Search._problem_key`) the same: the one NLP object, equal settings and arrays."""
    return len(a) == len(b) and a[0] is b[0] and all(x == y for x, y in zip(a[1:], b[1:], strict=True))


def _same_start(a: np.ndarray, b: np.ndarray) -> bool:
    """Two starts of an NLP the same to round-off (a start of the denser variant has more variables)."""
    n = min(a.size, b.size)
    return bool(np.allclose(a[:n], b[:n], rtol=SAME_START_REL, atol=SAME_ANGLE_RAD))


@dataclass(frozen=True)
class Optimum:
    """An attempt's first optimum ``x`` (before any refinement) of the problem ``key``
    (:meth:`Search._problem_key`), what the attempt ``found`` from it (verified values, score) and that plan."""

    key: tuple
    x: np.ndarray
    found: tuple[dict[str, float], float]
    solution: Solution


@dataclass(frozen=True)
class Ran:
    """A start already solved: its ``start`` values and what it ``found`` (verified values and score), or None."""

    start: dict[str, float]
    found: tuple[dict[str, float], float] | None


def prepare(
    case: Case, placement: Placement, nlp: CycleNLP | None = None, optima: list[Optimum] | None = None
) -> Search:
    """Prechecks, the case's parameters, the variable bounds and scales of the compiled NLP: ``nlp``, or by
    default the case's law's halves NLP (with the motor's rows when it has a drive). ``optima``: the first
    optima of another search of the same solve (a neighbour's start and the cold solve share them)."""
    t_start = time.perf_counter()
    w2_lo, w2_hi = precheck(case)
    nlp = nlp or halves_nlp_for(case)
    p = nlp.layout.values(case)
    lbx, ubx = nlp.variable_bounds(case, nlp.layout, w2_lo, w2_hi, p)
    search = Search(case, placement, nlp, p, lbx, ubx, nlp.variable_scales(case), (w2_lo, w2_hi), t_start)
    if optima is not None:
        search.optima = optima
    return search
