"""The source's own solution, rebuilt and checked against itself.

The paper prints X = [x1..x5, wm1, wm2, T1, T5, T9, T10, T14, J] (times from TDC [s], speeds [rpm],
J [rpm/s^2]) and the relations under its Fig. 6. Here each published quantity that can also be
computed from the other published ones is recomputed, and flagged as inconsistent when the two
differ by more than the printed digits allow (half a unit of each printed number's last digit,
propagated linearly through the formula).

The crank motion is rebuilt "as far as it can be": constant w1 up to x1, the feed S-curve
w1 -> wm1 -> w2 over 4 T1 + 4 T5, the draw over T9, the return S-curve w2 -> wm2 -> w1 over
4 T10 + 4 T14, constant w1 up to x5. Each half gets the jerk that makes it meet the printed speeds
(the paper's single J does not; see the checks), so the rebuilt profile is acceleration-continuous
but need not sweep 360 deg or meet the key angles.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from planning.model.case import RPM, Case, PublishedSolution
from planning.model.laws import improved_scurve as sc
from planning.model.plan import Plan
from planning.model.profile import Profile, Segment
from planning.tolerances import HALF_ULP_REL, SAME_RELATIVE


def half_unit(value: float) -> float:
    """Half a unit of the last printed digit of ``value`` (as written in the case file)."""
    text = repr(float(value))
    if "e" in text or "E" in text:
        return abs(value) * HALF_ULP_REL
    decimals = len(text.split(".")[1].rstrip("0")) if "." in text else 0
    return 0.5 * 10.0 ** (-decimals)


UNDECIDED_SHARE = 0.25  # a check whose printed digits allow more than this share of the value decides nothing


@dataclass(frozen=True)
class Consistency:
    """One published quantity against its value recomputed from other published quantities."""

    name: str
    printed: float
    recomputed: float
    unit: str
    allowance: float
    formula: str
    kind: str = "equal"  # "equal", or "at least" (the recomputed value must reach the printed one)

    @property
    def difference(self) -> float:
        return self.recomputed - self.printed

    @property
    def consistent(self) -> bool:
        if self.kind == "at least":
            return self.difference >= -self.allowance - SAME_RELATIVE
        return abs(self.difference) <= self.allowance + SAME_RELATIVE

    @property
    def verdict(self) -> str:
        """``inconsistent`` (the difference is beyond what the printed digits allow), ``undecided`` (it is
        within, but the digits allow more than :data:`UNDECIDED_SHARE` of the value: the check says
        nothing), else ``consistent``."""
        if not self.consistent:
            return "inconsistent"
        if self.allowance > UNDECIDED_SHARE * abs(self.printed):
            return "undecided"
        return "consistent"

    def as_dict(self) -> dict:
        return {
            "verdict": self.verdict,
            "name": self.name,
            "printed": self.printed,
            "recomputed": self.recomputed,
            "difference": self.difference,
            "allowance": self.allowance,
            "unit": self.unit,
            "consistent": self.consistent,
            "kind": self.kind,
            "formula": self.formula,
        }


def _propagate(f: Callable[[dict[str, float]], float], values: dict[str, float], names: list[str]) -> float:
    """Linear propagation of the printed rounding of ``names`` through ``f``."""
    total = 0.0
    for n in names:
        h = half_unit(values[n])
        if h == 0:
            continue
        up, dn = dict(values), dict(values)
        up[n] += h
        dn[n] -= h
        total += abs(f(up) - f(dn)) / 2
    return total


def _inputs(case: Case) -> dict[str, float]:
    x = case.published.solution
    k = case.key_points
    vals = {f: float(getattr(x, f)) for f in PublishedSolution.model_fields}
    vals.update(theta1=k.closing_deg, theta2=k.draw_start_deg, theta3=k.draw_end_deg, theta4=k.opening_deg)
    vals["w2_rpm"] = float(case.process.draw_speed_rpm) if case.process.draw_speed_rpm else math.nan
    vals["T0_s"] = case.process.transfer_time_s
    if case.published.spm is not None:
        vals["spm"] = case.published.spm
    return vals


def transfer_speed_rpm(v: dict[str, float]) -> float:
    """w1 [rpm] implied by wm1, J and T1 (Eq. 13: wm1 - w1 = 11/3 J T1^2)."""
    return v["wm1_rpm"] - sc.speed_change(v["J_rpm_s2"], v["T1_s"])


def rebuild_profile(case: Case) -> Profile | None:
    """The published crank motion from TDC (see the module docstring); None without a solution."""
    if case.published is None or case.published.solution is None or case.process.draw_speed_rpm is None:
        return None
    v = _inputs(case)
    w1 = transfer_speed_rpm(v) * RPM
    wm1, wm2, w2 = v["wm1_rpm"] * RPM, v["wm2_rpm"] * RPM, v["w2_rpm"] * RPM
    T1, T5, T9, T10, T14 = (v[k] for k in ("T1_s", "T5_s", "T9_s", "T10_s", "T14_s"))

    def jerk(dv: float, T: float) -> float:
        return dv / (sc.SPEED_GAIN * T**2)

    segs = [Segment("transfer:dwell", v["x1_s"], 0.0, 0.0)]
    segs += sc.accel_half(T1, jerk(wm1 - w1, T1), "feed:accel")
    segs += sc.decel_half(T5, jerk(wm1 - w2, T5), "feed:decel")
    segs.append(Segment("draw:constant", T9, 0.0, 0.0))
    segs += sc.accel_half(T10, jerk(wm2 - w2, T10), "return:accel")
    segs += sc.decel_half(T14, jerk(wm2 - w1, T14), "return:decel")
    used = sum(float(s.duration) for s in segs)
    segs.append(Segment("transfer:dwell", max(v["x5_s"] - used, 0.0), 0.0, 0.0))
    return Profile(tuple(segs), 0.0, w1)


def _draw_time(u: dict[str, float]) -> float:
    return math.radians(u["theta3"] - u["theta2"]) / (u["w2_rpm"] * RPM)


class Relation(NamedTuple):
    """A relation under the paper's Fig. 6: ``name``, the ``printed`` value (a function of the printed
    numbers; ``printed_key`` the number itself, None when it is a difference), ``unit``, the ``relation``
    giving it from other printed numbers ``uses``, the ``formula`` in words, and whether it ``needs_w2``
    (the draw speed)."""

    name: str
    printed_key: str | None
    printed: Callable[[dict[str, float]], float]
    unit: str
    relation: Callable[[dict[str, float]], float]
    uses: list[str]
    formula: str
    needs_w2: bool = False


RELATIONS = (
    Relation("T9 (draw time)", "T9_s", lambda v: v["T9_s"], "s", _draw_time, ["theta2", "theta3", "w2_rpm"],
             "(theta3 - theta2) / w2", needs_w2=True),
    Relation("x2 (feed peak)", "x2_s", lambda v: v["x2_s"], "s", lambda u: u["x1_s"] + 4 * u["T1_s"],
             ["x1_s", "T1_s"], "x1 + 4 T1"),
    Relation("x3 (return peak)", "x3_s", lambda v: v["x3_s"], "s",
             lambda u: u["x2_s"] + 4 * u["T5_s"] + u["T9_s"] + 4 * u["T10_s"], ["x2_s", "T5_s", "T9_s", "T10_s"],
             "x2 + 4 T5 + T9 + 4 T10 (t2 = x2 + 4 T5, t3 = t2 + T9, x3 = t3 + 4 T10)"),
    Relation("x4 (end of return)", "x4_s", lambda v: v["x4_s"], "s", lambda u: u["x3_s"] + 4 * u["T14_s"],
             ["x3_s", "T14_s"], "x3 + 4 T14 (t4 = x3 + 3 T14, x4 = t4 + T14)"),
    Relation("SPM", "spm", lambda v: v["spm"], "1/min", lambda u: 60.0 / u["x5_s"], ["x5_s"], "60 / x5"),
    Relation("wm1 - w2 (feed deceleration)", None, lambda v: v["wm1_rpm"] - v["w2_rpm"], "rpm",
             lambda u: sc.speed_change(u["J_rpm_s2"], u["T5_s"]), ["J_rpm_s2", "T5_s"], "11/3 J T5^2 (Eq. 13)",
             needs_w2=True),
    Relation("wm2 - w2 (return acceleration)", None, lambda v: v["wm2_rpm"] - v["w2_rpm"], "rpm",
             lambda u: sc.speed_change(u["J_rpm_s2"], u["T10_s"]), ["J_rpm_s2", "T10_s"], "11/3 J T10^2 (Eq. 13)",
             needs_w2=True),
    Relation("wm2 - w1 (return deceleration)", None, lambda v: v["wm2_rpm"] - transfer_speed_rpm(v), "rpm",
             lambda u: sc.speed_change(u["J_rpm_s2"], u["T14_s"]), ["J_rpm_s2", "T14_s"],
             "11/3 J T14^2, with w1 = wm1 - 11/3 J T1^2"),
)  # fmt: skip


def consistency(case: Case) -> list[Consistency]:
    """Every published quantity that other published quantities also determine."""
    if case.published is None or case.published.solution is None:
        return []
    v = _inputs(case)
    out: list[Consistency] = []
    for r in RELATIONS:
        if (r.needs_w2 and math.isnan(v["w2_rpm"])) or (r.printed_key == "spm" and "spm" not in v):
            continue
        allowance = _propagate(r.relation, v, r.uses) + (half_unit(v[r.printed_key]) if r.printed_key else 0.0)
        out.append(Consistency(r.name, r.printed(v), float(r.relation(v)), r.unit, allowance, r.formula))
    prof = rebuild_profile(case)
    if prof is not None:
        out += _rebuilt_checks(case, v, prof)
    return out


def _rebuilt_checks(case: Case, v: dict[str, float], prof: Profile) -> list[Consistency]:
    """The rebuilt profile against the published angles and transfer time."""
    allowance = _angle_allowance(case)

    def angle_at(t: float) -> float:
        return math.degrees(float(prof.at_time(np.array([t]))[0][0]))

    t1 = v["x1_s"] + v["T1_s"]
    t2 = v["x2_s"] + 4 * v["T5_s"]
    t4 = v["x3_s"] + 3 * v["T14_s"]
    return [
        Consistency(
            "angle swept by the rebuilt profile",
            360.0,
            angle_at(prof.duration),
            "deg",
            allowance,
            "integral of the rebuilt crank speed over x5",
        ),
        Consistency(
            "theta1 at t1 = x1 + T1",
            v["theta1"],
            angle_at(t1),
            "deg",
            allowance,
            "rebuilt profile at the published closing time",
        ),
        Consistency(
            "theta2 at t2 = x2 + 4 T5",
            v["theta2"],
            angle_at(t2),
            "deg",
            allowance,
            "rebuilt profile at the published draw start",
        ),
        Consistency(
            "transfer time theta4 -> theta1",
            v["T0_s"],
            v["x5_s"] - t4 + t1,
            "s",
            _propagate(
                lambda u: u["x5_s"] - u["x3_s"] - 3 * u["T14_s"] + u["x1_s"] + u["T1_s"],
                v,
                ["x5_s", "x3_s", "T14_s", "x1_s", "T1_s"],
            ),
            "x5 - (x3 + 3 T14) + (x1 + T1), at least T0",
            kind="at least",
        ),
    ]


def _angle_allowance(case: Case) -> float:
    """Angle [deg] the printed rounding of the times and speeds allows in the rebuilt profile."""
    v = _inputs(case)

    def swept(u: dict[str, float]) -> float:
        w1 = transfer_speed_rpm(u) * 6  # deg/s
        w2, wm1, wm2 = u["w2_rpm"] * 6, u["wm1_rpm"] * 6, u["wm2_rpm"] * 6
        used = u["x1_s"] + 4 * (u["T1_s"] + u["T5_s"] + u["T10_s"] + u["T14_s"]) + u["T9_s"]
        return (
            w1 * (u["x1_s"] + max(u["x5_s"] - used, 0.0))
            + 2 * u["T1_s"] * (w1 + wm1)
            + 2 * u["T5_s"] * (wm1 + w2)
            + w2 * u["T9_s"]
            + 2 * u["T10_s"] * (w2 + wm2)
            + 2 * u["T14_s"] * (wm2 + w1)
        )

    names = ["x1_s", "x5_s", "T1_s", "T5_s", "T9_s", "T10_s", "T14_s", "wm1_rpm", "wm2_rpm", "J_rpm_s2"]
    return _propagate(swept, v, names)


def paper_solution(plan: Plan) -> dict[str, float]:
    """An improved-S-curve plan in the paper's notation X = [x1..x5, wm1, wm2, T1, T5, T9, T10, T14, J].

    Mapping (time from TDC, as in the paper's Fig. 6): x1 start of the feed acceleration,
    x2 feed peak speed, x3 return peak speed, x4 end of the return deceleration, x5 the period;
    wm1, wm2 [rpm]; T1, T5, T10, T14 the sub-segment lengths of the four halves, T9 the draw [s];
    J [rpm/s^2] the feed jerk (the return jerk is reported separately as ``J_return``).
    """
    p = plan.parameters
    if plan.motion_law != sc.ImprovedSCurve.name:
        raise ValueError("the paper's notation describes improved-s-curve plans only")
    n = sc.SUBSEGMENTS
    tk = plan.profile.knot_times
    names = [s.name for s in plan.profile.segments]
    rpm = 60.0 / (2 * math.pi)

    def start(name: str) -> float:
        return float(tk[names.index(name)])

    def end(name: str) -> float:
        return float(tk[names.index(name) + 1])

    return {
        "x1_s": start("feed:accel1"),
        "x2_s": start("feed:decel1"),
        "x3_s": start("return:decel1"),
        "x4_s": end("return:decel4"),
        "x5_s": plan.period,
        "wm1_rpm": float(p.feed_peak_speed) * rpm,
        "wm2_rpm": float(p.return_peak_speed) * rpm,
        "T1_s": float(p.feed_accel_duration) / n,
        "T5_s": float(p.feed_decel_duration) / n,
        "T9_s": float(p.draw_time),
        "T10_s": float(p.return_accel_duration) / n,
        "T14_s": float(p.return_decel_duration) / n,
        "J_rpm_s2": float(p.feed_jerk) * rpm,
        "J_return_rpm_s2": float(p.return_jerk) * rpm,
    }
