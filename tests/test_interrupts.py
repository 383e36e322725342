"""Kills, Ctrl-C and SIGTERM: the output folder is entirely old or entirely new, one line and the
conventional exit status, and no worker process outlives a sweep."""

from __future__ import annotations

import hashlib
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from .conftest import PUBLISHED_CASE, ROOT

KILL_TRIALS = 5  # per test (two tests, 10 kills in all)
PRESSPLAN = [sys.executable, "-m", "planning.cli"]


def run(args: list[str], **kw) -> subprocess.CompletedProcess:
    return subprocess.run([*PRESSPLAN, *args], cwd=ROOT, capture_output=True, text=True, **kw)


def sweep_process(out: Path, workers: int) -> subprocess.Popen:
    """A 41-point transfer-time sweep of the published case in a child process, output captured; Ctrl-C as from
    a terminal (a suite started in the background of a non-interactive shell ignores SIGINT, and a child would
    inherit that)."""
    return subprocess.Popen(
        [*PRESSPLAN, "sweep", str(PUBLISHED_CASE), "--vary", "process.transfer_time_s=1.0:3.0:41"]
        + ["--workers", str(workers), "--out", str(out)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


def state(folder: Path) -> tuple:
    """What a folder holds, timing fields aside: file names and the bytes of the timing-free files."""
    names = tuple(sorted(p.name for p in folder.iterdir()))
    digest = {
        name: hashlib.sha256((folder / name).read_bytes()).hexdigest()
        for name in ("trajectory.csv", "cam_table.csv", "published_profile.csv")
        if (folder / name).exists()
    }
    return names, tuple(sorted(digest.items()))


@pytest.mark.slow  # 4-7 s a case: the normal run keeps under 5 minutes (CI runs the slow tier)
@pytest.mark.skipif(sys.platform != "linux", reason="the kill test drives Linux processes")
@pytest.mark.parametrize("seed", [2026, 2027], ids=["kills 1-5", "kills 6-10"])  # the two workers share them
def test_killed_solve_leaves_the_folder_entirely_old_or_entirely_new(tmp_path, seed):
    other = tmp_path / "other.yaml"
    other.write_text(PUBLISHED_CASE.read_text().replace("transfer_time_s: 2.0", "transfer_time_s: 1.8"))
    old_master, new_master = tmp_path / "old", tmp_path / "new"
    assert run(["solve", str(PUBLISHED_CASE), "--out", str(old_master)]).returncode == 0  # with figures
    t = time.perf_counter()
    assert run(["solve", str(other), "--out", str(new_master), "--no-plots"]).returncode == 0
    full = time.perf_counter() - t
    old, new = state(old_master), state(new_master)
    assert old != new
    rng = random.Random(seed)
    out = tmp_path / "work" / "out"
    ends = {"old": 0, "new": 0}
    for _ in range(KILL_TRIALS):
        shutil.rmtree(out, ignore_errors=True)
        shutil.copytree(old_master, out)
        proc = subprocess.Popen(
            [*PRESSPLAN, "solve", str(other), "--out", str(out), "--no-plots"],
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        time.sleep(rng.uniform(0.5, 1.15) * full)  # most kills land in the late part, where the files are written
        proc.kill()
        proc.wait()
        now = state(out)
        assert now in (old, new), now
        ends["old" if now == old else "new"] += 1
    assert run(["solve", str(other), "--out", str(out), "--no-plots"]).returncode == 0
    assert state(out) == new
    assert not [p.name for p in out.parent.iterdir() if ".pressplan-" in p.name]  # leftovers cleaned
    assert ends["old"] + ends["new"] == KILL_TRIALS


@pytest.mark.skipif(sys.platform != "linux", reason="signals to child processes")
def test_ctrl_c_is_one_line_and_exit_130(tmp_path):
    proc = sweep_process(tmp_path / "o", workers=1)  # 41 solves in this process: seconds on any machine
    time.sleep(2.0)  # inside the solves
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert err.strip().splitlines() == ["pressplan: interrupted"]


def _children(pid: int) -> set[int]:
    out = set()
    for task in Path("/proc").glob("[0-9]*"):
        try:
            fields = (task / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.add(int(task.name))
    return out


@pytest.mark.skipif(sys.platform != "linux", reason="reads /proc")
def test_sigterm_ends_a_sweep_and_its_workers(tmp_path):
    proc = sweep_process(tmp_path / "s", workers=2)
    workers: set[int] = set()
    deadline = time.monotonic() + 30
    while len(workers) < 2 and time.monotonic() < deadline:
        workers |= _children(proc.pid)
        time.sleep(0.1)
    assert workers, "the sweep started no worker processes"
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143
    assert err.strip().splitlines()[-1] == "pressplan: terminated" and "Traceback" not in err
    time.sleep(0.5)
    alive = []
    for pid in workers:
        try:
            os.kill(pid, 0)
            state_line = Path(f"/proc/{pid}/stat").read_text()
            if ") Z " not in state_line:  # a zombie is already dead
                alive.append(pid)
        except (ProcessLookupError, FileNotFoundError):
            pass
    assert not alive, f"worker processes still running: {alive}"


@pytest.mark.skipif(sys.platform != "linux", reason="signals")
def test_a_signal_inside_a_deferred_block_arrives_after_it():
    """A sweep loads matplotlib while its workers solve: a SIGTERM raised inside that import (in a compiled
    extension's initialisation) made the process abort instead of exiting 143 (seen in CI under load). Inside
    ``signals_held`` the signal is held; the process's handler gets it once the block has ended."""
    from planning.solver.ipopt import signals_held

    steps, before = [], signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, signal.default_int_handler)  # Ctrl-C raises KeyboardInterrupt (the CLI's)
    try:
        _deferred_then_raised(signals_held, steps)
    finally:
        signal.signal(signal.SIGINT, before)
    assert steps == ["after the signal, inside the block"]


def _deferred_then_raised(signals_held, steps: list[str]) -> None:  # noqa: ANN001 - the context manager
    with pytest.raises(KeyboardInterrupt):
        with signals_held():
            signal.raise_signal(signal.SIGINT)
            steps.append("after the signal, inside the block")
        steps.append("after the block")  # not reached: the handler raised on the way out
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # the handler is back


class _Number:
    """A number CasADi converts by trying Python functions in turn; the first attribute it asks for sends ``signum``
    to this process (the signal's handler then runs inside CasADi's attempt, where an exception is swallowed)."""

    asked = 0

    def __init__(self, signum: int) -> None:
        self.signum = signum

    def __float__(self) -> float:
        return 2.0

    def __getattr__(self, name: str):  # noqa: ANN204 - any attribute
        type(self).asked += 1
        if type(self).asked == 1:
            os.kill(os.getpid(), self.signum)
            sum(range(1000))  # a few bytecodes: the handler runs here
        raise AttributeError(name)


@pytest.mark.skipif(sys.platform != "linux", reason="signals")
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["Ctrl-C", "SIGTERM"])
def test_a_signal_inside_casadi_code_is_delivered_after_it(signum):
    """A Ctrl-C while an NLP was built ended the run with exit 0 after the whole solve: its KeyboardInterrupt was
    raised inside a Python function CasADi's C++ called to convert an argument, and CasADi took it for "not this
    type". The command's handler (``planning.interrupts``) delivers such a signal again once that code has returned."""
    import casadi as ca

    from planning import interrupts
    from planning.interrupts import Terminated, on_signal

    expected = KeyboardInterrupt if signum == signal.SIGINT else Terminated
    numbers = (signal.SIGINT, signal.SIGTERM, signal.SIGALRM)
    before = {n: signal.getsignal(n) for n in numbers}
    _Number.asked = 0
    for n in (signal.SIGINT, signal.SIGTERM):
        signal.signal(n, on_signal)
    try:
        with pytest.raises(expected):
            ca.times(ca.SX.sym("x"), _Number(signum))  # the signal arrives inside CasADi's conversion
            deadline = time.monotonic() + 2.0
            while time.monotonic() < deadline:  # on its way after it
                time.sleep(0.001)
        assert signal.getsignal(signal.SIGALRM) == before[signal.SIGALRM]  # the retry's timer left nothing behind
        assert signal.getitimer(signal.ITIMER_REAL)[0] == 0.0 and not interrupts._waiting
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        for n, handler in before.items():
            signal.signal(n, handler)
    assert _Number.asked >= 1


def _status_caught(pid: int) -> int:
    """The signals process ``pid`` catches (a bit mask, from /proc), 0 where it is gone."""
    try:
        lines = Path(f"/proc/{pid}/status").read_text().splitlines()
    except OSError:
        return 0
    return int(next(ln.split()[1] for ln in lines if ln.startswith("SigCgt:")), 16)


def _loaded(pid: int, library: str) -> bool:
    """Whether process ``pid`` has mapped a file whose name holds ``library`` (from /proc)."""
    try:
        return library in Path(f"/proc/{pid}/maps").read_text()
    except OSError:
        return True


@pytest.mark.skipif(sys.platform != "linux", reason="reads /proc")
def test_ctrl_c_while_the_command_loads_is_one_line_and_exit_130(tmp_path):
    """The console script sets its handlers before the command's modules load (``planning.__main__``): a Ctrl-C then
    (the first few tenths of a second: pydantic not loaded yet) ends the run as one during a solve does, not with a
    traceback. (Without the early handlers SIGTERM is caught only once the command is loaded: no run is caught
    early.)"""
    caught_early = 0
    out = tmp_path / "o"
    command = [sys.executable, "-m", "planning", "solve", str(PUBLISHED_CASE), "--no-plots", "--out", str(out)]
    for attempt in range(5):
        proc = subprocess.Popen(
            command,
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )
        deadline = time.monotonic() + 30
        while not _status_caught(proc.pid) & (1 << (signal.SIGTERM - 1)) and time.monotonic() < deadline:
            time.sleep(0.0005)  # until the handlers are set
        early = not _loaded(proc.pid, "_pydantic_core")  # pydantic's, a tenth of a second into the command's loading
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
        assert proc.returncode == 130, (attempt, err)
        assert err.strip().splitlines() == ["pressplan: interrupted"]
        assert not out.exists()
        caught_early += early
        if caught_early:
            break
    assert caught_early, "no Ctrl-C arrived before pydantic loaded"


def test_the_console_scripts_module_loads_nothing_heavy():
    """``planning.__main__`` (the console script's module) loads none of the command's modules before ``run``."""
    heavy = ("planning.cli", "casadi", "numpy", "pydantic")
    probe = f"import sys, planning.__main__; print(sorted(m for m in {heavy!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


_INSIDE_CASADI = {"__name__": "casadi.test_double", "sys": sys}  # a function of this namespace runs "in CasADi"
exec("def inside(handler, signum):\n    return handler(signum, sys._getframe())", _INSIDE_CASADI)


@pytest.mark.skipif(sys.platform != "linux", reason="signals")
def test_a_signal_waits_for_casadi_at_most_its_limit_and_sigterm_goes_first(monkeypatch):
    """A signal that keeps arriving inside CasADi's code is raised there after ``RETRY_LIMIT_S`` (a Python function of
    CasADi's that ran that long would hold it for ever); of a Ctrl-C and a SIGTERM both waiting, SIGTERM is
    delivered; the retry's timer and its SIGALRM handler are gone once a signal is raised."""
    from planning import interrupts

    numbers = (signal.SIGINT, signal.SIGTERM, signal.SIGALRM)
    before = {n: signal.getsignal(n) for n in numbers}
    monkeypatch.setattr(interrupts, "_waiting", {})
    monkeypatch.setattr(interrupts, "_alarm_before", [])
    try:
        for n in (signal.SIGINT, signal.SIGTERM):
            signal.signal(n, interrupts.on_signal)
        signal.setitimer(signal.ITIMER_REAL, 0)
        assert _INSIDE_CASADI["inside"](interrupts.on_signal, signal.SIGINT) is None  # waits: the timer set
        assert signal.getsignal(signal.SIGALRM) == interrupts._deliver_waiting
        interrupts._waiting[signal.SIGINT] -= interrupts.RETRY_LIMIT_S  # as if it had waited that long
        with pytest.raises(KeyboardInterrupt):
            _INSIDE_CASADI["inside"](interrupts.on_signal, signal.SIGINT)
        assert signal.getsignal(signal.SIGALRM) == before[signal.SIGALRM] and not interrupts._waiting
        assert signal.getitimer(signal.ITIMER_REAL)[0] == 0.0
        interrupts._waiting.update({signal.SIGINT: time.monotonic(), signal.SIGTERM: time.monotonic()})
        with pytest.raises(interrupts.Terminated):
            interrupts._deliver_waiting(signal.SIGALRM, None)
            time.sleep(0.01)  # (the handler runs at the next bytecode)
        assert not interrupts._waiting
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        for n, handler in before.items():
            signal.signal(n, handler)
