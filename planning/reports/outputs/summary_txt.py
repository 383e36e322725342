"""``summary.txt``: the summary ``pressplan solve`` prints."""

from __future__ import annotations

from planning.reports.outputs import Output, Writer, Written


def _writers(w: Written) -> dict[str, Writer]:
    from planning.reports.report import summary_text

    return {"summary.txt": lambda p: p.write_text(summary_text(w.result) + "\n", encoding="utf-8")}


OUTPUT = Output("summary.txt", "summary.txt", ("summary.txt",), _writers, order=40)
