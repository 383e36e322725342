"""The NLPs' derivative functions compiled to machine code, kept in a cache directory.

An SX problem's constraint Jacobian and Lagrangian Hessian are evaluated at every IPOPT iteration; CasADi interprets
them (the published case's Hessian is 132 000 operations: 0.7 ms a call, half an iteration). Compiled by a C
compiler from CasADi's generated code they evaluate three times faster and are the same functions (the same
operations in the same order: the same numbers; ``tests/test_compiled.py``). Compiling takes some 20 s a problem
(``gcc -O1``; 60 s for a drive NLP's), so it is done once, on request (``pressplan compile``) or in the background
by a long-lived process (``pressplan serve``: ``planning.solver.background``), and kept for every later solve of the
problem (any command, a sweep's workers, the web page): ``$PRESSPLAN_CACHE`` (default
``$XDG_CACHE_HOME/pressplan`` or ``~/.cache/pressplan``; ``off`` turns the cache off). A problem is found there by a
key: the SHA-256 of the problem's own functions (serialized by CasADi), CasADi's version, the machine and the
compiler's flags; another problem, another CasADi, another machine: another key. Without a compiler, or without the
cache, the functions are interpreted as before: said once, never an error.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import platform
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import casadi as ca

from planning.solver import lifting
from planning.solver.lifting import Lift

CACHE_ENV = "PRESSPLAN_CACHE"
OFF = "off"
# IEEE arithmetic as written: no fused multiply-adds (an aarch64 compiler's default contracts a * b + c), no fast
# math; so any conforming C compiler gives the interpreted functions' numbers
COMPILER_FLAGS = ("-O1", "-ffp-contract=off", "-shared", "-fPIC")
FORMAT = "1"  # the cache's layout: a change makes every key new
# nlpsol's options that take a derivative function, and the name of that function in a built solver (the ones
# evaluated at every iteration)
COMPILED_FUNCTIONS = {"jac_g": "nlp_jac_g", "hess_lag": "nlp_hess_l"}
_said: set[str] = set()


def cache_dir() -> Path | None:
    """The cache directory (module docstring; a relative ``PRESSPLAN_CACHE`` from the working directory, an empty
    one as unset), or None where it is turned off."""
    value = (os.environ.get(CACHE_ENV) or "").strip()
    if value:
        return None if value.lower() == OFF else Path(value).resolve()
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "pressplan"


def compiler() -> str | None:
    """The C compiler (``cc`` or ``gcc`` on the path), or None."""
    return shutil.which("cc") or shutil.which("gcc")


def problem_key(problem: dict, lift: Lift | None = None) -> str:
    """The cache key of an SX problem ``{"x", "p", "f", "g"}`` (module docstring); of a lifted one (``lift``:
    ``planning.solver.lifting``), the key of what its derivative functions are built from: its rows in ``x``, ``p``
    and the lifted symbols, the sample angles, the mechanism's coefficients and the lifting's own source."""
    inputs = [problem["x"]] + ([problem["p"]] if "p" in problem else [])
    parts = [ca.Function("nlp", inputs + ([lift.symbols] if lift else []), [problem["f"], problem["g"]])]
    if lift is not None:
        parts.append(ca.Function("angles", inputs, [lift.angle_values]))
        parts.append(ca.Function("mechanism", [lift.angles, *inputs[1:]], [*lift.values, *lift.first, *lift.second]))
    salt = "|".join((FORMAT, ca.__version__, platform.machine(), sys.platform, *COMPILER_FLAGS))
    digest = hashlib.sha256(salt.encode())
    for part in parts:
        digest.update(part.serialize().encode())
    if lift is not None:
        digest.update(Path(lifting.__file__).read_bytes())
    return "k" + digest.hexdigest()[:32]


def any_compiled() -> bool:
    """Whether the cache holds any compiled library (a problem's key need not be made to look for it otherwise)."""
    folder = cache_dir()
    try:
        return folder is not None and folder.is_dir() and any(folder.glob("*.so"))
    except OSError:  # unreadable: as without a cache
        return False


def cached_functions(key: str) -> dict[str, ca.Function] | None:
    """The compiled derivative functions of the problem of ``key`` (nlpsol's options) where the cache holds them,
    else None: also where the cache cannot be read or a library is damaged (its SHA-256 is not the one written
    beside it when it was made: a truncated file would crash the process that loads it) or does not load; such
    libraries are removed, said once, so that ``pressplan compile`` makes them anew."""
    folder = cache_dir()
    if folder is None:
        return None
    paths = _libraries(folder, key)
    try:
        if not all(_present(path) for path in paths.values()):
            return None
        if not all(_digest_path(path).read_text().strip() == _digest(path) for path in paths.values()):
            raise OSError("its checksum does not match")
        return {option: ca.external(COMPILED_FUNCTIONS[option], str(path)) for option, path in paths.items()}
    except (OSError, RuntimeError) as exc:  # unreadable or damaged: interpreted, as without a cache
        discard(key, exc)
        return None


def discard(key: str, reason: Exception) -> None:
    """Remove the libraries of ``key`` that did not load or did not fit their problem (``reason``), said once."""
    folder = cache_dir()
    if folder is None:
        return
    why = _first_line(reason)
    _say_once(f"{folder}: a compiled library not used ({why}; removed: pressplan compile makes it anew)")
    for library in _libraries(folder, key).values():
        for path in (library, _digest_path(library)):
            with contextlib.suppress(OSError):
                path.unlink(missing_ok=True)


def compile_into_cache(
    key: str, functions: dict[str, ca.Function], niceness: int = 0, cancel: Cancel | None = None
) -> float | None:
    """Compile ``functions`` (nlpsol's options -> the interpreted derivative functions of the problem of ``key``)
    into the cache; the seconds the compiler took (0.0 where every library was there already), None where there is
    no cache, no compiler, or the compiler or the folder failed (said once; not when ``cancel`` stopped it). Each
    file is written under a temporary name and renamed, its SHA-256 beside it last: a reader never takes half a
    library. ``niceness``: the compiler's (a background compile yields the cores to the solves)."""
    folder, cc = cache_dir(), compiler()
    if folder is None or cc is None:
        _say_once("no cache (PRESSPLAN_CACHE=off)" if folder is None else "no C compiler (cc, gcc) on the path")
        return None
    if folder.exists() and not folder.is_dir():
        _say_once(f"{folder}: not a folder (PRESSPLAN_CACHE)")
        return None
    t_start, compiled = time.perf_counter(), False
    try:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        for option, library in _libraries(folder, key).items():
            if not _present(library):
                _compile_one(cc, functions[option], folder, library.stem, niceness, cancel)
                compiled = True
    except (OSError, RuntimeError) as exc:  # RuntimeError: CasADi's generator, or the compiler's failure
        if cancel is None or not cancel.stopped:  # (a compile stopped on purpose: nothing to say)
            _say_once(f"{folder}: not compiled ({_first_line(exc)})")
        return None
    return time.perf_counter() - t_start if compiled else 0.0


def _compile_one(
    cc: str, function: ca.Function, folder: Path, stem: str, niceness: int = 0, cancel: Cancel | None = None
) -> None:
    """``function``'s generated C compiled by ``cc`` into ``folder/stem.so``, its SHA-256 into ``stem.so.sha256``
    (each written under a temporary name). The compiler runs in its own process group (at ``niceness``), killed
    with it when this process is interrupted or ``cancel`` is stopped (a compiler left running would burn a core
    for a minute)."""
    with tempfile.TemporaryDirectory(dir=folder) as work:
        generator = ca.CodeGenerator(f"{stem}.c", {"with_header": False})
        generator.add(function)
        generator.generate(work + os.sep)
        library = Path(work) / f"{stem}.so"
        command = [cc, *COMPILER_FLAGS, str(Path(work) / f"{stem}.c"), "-o", str(library), "-lm"]
        nice = shutil.which("nice") if niceness else None
        command = [nice, "-n", str(niceness), *command] if nice else command
        if cancel is not None and cancel.stopped:
            raise RuntimeError("stopped")
        temporary = {**os.environ, "TMPDIR": work}  # the compiler's own files too: gone with the folder, killed or not
        with subprocess.Popen(
            command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True, env=temporary
        ) as run:
            if cancel is not None:
                cancel.started(run.pid)  # (its own session: its process group is its pid)
            try:
                _, errors = run.communicate()
            except BaseException:
                os.killpg(run.pid, signal.SIGKILL)
                raise
            finally:
                if cancel is not None:
                    cancel.ended(run.pid)
        if run.returncode != 0:
            said = [ln for ln in errors.decode(errors="replace").splitlines() if "error" in ln] or ["no message"]
            raise RuntimeError(f"{Path(cc).name} failed: {said[0].strip()}")
        digest = Path(work) / f"{stem}.so.sha256"
        digest.write_text(_digest(library))
        os.replace(library, folder / f"{stem}.so")
        os.replace(digest, _digest_path(folder / f"{stem}.so"))


class Cancel:
    """The stop of a background compile (another thread's, ``planning.solver.background``): :meth:`stop` kills its
    compiler under way (its process group) and starts none after it; the compile ends as failed, unsaid."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._stopped = threading.Event()
        self._groups: set[int] = set()

    @property
    def stopped(self) -> bool:
        return self._stopped.is_set()

    def stop(self) -> None:
        with self._lock:
            self._stopped.set()
            for group in self._groups:
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.killpg(group, signal.SIGKILL)

    def started(self, group: int) -> None:
        """A compiler started (its process group): killed at once when stopped meanwhile."""
        with self._lock:
            self._groups.add(group)
            if self._stopped.is_set():
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.killpg(group, signal.SIGKILL)

    def ended(self, group: int) -> None:
        with self._lock:
            self._groups.discard(group)


def _libraries(folder: Path, key: str) -> dict[str, Path]:
    """The library of each compiled function of the problem of ``key`` (nlpsol's option -> its path)."""
    return {option: folder / f"{key}_{name}.so" for option, name in COMPILED_FUNCTIONS.items()}


def _present(library: Path) -> bool:
    """``library`` and its SHA-256 beside it are there (whether they match is checked when it is loaded)."""
    return library.is_file() and _digest_path(library).is_file()


def _digest(path: Path) -> str:
    """The SHA-256 of the file ``path`` (hex)."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _digest_path(library: Path) -> Path:
    """Where the SHA-256 of ``library`` is kept: beside it."""
    return library.with_name(library.name + ".sha256")


def _first_line(exc: Exception) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _say_once(reason: str) -> None:
    if reason not in _said:
        _said.add(reason)
        print(f"pressplan: {reason}: the NLPs' derivatives stay interpreted", file=sys.stderr)
