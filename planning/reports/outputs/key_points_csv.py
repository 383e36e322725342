"""``key_points.csv``: the four key points of the plan (θ1 closing, θ2 draw start, θ3 draw end, θ4 opening): the
crank angle [deg from TDC], the time [s from TDC], the slide's height [mm above BDC] and speed [mm/s, upward
positive, as in ``trajectory.csv``] and the crank speed [rpm] there, from the plan's evaluation."""

from __future__ import annotations

import csv

from planning.reports.outputs import Output, Writer, Written

COLUMNS = ("key_point", "angle_deg", "time_s", "slider_height_mm", "slider_speed_mm_s", "crank_speed_rpm")


def _writers(w: Written) -> dict[str, Writer]:
    rows = [
        (
            k["name"],
            repr(k["angle_deg"]),
            repr(k["time_s"]),
            repr(k["height_mm"]),
            repr(k["slider_speed_mm_s"] if k["direction"] == "up" else -k["slider_speed_mm_s"]),
            repr(k["crank_speed_rpm"]),
        )
        for k in w.result["key_points"]
    ]

    def write(path) -> None:  # noqa: ANN001 - a Path
        with open(path, "w", newline="", encoding="utf-8") as fh:
            table = csv.writer(fh)
            table.writerow(COLUMNS)
            table.writerows(rows)

    return {"key_points.csv": write}


OUTPUT = Output("key_points.csv", "key_points.csv", ("key_points.csv",), _writers, order=45, page=True)
