"""Draw the sketches of the link drive and the knuckle joint in docs/ (run from the project root).

Each is the shipped case's mechanism at one crank angle, drawn from ``Mechanism.joints`` (the same closed
form the planner uses), every dimension labelled with its case key and the oracle's letter.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from planning.model.case_file import read_case  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
LINK = "#34495e"
DIM = "#c0392b"


def point(joints: dict, name: str) -> np.ndarray:
    x, y = joints[name]
    return np.array([float(x), float(y)])


def bar(ax, p: np.ndarray, q: np.ndarray, label: str, offset: tuple[float, float] = (0, 0)) -> None:
    ax.plot([p[0], q[0]], [p[1], q[1]], color=LINK, lw=3, solid_capstyle="round", zorder=2)
    mid = (p + q) / 2
    ax.annotate(label, mid, xytext=offset, textcoords="offset points", color=LINK, fontsize=9, ha="center")


def dimension(ax, p: np.ndarray, q: np.ndarray, label: str, offset: tuple[float, float] = (0, 0)) -> None:
    ax.annotate("", q, p, arrowprops={"arrowstyle": "<->", "color": DIM, "lw": 1})
    ax.annotate(label, (p + q) / 2, xytext=offset, textcoords="offset points", color=DIM, fontsize=9, ha="center")


def joint(ax, p: np.ndarray, fixed: bool = False, label: str = "") -> None:
    ax.plot(*p, "o", ms=7, mfc=LINK if fixed else "white", mec=LINK, zorder=3)
    if fixed:
        ax.plot(*p, marker=(3, 0, 0), ms=14, mfc="none", mec=LINK, zorder=1, transform=ax.transData)
    if label:
        ax.annotate(label, p, xytext=(8, 6), textcoords="offset points", fontsize=8, color="#555")


def slide(ax, p: np.ndarray, width: float) -> None:
    ax.add_patch(plt.Rectangle((p[0] - width / 2, p[1] - width / 4), width, width / 2, fc="#5d8aa8", ec=LINK))
    ax.axvline(p[0], color="#99a", ls="--", lw=0.8, zorder=0)


def link_drive() -> None:
    case = read_case(ROOT / "cases" / "link-drive-side-panel.yaml")
    m = case.machine
    j = m.joints(np.array(math.radians(100.0)))
    o, a, b, c, p, s = (
        point(j, n) for n in ("crank centre", "crank pin", "rocker joint", "rod joint", "pivot", "slide")
    )
    fig, ax = plt.subplots(figsize=(7.5, 7.5))
    ax.fill(*zip(a, b, c, strict=True), fc="#aab7c4", alpha=0.4, ec="none")
    bar(ax, o, a, "a  crank_radius_mm", (70, 10))
    bar(ax, a, b, "b  ternary_rocker_side_mm", (10, 10))
    bar(ax, a, c, "m  ternary_rod_side_mm", (85, 0))
    bar(ax, b, c, "", (0, 0))
    bar(ax, p, b, "c  rocker_mm", (-45, 0))
    bar(ax, c, s, "g  rod_length_mm", (60, 0))
    low = p[1] - 170
    dimension(ax, np.array([p[0], low]), np.array([o[0], low]), "d  rocker_pivot_x_mm", (0, -14))
    ax.plot([p[0], p[0]], [p[1], low], color=DIM, lw=0.6, ls=":")
    ax.plot([o[0], o[0]], [o[1], low], color=DIM, lw=0.6, ls=":")
    left = p[0] - 170
    dimension(ax, np.array([left, p[1]]), np.array([left, o[1]]), "f  rocker_pivot_y_mm", (-62, 0))
    ax.plot([left, o[0]], [o[1], o[1]], color=DIM, lw=0.6, ls=":")
    ang_b = math.degrees(math.atan2(*(b - a)[::-1]))
    ang_c = math.degrees(math.atan2(*(c - a)[::-1]))
    arc = matplotlib.patches.Arc(a, 260, 260, theta1=ang_b, theta2=ang_c, color=DIM)
    ax.add_patch(arc)
    ax.annotate("tht  ternary_angle_deg", a, xytext=(-40, -40), textcoords="offset points", color=DIM, fontsize=9)
    ax.annotate(
        "h  slide_offset_mm: the slide's line at x = h",
        (s[0], s[1]),
        xytext=(-60, -28),
        textcoords="offset points",
        color=DIM,
        fontsize=9,
    )
    for name, q, fixed in (
        ("crank centre", o, True),
        ("rocker pivot (-d, -f)", p, True),
        ("", a, False),
        ("", b, False),
        ("", c, False),
    ):
        joint(ax, q, fixed, name)
    slide(ax, s, 180)
    ax.set_title("link drive (mechpress.ld.LD): crank angle counter-clockwise from +x", fontsize=10)
    finish(fig, ax, "link-drive.svg")


def knuckle_joint() -> None:
    case = read_case(ROOT / "cases" / "knuckle-joint-coining.yaml")
    m = case.machine
    j = m.joints(np.array(math.radians(110.0)))
    o, a, k, p, s = (point(j, n) for n in ("crank centre", "crank pin", "knuckle", "pivot", "slide"))
    fig, ax = plt.subplots(figsize=(7.5, 7.5))
    bar(ax, o, a, "a  crank_radius_mm", (-45, 14))
    bar(ax, a, k, "b  rod_length_mm", (0, 10))
    bar(ax, p, k, "c  rocker_mm", (-45, 0))
    bar(ax, k, s, "g  main_rod_mm", (50, 0))
    dimension(ax, np.array([o[0], o[1] - 80]), np.array([p[0], o[1] - 80]), "d  rocker_pivot_x_mm", (0, -14))
    right = p[0] + 260
    dimension(ax, np.array([right, o[1]]), np.array([right, p[1]]), "e  rocker_pivot_y_mm", (62, 0))
    ax.plot([o[0], right], [o[1], o[1]], color=DIM, lw=0.6, ls=":")
    ax.plot([p[0], right], [p[1], p[1]], color=DIM, lw=0.6, ls=":")
    ax.annotate(
        "h  slide_offset_mm: the slide's line at x = d + h",
        (s[0], s[1]),
        xytext=(-60, -28),
        textcoords="offset points",
        color=DIM,
        fontsize=9,
    )
    for name, q, fixed in (
        ("crank centre", o, True),
        ("rocker pivot (d, e)", p, True),
        ("", a, False),
        ("knuckle", k, False),
    ):
        joint(ax, q, fixed, name)
    slide(ax, s, 160)
    ax.set_title(
        "knuckle joint (presslink ModularKnuckleJoint, f = c): crank angle counter-clockwise from +x", fontsize=10
    )
    finish(fig, ax, "knuckle-joint.svg")


def finish(fig, ax, name: str) -> None:  # noqa: ANN001
    ax.set_aspect("equal")
    ax.margins(0.18)
    ax.set_xlabel("x [mm] from the crank centre")
    ax.set_ylabel("y [mm], up")
    ax.grid(alpha=0.2)
    fig.tight_layout()
    fig.savefig(ROOT / "docs" / name, metadata={"Date": None})
    plt.close(fig)
    print(f"wrote docs/{name}")


if __name__ == "__main__":
    link_drive()
    knuckle_joint()
