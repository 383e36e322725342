"""The NLPs' derivative functions compiled into the cache (``planning.solver.compiled``): the same functions (the
same numbers, the same IPOPT iterations), loaded by a later solver of the same problem, and a clear fallback where
there is no cache or no compiler; compiled in the background as a long-lived process builds them
(``planning.solver.background``), a compiler under way killed when it stops."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from planning.solver import compiled
from planning.solver.background import BackgroundCompiler
from planning.solver.ipopt import NLPSolver, adopt_compiled
from tests.conftest import PUBLISHED_CASE


def _problem() -> dict:
    """A small SX problem with curvature in its objective and rows (a Rosenbrock valley under a disc and a line)."""
    x, p = ca.SX.sym("x", 3), ca.SX.sym("p", 1)
    f = (1 - x[0]) ** 2 + p[0] * (x[1] - x[0] ** 2) ** 2 + (x[2] - x[1]) ** 2
    g = ca.vertcat(ca.sumsqr(x) - 2.0, x[0] + ca.sin(x[1]) * x[2])
    return {"x": x, "p": p, "f": f, "g": g}


def _solve(solver: NLPSolver):
    return solver.solve(np.array([-1.2, 1.0, 0.5]), [-5] * 3, [5] * 3, [-np.inf, -1.0], [0.0, 1.5], p=np.array([100.0]))


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


@pytest.mark.skipif(compiled.compiler() is None, reason="no C compiler on this machine")
def test_compiled_derivatives_are_the_interpreted_ones_and_a_later_solver_loads_them(cache):
    solver = NLPSolver("toy", _problem())
    early = NLPSolver("toy", _problem())  # another process's solver of it (the page's worker), built before
    assert not solver.compiled and not early.adopt()
    interpreted = _solve(solver)
    slow_functions = {name: solver._cold.get_function(name) for name in compiled.COMPILED_FUNCTIONS.values()}
    assert solver.compile() > 0
    assert solver.compiled and len(list(cache.glob("*.so"))) == 2
    again = _solve(solver)
    loaded = NLPSolver("toy", _problem())  # a later process's solver of the same problem: found in the cache
    assert loaded.compiled and loaded.compile() == 0.0
    assert not early.compiled and adopt_compiled() >= 1 and early.compiled  # takes them from the cache now
    for result in (again, _solve(loaded), _solve(early)):
        assert np.array_equal(result.x, interpreted.x) and result.iterations == interpreted.iterations
    # the compiled functions give the interpreted ones' numbers
    x, p, lam = np.array([0.3, -0.7, 1.1]), np.array([100.0]), np.array([0.4, -2.0])
    for name in compiled.COMPILED_FUNCTIONS.values():
        fast, slow = loaded._cold.get_function(name), slow_functions[name]
        assert fast.class_name() != slow.class_name()  # a library against CasADi's interpreter
        args = [x, p, 1.0, lam] if name == "nlp_hess_l" else [x, p]
        a, b = fast.call(args), slow.call(args)  # every output, as a list
        assert len(a) == len(b) and all(np.array_equal(np.array(u), np.array(v)) for u, v in zip(a, b, strict=True))
    other = _problem()
    other["f"] = other["f"] + other["x"][2] ** 4  # another problem: another key, not found
    assert not NLPSolver("toy", other).compiled
    # a library of another problem's shape under a key (copied there): discarded, the interpreted functions used
    wider = _problem()
    wider["g"] = ca.vertcat(wider["g"], wider["x"][0])  # a third row
    wider_key = compiled.problem_key(wider)
    for library in list(cache.glob("*.so")) + list(cache.glob("*.sha256")):
        (cache / library.name.replace(compiled.problem_key(_problem()), wider_key)).write_bytes(library.read_bytes())
    misfit = NLPSolver("wider", wider)
    assert not misfit.compiled and not any(cache.glob(f"{wider_key}*"))


def test_a_problems_key_is_made_only_where_the_cache_holds_a_library(cache, monkeypatch):
    """The key (a serialization of the problem: 0.2 s on a linkage's) is not made to look into a cache without any
    library; asked for, it is the problem's; with a library there, it is made to look for its own."""
    import planning.solver.ipopt as ipopt_module

    made: list[str] = []
    monkeypatch.setattr(ipopt_module, "problem_key", lambda *args: made.append("key") or compiled.problem_key(*args))
    solver = NLPSolver("toy", _problem())
    assert made == [] and not solver.compiled
    assert solver.key == compiled.problem_key(_problem()) and made == ["key"]
    cache.mkdir(parents=True)
    (cache / "kanother_nlp_jac_g.so").write_bytes(b"")
    assert not NLPSolver("toy", _problem()).compiled and made == ["key", "key"]


def test_without_a_cache_or_a_compiler_the_functions_stay_interpreted_said_once(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(compiled, "_said", set())
    monkeypatch.setenv(compiled.CACHE_ENV, "off")
    solver = NLPSolver("toy", _problem())
    assert solver.compile() is None and solver.compile() is None and not solver.compiled
    assert capsys.readouterr().err.count("no cache (PRESSPLAN_CACHE=off)") == 1
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(compiled, "compiler", lambda: None)
    assert solver.compile() is None
    assert "no C compiler" in capsys.readouterr().err
    monkeypatch.setattr(compiled, "compiler", lambda: "false")  # a compiler that fails: said in one line
    assert solver.compile() is None
    assert "not compiled (false failed" in capsys.readouterr().err
    assert _solve(solver).success  # interpreted, as before
    mx = {k: v for k, v in zip("xpfg", (ca.MX.sym("x", 1), ca.MX.sym("p", 0), 0, 0), strict=True)}
    mx["f"], mx["g"] = mx["x"] ** 2, mx["x"]
    assert NLPSolver("mx", mx).compile() is None  # an MX problem is not compiled


@pytest.mark.slow  # compiling the published case's NLP takes some 20 s
@pytest.mark.skipif(compiled.compiler() is None, reason="no C compiler on this machine")
def test_pressplan_compile_then_solve_gives_the_same_plan(tmp_path):
    env = {"PRESSPLAN_CACHE": str(tmp_path / "cache"), "PATH": "/usr/bin:/bin"}
    cli = [sys.executable, "-m", "planning.cli"]
    done = subprocess.run([*cli, "compile", str(PUBLISHED_CASE)], env=env, capture_output=True, text=True)
    assert done.returncode == 0 and "1 NLP(s) compiled" in done.stdout, done.stderr
    plans = {}
    for name, cache in (("compiled", env["PRESSPLAN_CACHE"]), ("interpreted", "off")):
        out = tmp_path / name
        args = [*cli, "solve", str(PUBLISHED_CASE), "--no-plots", "--out", str(out)]
        subprocess.run(args, env={**env, "PRESSPLAN_CACHE": cache}, check=True, capture_output=True)
        plans[name] = json.loads((out / "result.json").read_text())
    a, b = plans["compiled"], plans["interpreted"]
    assert a["spm"] == b["spm"] and a["solver"]["iterations"] == b["solver"]["iterations"]


def test_a_damaged_library_or_an_unwritable_cache_leaves_the_functions_interpreted(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(compiled, "_said", set())
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path))
    key = compiled.problem_key(_problem())
    for digest_of_what_is_there in (False, True):  # a truncated library (its checksum), or one that does not load
        for name in compiled.COMPILED_FUNCTIONS.values():
            library = tmp_path / f"{key}_{name}.so"
            library.write_bytes(b"not a library")
            text = compiled._digest(library) if digest_of_what_is_there else "0" * 64
            compiled._digest_path(library).write_text(text)
        monkeypatch.setattr(compiled, "_said", set())
        solver = NLPSolver("toy", _problem())
        assert not solver.compiled and _solve(solver).success
        assert "a compiled library not used" in capsys.readouterr().err
        assert not any(tmp_path.iterdir())  # removed: `pressplan compile` makes them anew
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "file" / "cache"))
    monkeypatch.setattr(compiled, "compiler", lambda: "cc")
    (tmp_path / "file").write_text("a file where the cache's folder would go")
    assert solver.compile() is None and "not compiled" in capsys.readouterr().err


@pytest.mark.parametrize("kind", [ca.SX, ca.MX])
def test_the_row_split_jacobian_is_casadis_own(kind):
    """Dense rows (more than DENSE_ROW variables) apart from sparse ones, in any order, none or all of them dense."""
    from planning.solver.lifting import DENSE_ROW, row_split_jacobian

    n = DENSE_ROW + 6
    x = kind.sym("x", n)
    dense = ca.sum1(ca.sin(x)) * x[0]
    rows = {
        "mixed": ca.vertcat(x[1] * x[2], dense, ca.cos(x[3]), ca.sumsqr(x), x[n - 1] ** 3),
        "sparse only": ca.vertcat(x[1] * x[2], ca.cos(x[3])),
        "dense only": ca.vertcat(dense, ca.sumsqr(x)),
    }
    point = np.linspace(-1.0, 1.0, n)
    for name, g in rows.items():
        ours = ca.Function("a", [x], [row_split_jacobian(g, x)])(point)
        theirs = ca.Function("b", [x], [ca.jacobian(g, x)])(point)
        assert ours.sparsity() == theirs.sparsity() and np.array_equal(np.array(ours), np.array(theirs)), name


@pytest.mark.skipif(compiled.compiler() is None, reason="no C compiler on this machine")
def test_the_background_compiler_compiles_what_the_process_builds_and_the_solves_stay_the_same(cache):
    solver = NLPSolver("toy", _problem())  # built by "the page": interpreted at first
    interpreted = _solve(solver)
    said = []
    compiler = BackgroundCompiler(say=said.append, poll_s=0.05, source=lambda: [solver]).start()
    try:
        deadline = time.monotonic() + 60
        while not compiler.compiled and time.monotonic() < deadline:  # its record: the solver swaps just before
            time.sleep(0.05)
    finally:
        compiler.close()
    assert solver.compiled and compiler.compiled == ["toy"] and len(said) == 1 and "toy compiled" in said[0]
    again = _solve(solver)  # the same solver object, its functions swapped
    assert np.array_equal(again.x, interpreted.x) and again.iterations == interpreted.iterations


def test_closing_the_background_compiler_kills_its_compiler_and_leaves_the_solver_interpreted(
    cache, tmp_path, monkeypatch, capsys
):
    slow = tmp_path / "bin" / "cc"  # a compiler that would take a minute
    slow.parent.mkdir()
    marker = tmp_path / "started"
    scratch = tmp_path / "scratch"  # where the compiler says its own temporary files go (gcc: $TMPDIR)
    slow.write_text(
        f'#!/bin/sh\necho "$TMPDIR" > {scratch}\ntouch "$TMPDIR/cc-own.s"\n'
        f"echo $$ > {marker}.tmp\nmv {marker}.tmp {marker}\nexec sleep 60\n"
    )
    slow.chmod(0o755)
    monkeypatch.setattr(compiled, "compiler", lambda: str(slow))
    solver = NLPSolver("toy", _problem())
    compiler = BackgroundCompiler(poll_s=0.05, source=lambda: [solver]).start()
    deadline = time.monotonic() + 30
    while not marker.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert marker.exists()
    pid = marker.read_text().strip()  # the compiler's process under way (sleeping its minute)
    assert subprocess.run(["kill", "-0", pid], capture_output=True).returncode == 0
    t_close = time.monotonic()
    compiler.close()
    assert time.monotonic() - t_close < 5 and not compiler._thread.is_alive()
    time.sleep(0.2)  # (reaped by the thread's Popen before close returned; the signal is immediate)
    assert subprocess.run(["kill", "-0", pid], capture_output=True).returncode != 0  # killed, not left to run
    assert not solver.compiled and not list(cache.glob("*.so"))
    own = Path(scratch.read_text().strip())  # its temporary files: in the cache's temporary folder, gone with it
    assert own.parent == cache and not own.exists()
    assert "not compiled" not in capsys.readouterr().err  # stopped on purpose: nothing to say


def test_a_compile_that_raises_is_said_in_one_line_and_the_thread_goes_on():
    class Failing:  # a built problem whose compile raises (CasADi's code generator, say)
        compilable, compiled, key, name = True, False, "k-failing", "failing"

        def compile(self, niceness, cancel):  # noqa: ANN001, ANN202
            raise ValueError("no code for this function")

    class Fine(Failing):
        key, name = "k-fine", "fine"

        def compile(self, niceness, cancel):  # noqa: ANN001, ANN202
            self.compiled = True
            return 1.0

    failing, fine = Failing(), Fine()
    said = []
    compiler = BackgroundCompiler(say=said.append, poll_s=0.02, source=lambda: [failing, fine]).start()
    deadline = time.monotonic() + 10
    while not fine.compiled and time.monotonic() < deadline:
        time.sleep(0.02)
    compiler.close()
    assert fine.compiled and compiler.compiled == ["fine"] and not failing.compiled
    assert said[0] == "failing not compiled (ValueError: no code for this function); it stays interpreted"
    assert len(said) == 2 and "fine compiled" in said[1]  # tried once, not again at every poll
