"""The output folder: checked before solving, written all or nothing.

Files are written into a hidden temporary folder beside the target and moved into place only when
every one of them is complete, so an earlier run's files are replaced only on success.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np


class OutputError(OSError):
    """The output folder cannot be written; ``str()`` is a one-line message."""


def ensure_writable(out: Path) -> None:
    """Fail early (before solving) when ``out`` cannot be created or written."""
    probe = out
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir():
        raise OutputError(f"{out}: output path is not a folder ({probe} is a file)")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(f"{out}: output folder is not writable")


def write_atomic(out: Path, writers: dict[str, Callable[[Path], None]]) -> list[Path]:
    """Run each ``writers[name](path)`` into a temporary folder, then move the files into ``out``."""
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=".pressplan-", dir=out))
    except OSError as exc:
        raise OutputError(f"{out}: cannot create the output folder ({exc.strerror})") from None
    try:
        for name, write in writers.items():
            write(tmp / name)
        moved = []
        for name in writers:
            os.replace(tmp / name, out / name)
            moved.append(out / name)
        return moved
    except OSError as exc:
        raise OutputError(f"{out}: cannot write the results ({exc.strerror})") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def write_json(path: Path, data: dict) -> None:
    path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n", encoding="utf-8")


def write_table(path: Path, table: np.ndarray, columns: tuple[str, ...], comments: str | None = None) -> None:
    """CSV with a header row, after optional ``#`` comment lines."""
    head = (comments + "\n" if comments else "") + ",".join(columns)
    np.savetxt(path, table, delimiter=",", header=head, comments="", fmt="%.12g")
