"""Where the time of a sweep or a trade-off goes: each point stamped where and when it was solved, and the
run's own marks (start-up, the second pass, the writing) put together as ``sweep.json``'s and
``tradeoff.json``'s ``timeline``.

A point's stamp is taken by the worker that solves it (``stamp``: its process, and the wall-clock times it
started and ended, seconds since the epoch, so that points of different processes on one machine line up).
The run's **serial part** is what no worker shares: from the run's start to the first point's start
(imports, the NLP builds before the workers fork), from the last point's end to the run's end (writing the
outputs), and any work that runs in one process (the sweep's second pass finding the points a neighbour's
plan may improve; their re-solves run on the workers). A worker's **idle** time is the
time between the first point's start and the last point's end in which it held no point.
"""

from __future__ import annotations

import os
import socket
import time
from dataclasses import dataclass, field
from typing import Any


def worker_name() -> str:
    """This process: ``host:pid``."""
    return f"{socket.gethostname()}:{os.getpid()}"


def stamp(row: dict[str, Any], started: float) -> None:
    """Mark ``row`` as solved by this process from ``started`` (``time.time()``) until now."""
    row["worker"] = worker_name()
    row["t_start"] = started
    row["t_end"] = time.time()


@dataclass
class Timeline:
    """The marks of one run (seconds since the epoch) and its stamped points' rows."""

    started: float = field(default_factory=time.time)
    marks: dict[str, float] = field(default_factory=dict)
    spans: dict[str, float] = field(default_factory=dict)  # durations [s] added up by name

    def mark(self, name: str) -> None:
        """Record ``name`` at this moment."""
        self.marks[name] = time.time()

    def add(self, name: str, seconds: float) -> None:
        """Add ``seconds`` to the duration ``name``."""
        self.spans[name] = self.spans.get(name, 0.0) + seconds

    def as_dict(self, rows: list[dict[str, Any]], blocks: list[list[int]] | None = None) -> dict[str, Any]:
        """The timeline of the stamped ``rows`` (rows of earlier runs carry no stamp) and ``blocks`` (each
        block's point indices, in the order the work was dealt): times in seconds from the run's start."""
        stamped = [r for r in rows if "t_start" in r]
        end = self.marks.get("end", time.time())
        out: dict[str, Any] = {"wall_s": end - self.started, "points": len(stamped)}
        if not stamped:
            return out
        first = min(r["t_start"] for r in stamped)
        last = max(r["t_end"] for r in stamped)
        second = self.marks.get("second_pass_end", last) - self.marks.get("second_pass_start", last)
        workers: dict[str, list[dict[str, Any]]] = {}
        for r in stamped:
            workers.setdefault(r["worker"], []).append(r)
        busy = {w: sum(r["t_end"] - r["t_start"] for r in rs) for w, rs in workers.items()}
        span = last - first
        out.update(
            startup_s=first - self.started,
            points_s=span,
            second_pass_s=second,
            writing_s=end - self.marks.get("second_pass_end", last),
            solve_time_sum_s=sum(r["t_end"] - r["t_start"] for r in stamped),
            workers=[
                {"worker": w, "points": len(rs), "busy_s": busy[w], "idle_s": max(span - busy[w], 0.0)}
                for w, rs in sorted(workers.items())
            ],
        )
        # the second pass: its finding runs in this process (serial), its re-solves on the workers; the serial
        # part is everything after the last point but the re-solves on the workers
        out["second_pass_serial_s"] = min(self.spans.get("second_pass_serial_s", second), second)
        out["serial_s"] = out["startup_s"] + (end - last) - (second - out["second_pass_serial_s"])
        out["efficiency"] = out["solve_time_sum_s"] / (len(workers) * span) if span > 0 else 1.0
        if blocks:
            by_index = {r["index"]: r for r in stamped}
            out["blocks"] = [
                {
                    "first_index": b[0],
                    "points": len(b),
                    "worker": by_index[b[0]]["worker"],
                    "start_s": min(by_index[i]["t_start"] for i in b) - self.started,
                    "duration_s": max(by_index[i]["t_end"] for i in b) - min(by_index[i]["t_start"] for i in b),
                }
                for b in blocks
                if all(i in by_index for i in b)
            ]
        return out
