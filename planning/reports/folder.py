"""The output folder: checked before solving, replaced as a whole, never half old and half new.

A command owns a set of file names in its folder (``solve``'s from the outputs' registry,
``planning.reports.outputs.owned_files``; :data:`COMPARE_FILES`, ...).
:func:`write_atomic` builds the folder's next state beside it, in a hidden sibling folder
``.NAME.pressplan-PID-TOKEN``: the command's new files, plus hard links to every file in the folder
that the command does not own (another command's results, a note of the user's). Files the command
owns but did not write this time (last run's figures after a ``--no-plots`` run) are left out: nothing
stale survives. The two folders are then swapped in one step (Linux ``renameat2`` with
``RENAME_EXCHANGE``), so the folder is at every moment either entirely old or entirely new, whatever
kills the process; elsewhere two renames do it, and a run interrupted between them is repaired by the
next. The old state is then deleted. Leftovers of interrupted runs (sibling folders of processes that
no longer exist) are removed by the next run into the same folder.

The case file is never written: a folder that holds it under a name the command writes is refused.
A folder with sub-folders the command did not write is refused too (its files could not be carried
over by links), as is one with more than :data:`MAX_FOREIGN_FILES` foreign files: choose another.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import fnmatch
import json
import os
import re
import secrets
import shutil
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

COMPARE_FILES = ("comparison.json", "comparison.md")
LAWS_FILES = ("laws.json", "laws.md", "laws_overlay.*")
TRADEOFF_FILES = ("tradeoff.csv", "tradeoff.json", "tradeoff.png")
MAX_FOREIGN_FILES = 200
_LEFTOVER = re.compile(r"^\.(?P<name>.+)\.pressplan-(?P<pid>\d+)-(?P<kind>new|old)-[0-9a-f]+$")
_LEGACY_TEMP = re.compile(r"^\.pressplan-[A-Za-z0-9_]+$")  # temp folders of earlier versions, inside the folder
_RENAME_EXCHANGE = 2


class OutputError(OSError):
    """The output folder cannot be written; ``str()`` is a one-line message."""


def ensure_writable(out: Path) -> None:
    """Fail early (before solving) when ``out`` cannot be created or written."""
    out = Path(out)
    probe = out
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir():
        raise OutputError(f"{out}: output path is not a folder ({probe} is a file)")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(f"{out}: output folder is not writable")
    if out.exists() and not os.access(out.resolve().parent, os.W_OK | os.X_OK):
        raise OutputError(f"{out}: the folder that holds it is not writable (the output folder is replaced whole)")


def check_case_outside(out: Path, case_path: str | Path, owned: Iterable[str]) -> None:
    """Refuse an output folder that holds the case file under a name the command writes."""
    case = Path(case_path).resolve()
    if case.parent == Path(out).resolve() and _owned(case.name, tuple(owned)):
        raise OutputError(
            f"{out}: holds the case file {Path(case_path).name}, which this command would replace; choose another --out"
        )


def write_atomic(
    out: Path,
    writers: dict[str, Callable[[Path], None]],
    owned: Iterable[str] | None = None,
    keep: Path | str | None = None,
) -> list[Path]:
    """Replace the folder ``out`` as a whole: ``writers[name](path)`` write the new files; files that
    match the glob patterns ``owned`` (default: the names written) and were not written now are
    dropped; every other file is kept. ``keep``: a file (the case) that must not be replaced."""
    out = Path(out)
    owned = tuple(owned) if owned is not None else tuple(writers)
    if keep is not None:
        check_case_outside(out, keep, owned)
    target = out.resolve()
    _clean_leftovers(target)
    carried = _foreign_files(out, target, owned, set(writers))
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{out}: cannot create the output folder ({exc.strerror})") from None
    staging = _sibling(target, "new")
    try:
        staging.mkdir()
        for name, write in writers.items():
            write(staging / name)
        for name in carried:
            _link_or_copy(target / name, staging / name)
        _swap_in(staging, target)
    except OSError as exc:
        raise OutputError(f"{out}: cannot write the results ({exc.strerror or exc})") from None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return [out / name for name in writers]


def _owned(name: str, patterns: tuple[str, ...]) -> bool:
    return any(fnmatch.fnmatchcase(name, pattern) for pattern in patterns)


def _foreign_files(out: Path, target: Path, owned: tuple[str, ...], written: set[str]) -> list[str]:
    """Names in the folder to carry over: neither owned nor written now."""
    if not target.exists():
        return []
    if not target.is_dir():
        raise OutputError(f"{out}: output path is not a folder")
    carried = []
    try:
        entries = sorted(os.scandir(target), key=lambda e: e.name)
    except OSError as exc:
        raise OutputError(f"{out}: cannot read the output folder ({exc.strerror})") from None
    for entry in entries:
        if entry.name in written or _owned(entry.name, owned):
            if entry.is_dir(follow_symlinks=False):
                raise OutputError(f"{out}: {entry.name} is a folder where pressplan writes a file")
            continue
        if _LEGACY_TEMP.match(entry.name) and entry.is_dir(follow_symlinks=False):
            shutil.rmtree(entry.path, ignore_errors=True)  # an interrupted run of an earlier version
            continue
        if entry.is_dir(follow_symlinks=False):
            raise OutputError(f"{out}: holds a folder pressplan did not write ({entry.name}); choose another --out")
        carried.append(entry.name)
    if len(carried) > MAX_FOREIGN_FILES:
        raise OutputError(f"{out}: holds {len(carried)} files pressplan did not write; choose another --out")
    return carried


def _sibling(target: Path, kind: str) -> Path:
    return target.parent / f".{target.name}.pressplan-{os.getpid()}-{kind}-{secrets.token_hex(4)}"


def _link_or_copy(src: Path, dst: Path) -> None:
    if src.is_symlink():
        os.symlink(os.readlink(src), dst)
        return
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one step (Linux renameat2 RENAME_EXCHANGE); False where not available."""
    libc_name = ctypes.util.find_library("c")
    if libc_name is None:
        return False
    libc = ctypes.CDLL(libc_name, use_errno=True)
    fn = getattr(libc, "renameat2", None)
    if fn is None:
        return False
    at_fdcwd = -100
    rc = fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), _RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (38, 22, 95):  # ENOSYS, EINVAL, EOPNOTSUPP: the file system cannot exchange
        return False
    raise OSError(err, os.strerror(err))


def _swap_in(staging: Path, target: Path) -> None:
    """Make ``staging`` the folder ``target``; the old folder's contents end in ``staging`` (deleted by
    the caller)."""
    if not target.exists():
        os.rename(staging, target)
        return
    if _exchange(staging, target):
        return
    old = _sibling(target, "old")
    os.rename(target, old)
    os.rename(staging, target)  # a kill between the two renames is repaired by _clean_leftovers
    os.rename(old, staging)


def _clean_leftovers(target: Path) -> None:
    """Remove the sibling folders of interrupted runs into ``target`` (their process is gone); put an
    old folder back when a run was interrupted between the two renames of the fallback swap."""
    parent = target.parent
    if not parent.is_dir():
        return
    with contextlib.suppress(OSError):
        for entry in os.scandir(parent):
            m = _LEFTOVER.match(entry.name)
            if not m or m["name"] != target.name or _alive(int(m["pid"])):
                continue
            if m["kind"] == "old" and not target.exists():
                os.rename(entry.path, target)
            else:
                shutil.rmtree(entry.path, ignore_errors=True)


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def write_json(path: Path, data: dict) -> None:
    path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n", encoding="utf-8")


def write_table(path: Path, table: np.ndarray, columns: tuple[str, ...], comments: str | None = None) -> None:
    """CSV with a header row, after optional ``#`` comment lines."""
    head = (comments + "\n" if comments else "") + ",".join(columns)
    np.savetxt(path, table, delimiter=",", header=head, comments="", fmt="%.12g")
