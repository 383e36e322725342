"""The NLPs' derivative functions compiled to machine code, kept in a cache directory.

An SX problem's constraint Jacobian and Lagrangian Hessian are evaluated at every IPOPT iteration; CasADi interprets
them (the published case's Hessian is 132 000 operations: 0.7 ms a call, half an iteration). Compiled by a C
compiler from CasADi's generated code they evaluate three times faster and are the same functions (the same
operations in the same order: the same numbers; ``tests/test_compiled.py``). Compiling takes some 20 s a problem
(``gcc -O1``; 60 s for a drive NLP's), so it is done once, on request (``pressplan compile``), and kept for every
later solve of the problem (any command, a sweep's workers, the web page): ``$PRESSPLAN_CACHE`` (default
``$XDG_CACHE_HOME/pressplan`` or ``~/.cache/pressplan``; ``off`` turns the cache off). A problem is found there by a
key: the SHA-256 of the problem's own functions (serialized by CasADi), CasADi's version, the machine and the
compiler's flags; another problem, another CasADi, another machine: another key. Without a compiler, or without the
cache, the functions are interpreted as before: said once, never an error.
"""

from __future__ import annotations

import hashlib
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import casadi as ca

CACHE_ENV = "PRESSPLAN_CACHE"
OFF = "off"
COMPILER_FLAGS = ("-O1", "-shared", "-fPIC")
FORMAT = "1"  # the cache's layout: a change makes every key new
# nlpsol's options that take a derivative function, and the name of that function in a built solver (the ones
# evaluated at every iteration)
COMPILED_FUNCTIONS = {"jac_g": "nlp_jac_g", "hess_lag": "nlp_hess_l"}
_said: set[str] = set()


def cache_dir() -> Path | None:
    """The cache directory (module docstring), or None where it is turned off."""
    value = os.environ.get(CACHE_ENV)
    if value is not None:
        return None if value.strip().lower() == OFF else Path(value)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "pressplan"


def compiler() -> str | None:
    """The C compiler (``cc`` or ``gcc`` on the path), or None."""
    return shutil.which("cc") or shutil.which("gcc")


def problem_key(problem: dict) -> str:
    """The cache key of an SX problem ``{"x", "p", "f", "g"}`` (module docstring)."""
    inputs = [problem["x"]] + ([problem["p"]] if "p" in problem else [])
    serialized = ca.Function("nlp", inputs, [problem["f"], problem["g"]]).serialize()
    salt = "|".join((FORMAT, ca.__version__, platform.machine(), sys.platform, *COMPILER_FLAGS))
    return "k" + hashlib.sha256(salt.encode() + serialized.encode()).hexdigest()[:32]


def cached_functions(problem: dict) -> dict[str, ca.Function] | None:
    """The compiled derivative functions of ``problem`` (nlpsol's options) where the cache holds them, else None."""
    folder = cache_dir()
    if folder is None:
        return None
    key = problem_key(problem)
    paths = {option: folder / f"{key}_{name}.so" for option, name in COMPILED_FUNCTIONS.items()}
    if not all(path.is_file() for path in paths.values()):
        return None
    try:
        return {option: ca.external(COMPILED_FUNCTIONS[option], str(path)) for option, path in paths.items()}
    except RuntimeError as exc:  # a damaged library: the interpreted functions, as without one
        _say_once(f"{paths['hess_lag'].parent}: a compiled library does not load ({str(exc).splitlines()[0]})")
        return None


def compile_into_cache(problem: dict, functions: dict[str, ca.Function]) -> float | None:
    """Compile ``functions`` (nlpsol's options -> the interpreted derivative functions of ``problem``) into the
    cache; the seconds it took, 0 where they were there already, None where there is no cache or no compiler (said
    once). Each file is written under a temporary name and renamed: a reader never sees half a library."""
    folder, cc = cache_dir(), compiler()
    if folder is None or cc is None:
        _say_once("no cache (PRESSPLAN_CACHE=off)" if folder is None else "no C compiler (cc, gcc) on the path")
        return None
    key, t_start = problem_key(problem), time.perf_counter()
    try:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        for option, name in COMPILED_FUNCTIONS.items():
            if not (folder / f"{key}_{name}.so").is_file():
                _compile_one(cc, functions[option], folder, f"{key}_{name}")
    except (OSError, subprocess.CalledProcessError) as exc:
        _say_once(f"{folder}: not compiled ({exc})")
        return None
    return time.perf_counter() - t_start


def _compile_one(cc: str, function: ca.Function, folder: Path, stem: str) -> None:
    """``function``'s generated C compiled by ``cc`` into ``folder/stem.so`` (written under a temporary name)."""
    with tempfile.TemporaryDirectory(dir=folder) as work:
        generator = ca.CodeGenerator(f"{stem}.c", {"with_header": False})
        generator.add(function)
        generator.generate(work + os.sep)
        library = Path(work) / f"{stem}.so"
        command = [cc, *COMPILER_FLAGS, str(Path(work) / f"{stem}.c"), "-o", str(library), "-lm"]
        subprocess.run(command, check=True, capture_output=True)
        os.replace(library, folder / f"{stem}.so")


def _say_once(reason: str) -> None:
    if reason not in _said:
        _said.add(reason)
        print(f"pressplan: {reason}: the NLPs' derivatives stay interpreted", file=sys.stderr)
