"""IPOPT behind one interface: the options, the call, the success test, scaling and warm starts.

Every NLP of the project (the cycle NLP of each motion law, the optimal law's, the time-optimal bound)
is compiled once into an :class:`NLPSolver` and solved through :meth:`NLPSolver.solve`, which returns
an :class:`NLPResult` with a typed status, the values in physical units, the constraint values, the
multipliers, the iteration count and the wall time. This module and the modules that build CasADi
expressions for it (``planning.solver.nlp``, ``planning.solver.halves_nlp``, ``planning.solver.free_nlp``,
``planning.solver.bound``, ``planning.solver.lifting``) are the only ones that import CasADi
(``tests/test_architecture.py`` checks). A problem that samples a lifted mechanism comes with its
:class:`~planning.solver.lifting.Lift`: its derivative functions are put together by the chain rule. An SX
problem's (a lifted one's too) Jacobian and Hessian come compiled to machine code where the cache holds them
(``planning.solver.compiled``; :meth:`NLPSolver.compile` puts them there): the same functions, faster.

Scaling: a problem may read a per-solve scale vector from the end of its parameter vector
(physical value = scale * decision variable). :meth:`NLPSolver.solve` then takes the physical start
and bounds, divides them by the scale, appends the scale to the parameters and multiplies the answer
back, so callers only see physical values.
"""

from __future__ import annotations

import contextlib
import enum
import io
import signal
import sys
import threading
import time
import weakref
from collections.abc import Iterator
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from planning.solver.compiled import (
    COMPILED_FUNCTIONS,
    Cancel,
    any_compiled,
    cached_functions,
    compile_into_cache,
    discard,
    problem_key,
)
from planning.solver.lifting import Lift, lifted_problem, row_split_jacobian
from planning.tolerances import IPOPT_MU_INIT, IPOPT_TOL, IPOPT_WARM_PUSH

MAX_SOLVE_WALL_S = 30.0  # [s] one IPOPT call at most (a normal one takes well under a second)
BASE_OPTIONS = {
    "ipopt.print_level": 0,
    "print_time": False,
    "ipopt.sb": "yes",
    "ipopt.tol": IPOPT_TOL,
    "ipopt.max_wall_time": MAX_SOLVE_WALL_S,
}
_SIGNALS = ("SIGINT", "SIGTERM")
# One IPOPT call at a time in a process: a compiled CasADi function keeps its work memory per instance,
# and IPOPT's linear solver (MUMPS) is not thread-safe; threads (the web server's, a Dask worker's) queue here.
_IPOPT_LOCK = threading.Lock()
WARM_START_OPTIONS = {  # a start from a nearby solution and its multipliers: a few iterations
    "ipopt.warm_start_init_point": "yes",
    "ipopt.mu_init": IPOPT_MU_INIT,
    "ipopt.warm_start_bound_push": IPOPT_WARM_PUSH,
    "ipopt.warm_start_mult_bound_push": IPOPT_WARM_PUSH,
    "ipopt.warm_start_slack_bound_push": IPOPT_WARM_PUSH,
}

BUILT: weakref.WeakSet = weakref.WeakSet()  # the process's solvers of SX problems (``pressplan compile`` compiles them)
_KEPT: list[list] = []  # while :func:`kept_solvers` runs: the solvers built, held (a solve may drop its NLP)
# nlpsol's options that take a derivative function, and the name of that function in a built solver
DERIVATIVE_FUNCTIONS = {"grad_f": "nlp_grad_f", "jac_g": "nlp_jac_g", "hess_lag": "nlp_hess_l"}
GAMMA = {"gamma": ["f", "g"]}  # the Lagrangian's terms (objective and rows), as nlpsol weighs them in its Hessian


class NLPStatus(enum.Enum):
    """How IPOPT ended, grouped by what it means for the caller."""

    SOLVED = "solved"  # Solve_Succeeded
    ACCEPTABLE = "acceptable"  # Solved_To_Acceptable_Level
    STOPPED_AT_LIMIT = "stopped at its iteration or time limit"  # Maximum_Iterations_Exceeded, ..._WallTime_...
    LOCALLY_INFEASIBLE = "locally infeasible"  # Infeasible_Problem_Detected (a local statement only)
    FAILED = "failed"  # anything else: restoration failed, numerical trouble, ...

    @classmethod
    def from_ipopt(cls, return_status: str) -> NLPStatus:
        """The status for IPOPT's ``return_status`` string."""
        if return_status == "Solve_Succeeded":
            return cls.SOLVED
        if return_status == "Solved_To_Acceptable_Level":
            return cls.ACCEPTABLE
        if return_status.startswith("Maximum_"):
            return cls.STOPPED_AT_LIMIT
        if return_status == "Infeasible_Problem_Detected":
            return cls.LOCALLY_INFEASIBLE
        return cls.FAILED


@dataclass(frozen=True)
class NLPResult:
    """One IPOPT solve. ``x``: the variables in physical units, clipped to their bounds unless asked not
    to (IPOPT relaxes bounds by about 1e-8); ``g``: the constraint values; ``multipliers``:
    ``(lam_x, lam_g)`` as the solver sees them (for a warm start of the same problem); ``objective``;
    ``iterations``; ``wall_time_s`` [s]; ``return_status``: IPOPT's own words."""

    status: NLPStatus
    return_status: str
    x: np.ndarray
    g: np.ndarray
    multipliers: tuple[np.ndarray, np.ndarray] = field(repr=False)
    objective: float
    iterations: int
    wall_time_s: float

    @property
    def success(self) -> bool:
        """Converged (to the requested or the acceptable tolerance)."""
        return self.status in (NLPStatus.SOLVED, NLPStatus.ACCEPTABLE)


class NLPSolver:
    """IPOPT on one CasADi problem ``{"x", "p", "f", "g"}``, compiled once and solved many times.

    ``options`` are added to :data:`BASE_OPTIONS`; ``fixed_scale``: the scales of a problem built in
    scaled variables with its scales as constants (physical = fixed_scale * x); the warm-start
    variant (same problem, IPOPT set up for a start from a nearby solution's multipliers, with
    ``warm_options`` added to :data:`WARM_START_OPTIONS`) is built on first use.
    """

    def __init__(
        self,
        name: str,
        problem: dict | ca.Function,
        options: dict | None = None,
        fixed_scale: np.ndarray | None = None,
        warm_options: dict | None = None,
        lift: Lift | None = None,
    ):
        self.fixed_scale = None if fixed_scale is None else np.asarray(fixed_scale, dtype=float)
        self.name = name
        self.options = {**BASE_OPTIONS, **(options or {})}
        # an SX problem's derivatives (a lifted one's too) compiled to machine code where the cache holds them
        # (``compiled``): found by the problem's key
        self.compilable = isinstance(problem, dict) and not isinstance(problem["x"], ca.MX)
        # its cache key (a serialization of the problem: 0.2 s on a linkage's lifted one) made when first needed:
        # where the cache holds compiled libraries, when compiled
        self._key_of: tuple | None = (problem, lift) if self.compilable else None
        self._key: str | None = None
        if lift is not None:  # the mechanism's quantities lifted out of the derivatives (``lifting``)
            problem, derivatives = lifted_problem(problem, lift)
            self.options.update(derivatives)
        self.problem = problem  # a dict of expressions, or (lifted) a function of x and p
        self.warm_options = {**WARM_START_OPTIONS, **(warm_options or {})}
        self.compiled = False
        self._cold = self._solver_with(cached_functions(self.key) if self.compilable and any_compiled() else None)
        self._warm: ca.Function | None = None
        if self.compilable:
            BUILT.add(self)
            for kept in _KEPT:
                kept.append(self)

    @property
    def key(self) -> str | None:
        """The problem's key in the compiled cache (``planning.solver.compiled.problem_key``); None for an MX
        problem."""
        if self._key is None and self._key_of is not None:
            self._key = problem_key(*self._key_of)
        return self._key

    def compile(self, niceness: int = 0, cancel: Cancel | None = None) -> float | None:
        """Compile this problem's derivative functions into the cache (``planning.solver.compiled``; the
        compiler at ``niceness``, stopped by ``cancel``) and solve with them from now on; the seconds the
        compiler took (0: they were there), or None where this problem cannot be compiled (an MX problem),
        there is no compiler or no cache, the compile was stopped, or the libraries made do not load (said
        once)."""
        if not self.compilable:
            return None
        if self.compiled:
            return 0.0
        functions = {option: self._cold.get_function(name) for option, name in COMPILED_FUNCTIONS.items()}
        seconds = compile_into_cache(self.key, functions, niceness, cancel)
        return seconds if seconds is not None and self.adopt() else None

    def adopt(self) -> bool:
        """Solve with the compiled derivative functions from now on where the cache holds them (compiled by this
        process or by another: the page's cold-solve worker takes those of the server's background compiler);
        whether this problem is compiled now. A cache without them costs two file lookups."""
        if self.compiled or not self.compilable:
            return self.compiled
        found = cached_functions(self.key)
        solver = self._fitted(found) if found is not None else None  # built outside the lock: solves go on
        if solver is None:
            return False
        with _IPOPT_LOCK:  # a thread may be solving with the interpreted functions: swapped between its solves
            self._cold, self._warm = self._adopted(found, solver), None
        return True

    def _solver_with(self, found: dict[str, ca.Function] | None) -> ca.Function:
        """The cold solver, with the compiled derivative functions ``found`` where they fit the problem (else,
        their libraries discarded, the interpreted ones); sets :attr:`compiled`."""
        solver = self._fitted(found) if found is not None else None
        if solver is None:
            return _compiled(self.name, self.problem, self.options)
        return self._adopted(found, solver)

    def _adopted(self, found: dict[str, ca.Function], solver: ca.Function) -> ca.Function:
        """``solver`` (built with the compiled functions ``found``), this problem's from now on: the options (the
        warm solver is built from them) and :attr:`compiled` say so."""
        self.options.update(found)
        self.compiled = True
        return solver

    def _fitted(self, found: dict[str, ca.Function]) -> ca.Function | None:
        """The cold solver with the compiled derivative functions ``found``; None where they do not fit the
        problem (a library of another shape under this key: not this problem's; discarded)."""
        try:
            return _compiled(self.name, self.problem, {**self.options, **found})
        except RuntimeError as exc:
            discard(self.key, exc)
            return None

    def _warm_function(self) -> ca.Function:
        if self._warm is None:
            # the same problem: its derivative functions are the cold solver's (generating them again would
            # cost as much as the first build)
            derivatives = {option: self._cold.get_function(name) for option, name in DERIVATIVE_FUNCTIONS.items()}
            options = {**self.options, **self.warm_options, **derivatives}
            self._warm = ca.nlpsol(f"{self.name}_warm", "ipopt", self.problem, options)
        return self._warm

    def solve(
        self,
        x0: np.ndarray,
        lbx: np.ndarray,
        ubx: np.ndarray,
        lbg: np.ndarray,
        ubg: np.ndarray,
        p: np.ndarray | None = None,
        scale: np.ndarray | None = None,
        warm_start: tuple[np.ndarray, np.ndarray] | None = None,
        clip_to_bounds: bool = True,
    ) -> NLPResult:
        """Solve from ``x0`` within ``lbx .. ubx`` (physical units) and ``lbg .. ubg``.

        ``scale``: the variables' scales when the problem reads them from the end of ``p``;
        ``warm_start``: the multipliers of a nearby solve of this problem (its :attr:`NLPResult.multipliers`);
        ``clip_to_bounds``: clip the answer into ``lbx .. ubx`` (IPOPT relaxes bounds by about 1e-8), or
        return it as IPOPT found it.
        """
        t0 = time.perf_counter()
        lbx, ubx = np.asarray(lbx, dtype=float), np.asarray(ubx, dtype=float)
        if scale is not None:
            unit = np.asarray(scale, dtype=float)
        else:
            unit = self.fixed_scale if self.fixed_scale is not None else np.ones(lbx.shape)
        args = {
            "x0": np.clip(np.asarray(x0, dtype=float), lbx, ubx) / unit,
            "lbx": lbx / unit,
            "ubx": ubx / unit,
            "lbg": lbg,
            "ubg": ubg,
        }
        if p is not None or scale is not None:
            parts = [np.asarray(p, dtype=float)] if p is not None else []
            args["p"] = np.concatenate(parts + ([unit] if scale is not None else []))
        if warm_start is not None:
            args.update(lam_x0=warm_start[0], lam_g0=warm_start[1])
        with _IPOPT_LOCK:  # the solvers chosen under it too: ``compile`` replaces them under it
            solver = self._cold if warm_start is None else self._warm_function()
            res = _call_passing_signals_on(solver, args)
            stats = solver.stats()
        x = np.array(res["x"]).ravel() * unit
        return_status = str(stats["return_status"])
        return NLPResult(
            status=NLPStatus.from_ipopt(return_status),
            return_status=return_status,
            x=np.clip(x, lbx, ubx) if clip_to_bounds else x,
            g=np.array(res["g"]).ravel(),
            multipliers=(np.array(res["lam_x"]).ravel(), np.array(res["lam_g"]).ravel()),
            objective=float(res["f"]),
            iterations=int(stats["iter_count"]),
            wall_time_s=time.perf_counter() - t0,
        )


def adopt_compiled() -> int:
    """Every problem this process built and solves interpreted: compiled from now on where the cache holds its
    functions now (:meth:`NLPSolver.adopt`); how many were adopted."""
    return sum(solver.adopt() for solver in list(BUILT) if not solver.compiled)


@contextlib.contextmanager
def kept_solvers() -> Iterator[list[NLPSolver]]:
    """The solvers of SX problems built inside the block (held by the list yielded: a solve that builds an NLP for
    one case only, a pendulum's, lets it go), and those built before that are still alive."""
    kept: list[NLPSolver] = list(BUILT)
    _KEPT.append(kept)
    try:
        yield kept
    finally:
        _KEPT.remove(kept)


def _compiled(name: str, problem: dict | ca.Function, options: dict) -> ca.Function:
    """``nlpsol`` of ``problem``. An SX problem as it is. An MX problem (vector operations, cheap to
    differentiate) is differentiated in MX: its gradient and Hessian by CasADi, its constraint Jacobian with the
    dense rows apart (``lifting.row_split_jacobian``), which evaluates as fast as CasADi's own Jacobian expanded
    to SX (a general colouring needs a sweep per variable where a dense row meets a dense column: 11-41 ms against
    1-6 ms on the optimal law's NLP of 1046-2502 variables) and is built without the expansion (0.1-1.4 s)."""
    if isinstance(problem, ca.Function) or not isinstance(problem["x"], ca.MX):
        return ca.nlpsol(name, "ipopt", problem, options)
    x, p, g = problem["x"], problem.get("p", ca.MX.sym("p", 0)), problem["g"]
    oracle = ca.Function("nlp", [x, p], [problem["f"], g], ["x", "p"], ["f", "g"])
    supplied = {  # as nlpsol derives them (the same functions), without the Jacobian it would derive too
        "grad_f": oracle.factory("nlp_grad_f", ["x", "p"], ["f", "grad:f:x"]),
        "hess_lag": oracle.factory("nlp_hess_l", ["x", "p", "lam:f", "lam:g"], ["triu:hess:gamma:x:x"], GAMMA),
    }
    supplied["jac_g"] = ca.Function("nlp_jac_g", [x, p], [g, row_split_jacobian(g, x)], ["x", "p"], ["g", "jac_g_x"])
    return ca.nlpsol(name, "ipopt", problem, {**options, **supplied})


def _call_passing_signals_on(solver: ca.Function, args: dict) -> dict:
    """Call ``solver``; a Ctrl-C or SIGTERM that arrives meanwhile is delivered again after the call.

    CasADi catches an interrupt inside IPOPT and ends the solve as a failed one
    (``NonIpopt_Exception_Thrown``): the signal would be lost and the next start would run on. Here
    the signal is recorded, the solve is stopped, and once CasADi has returned the signal is raised
    again with the process's own handlers (exit 130 or 143 in the CLI); CasADi's warning about it is
    dropped, anything else it writes to stderr passes through.
    """
    said = io.StringIO()  # CasADi reports a caught interrupt as a warning on sys.stderr
    with signals_held(stop=True) as caught:
        try:
            with contextlib.redirect_stderr(said):
                res = solver(**args)
        finally:
            lines = said.getvalue().splitlines(keepends=True)
            sys.stderr.write("".join(ln for ln in lines if not (caught and "KeyboardInterruptException" in ln)))
    if caught:
        raise KeyboardInterrupt  # a handler that returned: the solve was stopped all the same
    return res


@contextlib.contextmanager
def signals_held(stop: bool = False) -> Iterator[list[int]]:
    """A Ctrl-C or SIGTERM that arrives inside the block is recorded (the list yielded) and delivered to the
    process's own handler once the block has ended (exit 130 or 143 in the CLI). ``stop``: the recording
    also raises KeyboardInterrupt inside the block, which stops IPOPT at its next check. Without it the
    block runs on: an exception raised in the middle of importing a compiled extension (matplotlib's, while
    a sweep's workers solve) left the interpreter unable to exit (it aborted or hung instead of ending with
    143). Only the main thread can set handlers; elsewhere the block runs as it is. An ignored signal stays
    ignored."""
    caught: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield caught
        return

    def record(signum: int, frame) -> None:  # noqa: ANN001 - a signal handler's signature
        caught.append(signum)
        if stop:
            raise KeyboardInterrupt

    numbers = [getattr(signal, name) for name in _SIGNALS if hasattr(signal, name)]
    numbers = [num for num in numbers if signal.getsignal(num) is not signal.SIG_IGN]
    previous = {num: signal.signal(num, record) for num in numbers}
    try:
        yield caught
    finally:
        for num, handler in previous.items():
            signal.signal(num, handler)
        if caught:
            signal.raise_signal(caught[0])  # the process's own handler decides (KeyboardInterrupt, exit, ...)
