"""``pressplan compare``: the published solution beside ours, quantity by quantity, and the
published numbers checked against each other (``planning.reports.source_solution``)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planning.model.case import KEY_POINT_NAMES, Case, PublishedSolution
from planning.reports.report import key_points
from planning.reports.source_solution import consistency, paper_solution, rebuild_profile, transfer_speed_rpm
from planning.solver.solution import Solution

SYMBOLS = {
    "x1_s": ("x1", "s", "start of the feed acceleration"),
    "x2_s": ("x2", "s", "feed peak speed"),
    "x3_s": ("x3", "s", "return peak speed"),
    "x4_s": ("x4", "s", "end of the return deceleration"),
    "x5_s": ("x5", "s", "period"),
    "wm1_rpm": ("wm1", "rpm", "feed peak speed"),
    "wm2_rpm": ("wm2", "rpm", "return peak speed"),
    "T1_s": ("T1", "s", "feed acceleration sub-segment"),
    "T5_s": ("T5", "s", "feed deceleration sub-segment"),
    "T9_s": ("T9", "s", "draw"),
    "T10_s": ("T10", "s", "return acceleration sub-segment"),
    "T14_s": ("T14", "s", "return deceleration sub-segment"),
    "J_rpm_s2": ("J", "rpm/s^2", "jerk (ours: feed; return jerk separate)"),
}


def comparison(case: Case, ours_published: Solution, ours_free: Solution) -> dict[str, Any]:
    """Plain data for the comparison (engineering units)."""
    pub = case.published
    kp_ours = key_points(ours_published)
    rows_kp = []
    for i, name in enumerate(KEY_POINT_NAMES):
        ref = getattr(pub.key_points, name) if pub and pub.key_points else None
        for qty, key, unit in (("S", "height_mm", "mm"), ("v", "slider_speed_mm_s", "mm/s")):
            printed = getattr(ref, key) if ref is not None else None
            if printed is None:
                continue
            ours = kp_ours[i][key]
            rows_kp.append(
                {
                    "name": f"{qty}{i + 1} ({name})",
                    "unit": unit,
                    "published": printed,
                    "computed": ours,
                    "difference": ours - printed,
                }
            )
    x_pub = pub.solution.model_dump() if pub and pub.solution else {}
    x_a = paper_solution(ours_published.plan)
    x_b = paper_solution(ours_free.plan)
    rows_x = [
        {
            "symbol": sym,
            "unit": unit,
            "meaning": meaning,
            "published": x_pub.get(key),
            "ours_published": x_a[key],
            "ours_free": x_b[key],
        }
        for key, (sym, unit, meaning) in SYMBOLS.items()
    ]
    rows_x.append(
        {
            "symbol": "J_return",
            "unit": "rpm/s^2",
            "meaning": "return jerk",
            "published": None,
            "ours_published": x_a["J_return_rpm_s2"],
            "ours_free": x_b["J_return_rpm_s2"],
        }
    )
    derived = {}
    if pub and pub.solution:
        v = {k: float(getattr(pub.solution, k)) for k in PublishedSolution.model_fields}
        derived["transfer speed w1 implied by wm1, J, T1 [rpm]"] = transfer_speed_rpm(v)
        prof = rebuild_profile(case)
        if prof is not None:
            t = np.linspace(0.0, prof.duration, int(math.ceil(prof.duration / 1e-3)) + 1)
            th, om, al, je = prof.at_time(t)
            a = case.machine.slider(th, om, al, je)[2]
            derived["max |slider acceleration| of the rebuilt published profile [mm/s^2]"] = float(np.max(np.abs(a)))
    return {
        "case": case.name,
        "source": case.source,
        "spm": {
            "published": pub.spm if pub else None,
            "ours_published_placement": ours_published.plan.spm,
            "ours_free_placement": ours_free.plan.spm,
        },
        "structure": {"published_placement": ours_published.plan.structure, "free_placement": ours_free.plan.structure},
        "key_points": rows_kp,
        "solution": rows_x,
        "published_consistency": [c.as_dict() for c in consistency(case)],
        "derived": derived,
        "notes": [
            "Times x1..x5 from TDC; ours from the verified plans. Ours have one jerk per S-curve (feed J shown "
            "under J, return J under J_return); the paper prints one J for both.",
            "A published quantity is flagged inconsistent when recomputing it from other published numbers "
            "differs by more than their printed digits allow (half a unit of each last digit, propagated).",
        ],
    }


def _fmt(x: Any, digits: int = 4) -> str:
    if x is None:
        return "-"
    if isinstance(x, float):
        return f"{x:.{digits}f}"
    return str(x)


def comparison_markdown(data: dict[str, Any]) -> str:
    """``comparison.md``: the comparison as Markdown tables."""
    s = data["spm"]
    st_pub, st_free = data["structure"]["published_placement"], data["structure"]["free_placement"]
    lines = [
        f"# {data['case']}: published vs pressplan",
        "",
        f"Source: {data['source']}",
        "",
        "| | published | ours, published placement | ours, free placement |",
        "|---|---:|---:|---:|",
        f"| strokes per minute | {_fmt(s['published'], 2)} | {_fmt(s['ours_published_placement'], 3)} | "
        f"{_fmt(s['ours_free_placement'], 3)} |",
        "",
        f"Structure, published placement: theta1 in {st_pub['closing']}, theta4 in {st_pub['opening']}. "
        f"Free placement: theta1 in {st_free['closing']}, theta4 in {st_free['opening']}.",
        "",
        "## Key points (exact kinematics at the draw speed)",
        "",
        "| quantity | unit | published | computed | difference |",
        "|---|---|---:|---:|---:|",
    ]
    for r in data["key_points"]:
        lines.append(
            f"| {r['name']} | {r['unit']} | {_fmt(r['published'], 1)} | {_fmt(r['computed'], 3)} | "
            f"{r['difference']:+.3f} |"
        )
    lines += [
        "",
        "## Solution X",
        "",
        "| symbol | unit | meaning | published | ours, published placement | ours, free placement |",
        "|---|---|---|---:|---:|---:|",
    ]
    for r in data["solution"]:
        lines.append(
            f"| {r['symbol']} | {r['unit']} | {r['meaning']} | {_fmt(r['published'], 3)} | "
            f"{_fmt(r['ours_published'])} | {_fmt(r['ours_free'])} |"
        )
    lines += [
        "",
        "## The published numbers checked against each other",
        "",
        "| quantity | unit | printed | recomputed | difference | printed digits allow | verdict | from |",
        "|---|---|---:|---:|---:|---:|---|---|",
    ]
    for c in data["published_consistency"]:
        verdict = "**inconsistent**" if c["verdict"] == "inconsistent" else c["verdict"]
        lines.append(
            f"| {c['name']} | {c['unit']} | {_fmt(c['printed'])} | {_fmt(c['recomputed'])} | "
            f"{c['difference']:+.4f} | {c['allowance']:.4f} | {verdict} | {c['formula']} |"
        )
    if data["derived"]:
        lines += ["", "## Derived from the published solution", ""]
        lines += [f"- {k}: {v:.3f}" for k, v in data["derived"].items()]
    lines += ["", "## Notes", ""] + [f"- {n}" for n in data["notes"]]
    return "\n".join(lines) + "\n"


def comparison_text(data: dict[str, Any]) -> str:
    """Console version of the comparison."""
    s = data["spm"]
    out = [
        f"{data['case']}: strokes/min published {_fmt(s['published'], 2)} | ours (published placement) "
        f"{s['ours_published_placement']:.3f} | ours (free placement) {s['ours_free_placement']:.3f}",
        "",
        f"  {'key point':<18} {'published':>10} {'computed':>10} {'diff':>8}",
    ]
    for r in data["key_points"]:
        out.append(
            f"  {r['name']:<18} {r['published']:10.1f} {r['computed']:10.3f} {r['difference']:+8.3f} {r['unit']}"
        )
    out += ["", f"  {'X':<9} {'unit':<8} {'published':>10} {'ours pub.':>10} {'ours free':>10}"]
    for r in data["solution"]:
        out.append(
            f"  {r['symbol']:<9} {r['unit']:<8} {_fmt(r['published'], 3):>10} {_fmt(r['ours_published']):>10} "
            f"{_fmt(r['ours_free']):>10}"
        )
    checks = data["published_consistency"]
    counts = {v: sum(c["verdict"] == v for c in checks) for v in ("inconsistent", "undecided")}
    out += [
        "",
        f"  the published solution checked against itself: {counts['inconsistent']} of {len(checks)} quantities "
        f"inconsistent, {counts['undecided']} undecided (their printed digits allow more than a quarter of the value)",
    ]
    for c in checks:
        out.append(
            f"  {c['verdict'].upper() if c['verdict'] == 'inconsistent' else c['verdict']:<12} {c['name']:<36} "
            f"printed {c['printed']:9.4f} recomputed {c['recomputed']:9.4f} ({c['difference']:+.4f} {c['unit']}; "
            f"the printed digits allow ±{c['allowance']:.4f}) from {c['formula']}"
        )
    for k, v in data["derived"].items():
        out.append(f"  {k}: {v:.3f}")
    return "\n".join(out)
