"""Independent verification of a plan: dense closed-form re-simulation against every constraint.

The plan's profile is evaluated in closed form on a uniform grid of at most 1 ms (not at the
optimizer's sample points), plus every knot. First the checks of the cycle itself (finite, closed,
continuous at every knot, the key angles reached, the draw at constant speed, with a drive the energy
balance), then each limit of the case checks itself (``planning.model.limits``), with the tolerances
below and the limits' own (the README's numerical contract). Only a plan whose checks all pass is a
success. The drive's figures (``planning.model.drive``) come from the same evaluation.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field, replace

import numpy as np

from planning.model.case import RPM, Case
from planning.model.drive import DriveFigures, PowerFigures, breakpoints, cycle_integrals, drive_figures
from planning.model.limits import field_of, limits_of
from planning.model.limits.base import Check, Dense
from planning.model.plan import Plan
from planning.model.profile import max_abs_jerk, sample_times
from planning.solver.peak_shaving import power_columns, power_figures
from planning.tolerances import (
    ACCEL_CLOSE_TOL_RAD_S2,
    ANGLE_TOL_RAD,
    BINDING_SHARE,
    CONTINUITY_TOL,
    ENERGY_REL_TOL,
    KNOT_PROBE_S,
    ROUND_OFF_REL,
    SPEED_TOL_RAD_S,
)
from press.dynamics import drive_state
from press.mechanism import slider_motion

__all__ = ["BINDING_SHARE", "Check", "CheckId", "Evaluation", "Verification", "evaluate", "field_of_check", "verify"]


class CheckId(str, enum.Enum):
    """Stable identifiers of the checks of the cycle itself (a limit's check has the limit's id)."""

    FINITE = "finite"
    CYCLE_ANGLE = "cycle_angle"
    SPEED_CLOSES = "speed_closes"
    ACCEL_CLOSES = "accel_closes"
    SPEED_CONTINUOUS = "speed_continuous"
    ACCEL_CONTINUOUS = "accel_continuous"
    KEY_ANGLES = "key_angles"
    DRAW_CONSTANT = "draw_constant_speed"
    ENERGY_BALANCE = "energy_balance"
    GRID_BALANCE = "grid_energy_balance"
    STORAGE_EMPTY = "storage_above_empty"
    STORAGE_FULL = "storage_below_full"
    STORAGE_CLOSES = "storage_closes"


SCHEDULE_CHECKS = frozenset({CheckId.STORAGE_EMPTY, CheckId.STORAGE_FULL})  # the storage schedule's own bounds:
# at them the storage is used to the full, which binds no limit of the plan (not in the binding list)
BY_CONSTRUCTION = frozenset({"robots_path"})  # a robot's speed and acceleration: its moves are the fastest its
# limits allow, at them by construction, which binds no limit of the plan (not in the binding list)
CYCLE_FIELDS = {CheckId.KEY_ANGLES: "key_points"}  # the case field behind a cycle check, where one is


def field_of_check(check_id: str) -> str:
    """The case field a user changes to pass the check ``check_id`` ('' where none says it)."""
    return field_of(check_id) or CYCLE_FIELDS.get(check_id, "")


@dataclass(frozen=True)
class Verification:
    """All checks of a plan; ``passed`` when every one holds. ``step_s`` [s] is the grid step used."""

    checks: tuple[Check, ...]
    step_s: float
    samples: int

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def failures(self) -> list[Check]:
        return [c for c in self.checks if not c.passed]

    def binding(self) -> list[Check]:
        """The checks at their limits (:attr:`Check.binds`), the storage schedule's bounds and the robots' own
        moves apart."""
        return [c for c in self.checks if c.binds and c.id not in SCHEDULE_CHECKS | BY_CONSTRUCTION]

    def check(self, check_id: str) -> Check | None:
        """The check with id ``check_id`` (a limit's id or a :class:`CheckId`), None when the plan has none."""
        return next((c for c in self.checks if c.id == check_id), None)


@dataclass(frozen=True)
class Evaluation:
    """A plan re-simulated densely against a case, once: what every output reads (pvlib's
    ``ModelChainResult``: one field per step, computed once and carried).

    ``samples``: the dense re-simulation (:class:`~planning.model.limits.base.Dense`: times from TDC, the
    crank's and the slide's motion, with a drive its state and the cycle's integrals, with the drive's
    electrical side its power chain and ``power_columns`` at the samples); ``uniform``: the indices of the
    samples on the uniform grid (the knots are the others); ``verification``: every check, each with where
    it peaked; ``drive``: the drive's figures (a case with a drive)."""

    samples: Dense
    uniform: np.ndarray
    verification: Verification
    drive: DriveFigures | None = None
    power_columns: dict[str, np.ndarray] | None = field(default=None, repr=False)

    def rows(self, most: int) -> np.ndarray:
        """Indices of at most ``most`` + 1 samples on the uniform grid, evenly spaced, both ends included
        (every uniform sample when there are no more)."""
        stride = max(1, math.ceil((self.uniform.size - 1) / most))
        picked = self.uniform[::stride]
        return picked if picked[-1] == self.uniform[-1] else np.append(picked, self.uniform[-1])


def verify(plan: Plan, case: Case) -> Verification:
    """Re-simulate ``plan`` densely and check it against the limits of ``case``."""
    return evaluate(plan, case).verification


def evaluate(plan: Plan, case: Case, least_energy: bool = True, cam: bool = False) -> Evaluation:
    """The :class:`Evaluation` of ``plan`` against ``case``: the dense re-simulation, every check, the
    drive's figures. ``least_energy`` False: with a storage, its lazy schedule at the least grid peak
    instead of the one that draws the least energy (``planning.solver.peak_shaving.shave``): the same peak
    and checks, in O(N) (a search's verifications; its answer then takes :func:`with_least_energy`).
    ``cam``: ``plan``'s profile is a cam as its controller runs it (``planning.solver.cam_proof``): the cycle
    closes and every limit of the press and the process holds; the law's own checks (continuous at its knots,
    the key angles at their times, the draw at one speed) and the plan's goals (a target rate) are not the
    cam's."""
    dense, uniform = simulate(plan, case)
    if case.drive is not None and case.electrical:
        dense.power = power_figures(plan.profile, case, dense.t, dense.drive_state, least_energy)
    return _judged(dense, uniform, cam)


def simulate(plan: Plan, case: Case) -> tuple[Dense, np.ndarray]:
    """The dense re-simulation of ``plan`` (the one evaluation of a plan's profile that every check and
    output reads): the profile in closed form on the uniform grid of at most 1 ms and every knot, the
    slide's motion, with a drive its state and the cycle's integrals; and the uniform grid's indices."""
    prof = plan.profile
    # every knot, and with a drive where the forming force starts, kinks and ends (its peaks may lie there)
    t, uniform = sample_times(plan.period, prof.knot_times if case.drive is None else breakpoints(prof, case))
    th, om, al, je = prof.at_time(t)
    h, d1, d2, d3 = case.machine.jets(th)
    _, v, a, slide_jerk = slider_motion(h, d1, d2, d3, om, al, je)
    key_times = plan.key_times()
    dense = Dense(case, plan, t, th, om, al, je, h, v, a, key_times, slide_jerk=slide_jerk, slope=d1, curvature=d2)
    k_th, k_om, k_al, k_je = prof.at_time(key_times)
    k_h, k_v, _, _ = case.machine.slider(k_th, k_om, k_al, k_je)
    dense.key_motion = {"omega": k_om, "h": k_h, "v": k_v}
    if case.drive is not None:
        dense.drive_state = drive_state(th, om, al, case.machine, case.drive_model)
        dense.integrals = cycle_integrals(prof, case)
    return dense, uniform


def with_least_energy(evaluation: Evaluation) -> Evaluation:
    """``evaluation`` with the storage's least-energy schedule (its samples as they were; the power chain
    and the checks again): the answer of a search whose verifications took the lazy one."""
    dense = replace(evaluation.samples)
    dense.power = power_figures(dense.plan.profile, dense.case, dense.t, dense.drive_state, True)
    return _judged(dense, evaluation.uniform)


def _judged(dense: Dense, uniform: np.ndarray, cam: bool = False) -> Evaluation:
    """The checks of the cycle, of each limit and of the drive's balances on ``dense``; the drive's figures
    (``cam``: :func:`evaluate`'s)."""
    case = dense.case
    checks = _closure_checks(dense) if cam else _closure_checks(dense) + _law_checks(dense)
    for limit in limits_of(case):
        if not (cam and limit.goal):
            checks += limit.check(dense)
    if case.drive is not None:
        checks.append(energy_balance(dense.integrals))
    columns = None
    if dense.power is not None:
        checks += power_checks(dense.power, dense.integrals, case.drive.storage is not None)
        columns = power_columns(dense.power.schedule, dense.drive_state, dense.t, case)
    verification = Verification(tuple(checks), float(np.max(np.diff(dense.t))), int(dense.t.size))
    figures = None
    if case.drive is not None:
        figures = drive_figures(dense.plan.profile, case, dense.integrals, (dense.theta, dense.drive_state))
        figures = replace(figures, power=dense.power)
    return Evaluation(dense, uniform, verification, figures, columns)


def schedule_matters(case: Case) -> bool:
    """Whether :func:`evaluate`'s ``least_energy`` changes anything for ``case`` (a storage on the bus)."""
    return case.drive is not None and case.drive.storage is not None


def power_checks(power: PowerFigures, integrals: dict, storage: bool) -> list[Check]:
    """The power chain over the cycle: the grid's energy is the forming work and every loss (the kinetic
    energies return to their start), and (``storage``) the storage stays within its usable energy and ends
    where it started."""
    losses = (
        power.gear_loss_kJ
        + power.copper_loss_kJ
        + power.converter_loss_kJ
        + power.storage_loss_kJ
        + power.resistor_loss_kJ
    )
    scale = max(abs(integrals["forming_work_kJ"]), integrals["crank_work_abs_kJ"], abs(power.grid_energy_kJ))
    usable = power.storage_usable_kJ
    room = ENERGY_REL_TOL * max(usable, scale)
    balance = [
        Check.of(
            CheckId.GRID_BALANCE,
            "energy balance: grid = forming work + losses + storage change",
            power.grid_energy_kJ,
            integrals["forming_work_kJ"] + losses + power.storage_change_kJ,
            "kJ",
            "equal",
            ENERGY_REL_TOL * scale,
        )
    ]
    if not storage:
        return balance
    return balance + [
        Check.of(CheckId.STORAGE_EMPTY, "storage above empty", power.storage_min_kJ, 0.0, "kJ", "min", room),
        Check.of(CheckId.STORAGE_FULL, "storage below full", power.storage_max_kJ, usable, "kJ", "max", room),
        Check.of(CheckId.STORAGE_CLOSES, "storage closes", power.storage_change_kJ, 0.0, "kJ", "equal", room),
    ]


def _closure_checks(d: Dense) -> list[Check]:
    """The cycle itself: finite, closed after 360 deg with the same speed and acceleration."""
    prof, P = d.plan.profile, d.plan.period
    checks = []
    finite = bool(np.all(np.isfinite(np.concatenate([d.theta, d.omega, d.alpha, d.h, d.v, d.a]))))
    checks.append(Check.of(CheckId.FINITE, "trajectory finite", 1.0 if finite else math.nan, 1.0, "", "equal", 0.0))
    end = prof.at_time(np.array([0.0, P]))
    turn = math.degrees(end[0][1] - end[0][0])
    tol = math.degrees(ANGLE_TOL_RAD)
    checks.append(Check.of(CheckId.CYCLE_ANGLE, "cycle angle", turn, 360.0, "deg", "equal", tol))
    closes = (end[1][1] - end[1][0]) / RPM
    checks.append(Check.of(CheckId.SPEED_CLOSES, "speed closes", closes, 0.0, "rpm", "equal", SPEED_TOL_RAD_S / RPM))
    accel = end[2][1] - end[2][0]
    checks.append(
        Check.of(CheckId.ACCEL_CLOSES, "acceleration closes", accel, 0.0, "rad/s^2", "equal", ACCEL_CLOSE_TOL_RAD_S2)
    )
    return checks


def _law_checks(d: Dense) -> list[Check]:
    """The law's own: continuous at every knot, the key angles reached at their times, the draw at constant
    speed (but a draw at constant slide speed, which ``planning.model.limits.draw_slide_speed`` checks)."""
    prof = d.plan.profile
    checks = continuity_checks(prof)
    th_key = prof.at_time(d.key_times)[0]
    err = float(np.max(np.abs(th_key - np.array(d.plan.key_angles))))
    tol = math.degrees(ANGLE_TOL_RAD)
    checks.append(Check.of(CheckId.KEY_ANGLES, "key angles reached", math.degrees(err), 0.0, "deg", "equal", tol))
    if getattr(d.plan.parameters, "free_draw", False):  # a draw at constant slide speed: its own limit checks it
        return checks
    _, t2, t3, _ = d.key_times
    draw = (d.t >= t2) & (d.t <= t3)
    w2 = float(d.plan.parameters.draw_speed)
    off = float(np.max(np.abs(d.omega[draw] - w2))) / RPM
    name = "draw at constant crank speed"
    checks.append(Check.of(CheckId.DRAW_CONSTANT, name, off, 0.0, "rpm", "equal", SPEED_TOL_RAD_S / RPM))
    return checks


def continuity_checks(prof) -> list[Check]:  # noqa: ANN001 - a Profile
    """Across a knot t_k, omega(t_k + e) - omega(t_k - e) = 2 e alpha + O(e^2 |jerk|) and
    alpha(t_k + e) - alpha(t_k - e) = e (j_left + j_right) + O(e^2 |dj/dt|); a jump would add its full
    size. e stays within both neighbouring segments; the remainders are bounded from their jerks."""
    knots = prof.knot_times[1:-1]
    if not knots.size:
        return []
    T = prof.durations
    eps = np.minimum(KNOT_PROBE_S, 0.25 * np.minimum(T[:-1], T[1:]))
    left, right = prof.at_time(knots - eps), prof.at_time(knots + eps)
    j_max = max_abs_jerk(prof)
    j1_max = max(_max_jerk_rate(s) for s in prof.segments)
    jump_w = float(np.max(np.abs(right[1] - left[1] - 2 * eps * prof.at_time(knots)[2])))
    jump_a = float(np.max(np.abs(right[2] - left[2] - eps * (left[3] + right[3]))))
    return [
        Check.of(
            CheckId.SPEED_CONTINUOUS,
            "crank speed continuous at knots",
            jump_w,
            0.0,
            "rad/s",
            "equal",
            CONTINUITY_TOL + ROUND_OFF_REL * j_max,
        ),
        Check.of(
            CheckId.ACCEL_CONTINUOUS,
            "crank acceleration continuous at knots",
            jump_a,
            0.0,
            "rad/s^2",
            "equal",
            CONTINUITY_TOL + ROUND_OFF_REL * j1_max,
        ),
    ]


def energy_balance(integrals: dict) -> Check:
    """Over a cycle the kinetic energy returns to its start and gravity and the counterbalance are
    conservative: the crank's work equals the forming work (``planning.model.drive``)."""
    scale = max(abs(integrals["forming_work_kJ"]), integrals["crank_work_abs_kJ"])
    return Check.of(
        CheckId.ENERGY_BALANCE,
        "energy balance: crank work = forming work",
        integrals["crank_work_kJ"],
        integrals["forming_work_kJ"],
        "kJ",
        "equal",
        ENERGY_REL_TOL * scale,
    )


def _max_jerk_rate(seg) -> float:  # noqa: ANN001 - a Segment
    """A bound on |d jerk / dt| [rad/s^4] inside ``seg`` (for the continuity remainder): ``j1`` of the
    linear part plus, for a shape, twice the largest finite-difference slope of its jerk on 400 steps."""
    rate = abs(float(seg.j1))
    if seg.shape is not None:
        u = np.linspace(0.0, 1.0, 401)
        s2 = np.asarray(seg.shape.terms(u)[3], dtype=float)
        rate += 2 * abs(float(seg.dv)) / float(seg.span) ** 3 * float(np.max(np.abs(np.diff(s2)) / np.diff(u)))
    return rate
