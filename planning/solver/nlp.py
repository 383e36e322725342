"""What every NLP of a press cycle shares: the compiled program and its named row blocks, the limits' rows,
the drive's torque at the samples, the objectives at a rate.

Two transcriptions state the same problem (rockit's split of the problem from its transcription):
``planning.solver.halves_nlp`` (a motion law's halves in closed form, one NLP per law) and
``planning.solver.free_nlp`` (the optimal law's free profile, multiple shooting). Each builds its own
states at its samples and the extremes it can state in closed form, hands them to the limits as a
:class:`~planning.model.limits.base.Transcription`, and adds every row the limits return
(:func:`add_limit_rows`); it never names a limit. Every number of a case enters as a parameter
(``planning.solver.parameters``), so an NLP is built once per process and kind -- motion law, mechanism
kind, the limits the case sets, with or without the drive, at a rate or not -- and reused for every
case and start of that kind.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from planning.model.case import Case, Placement
from planning.model.limits import limits_of
from planning.model.limits.base import Transcription, trapezoid
from planning.model.plan import Plan
from planning.model.profile import advance
from planning.solver.ipopt import NLPResult, NLPSolver
from planning.solver.lifting import SERIES_ORDER, Lift
from planning.solver.parameters import FORMING_SAMPLES, LINK, ParameterLayout, link_parameter
from planning.tolerances import IPOPT_CONSTR_VIOL_TOL, IPOPT_RATE_TOL
from press.dynamics import DriveModel, LinkMass, crank_torque, link_jets, link_terms, motor_speed, motor_torque
from press.mechanism import Formula

CYCLE_OPTIONS = {  # added to the wrapper's base options
    "ipopt.constr_viol_tol": IPOPT_CONSTR_VIOL_TOL,
    "ipopt.max_iter": 400,  # a start that has not converged by then is dropped (others remain)
}
# the rate NLP's objectives (heat, energy; normalised to 1 at the baseline) are wanted to about a millionth:
# a tighter optimality tolerance only lengthens IPOPT's crawl where a law's half degenerates (hundreds of
# iterations for the last digits); the constraints keep CYCLE_OPTIONS' tolerance and the dense verification
RATE_OPTIONS = {"ipopt.tol": IPOPT_RATE_TOL}
# the drive NLPs' rows (the motor torque at every sample, the RMS integral) depend on every variable: with
# MUMPS's approximate-minimum-degree ordering an iteration takes 20-30 % less time than with its automatic
# choice (measured; the optimal law's NLP uses it too); the kinematic NLP keeps the automatic choice (with
# AMD it needs more iterations)
DRIVE_OPTIONS = {"ipopt.mumps_pivot_order": 0}


@dataclass(frozen=True)
class ConstraintBlock:
    """A group of NLP rows: its ``name``, row range, the case ``field`` a user changes to relax it, and the
    id of the limit that stated it ('' for the cycle's own rows)."""

    name: str
    start: int
    stop: int
    field: str
    limit_id: str = ""


@dataclass(frozen=True)
class Refinement:
    """A limit the NLP holds at its samples only: the parameter the search tightens (``index``) when the
    dense check finds the limit exceeded between them, raised instead for a lower limit (``upward``)."""

    index: int
    upward: bool


class Rows:
    """The constraint rows of an NLP as they are added: named blocks, expressions and bounds."""

    def __init__(self) -> None:
        self.blocks: list[ConstraintBlock] = []
        self.g: list = []
        self.lb: list[float] = []
        self.ub: list[float] = []

    def add(self, name: str, expr: Any, lo: Any, hi: Any, field: str, limit_id: str = "") -> slice:
        """Rows ``lo <= expr <= hi`` as the block ``name``; returns their slice."""
        expr = ca.vec(expr)
        n = expr.shape[0]
        self.blocks.append(ConstraintBlock(name, len(self.lb), len(self.lb) + n, field, limit_id))
        self.g.append(expr)
        self.lb.extend(np.broadcast_to(lo, (n,)).tolist())
        self.ub.extend(np.broadcast_to(hi, (n,)).tolist())
        return slice(len(self.lb) - n, len(self.lb))

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array(self.lb), np.array(self.ub)


def add_limit_rows(rows: Rows, nlp: Transcription, layout: ParameterLayout) -> dict[str, Refinement]:
    """Every row of every limit the NLP holds, in the limits' order; returns the limits held at samples
    only, by id (what the search may refine)."""
    refinable = {}
    for limit in layout.limits:
        for row in limit.rows(nlp):
            rows.add(row.name, row.expr, row.lo, row.hi, limit.field, limit.id)
            refined = row.refined or limit.refined
            if row.sampled and refined is not None:
                refinable[limit.id] = Refinement(layout.index(refined), limit.refine_upward)
    return refinable


def nlp_limits(case: Case, drive: bool) -> tuple[str, ...]:
    """The ids of the limits an NLP of ``case`` holds: those the case sets, without the ones whose rows need
    the drive's torque unless ``drive``."""
    return tuple(limit.id for limit in limits_of(case) if drive or not limit.uses_drive)


@dataclass
class CycleNLP:
    """A compiled NLP of a press cycle (either transcription). ``published_rows`` pin theta1 and theta4 to
    the points of the published structure (left unbounded for the free placement); ``refinable``: the
    limits it holds at samples only; ``variables``: name and scale kind of each decision variable;
    ``variable_scales(case)``, ``variable_bounds(case, layout, w2_lo, w2_hi, parameters)`` and
    ``make_plan(case, values, placement, info)`` (the plan of a solve's variable values): the
    transcription's own. ``denser``: the same NLP with more sampled rows (built on first call), for a plan
    that fails a limit this one holds only where it cannot see the failure."""

    program: NLPSolver
    lbg: np.ndarray
    ubg: np.ndarray
    blocks: tuple[ConstraintBlock, ...]
    layout: ParameterLayout
    variables: tuple[tuple[str, str], ...]
    variable_scales: Callable[[Case], np.ndarray]
    variable_bounds: Callable[..., tuple[np.ndarray, np.ndarray]]
    make_plan: Callable[..., Plan]
    published_rows: slice = field(default_factory=lambda: slice(0, 0))
    refinable: dict[str, Refinement] = field(default_factory=dict)
    denser: Callable[[], CycleNLP] | None = None
    complete: Callable[[dict[str, float]], dict[str, float]] | None = None  # a start's missing variables

    def completed(self, values: dict[str, float]) -> dict[str, float]:
        """``values`` with the variables a start of another NLP lacks filled in (:attr:`complete`)."""
        return values if self.complete is None else self.complete(values)

    def values_of(self, result: NLPResult) -> dict[str, float]:
        """The variables of a solve by name."""
        return {k: float(result.x[j]) for j, (k, _) in enumerate(self.variables)}

    def block_of(self, limit_id: str) -> ConstraintBlock | None:
        """The first block of the limit ``limit_id``, None when the NLP has none."""
        return next((b for b in self.blocks if b.limit_id == limit_id), None)

    def bounds(self, placement: Placement, fixed_period: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """``(lbg, ubg)`` for ``placement``; ``fixed_period``: the cycle time held at the parameter
        ``target_period`` (a target rate; the rate NLP only)."""
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        pinned = 0.0 if placement == "published" else np.inf
        lbg[self.published_rows], ubg[self.published_rows] = -pinned, pinned
        if fixed_period:
            block = self.block_of("cycle_time")
            if block is None:
                raise ValueError("only the rate NLP holds a target cycle time")
            lbg[block.start : block.stop], ubg[block.start : block.stop] = 0.0, 0.0
        return lbg, ubg

    def solve(
        self,
        start: dict[str, float],
        case_parameters: np.ndarray,
        lbx: np.ndarray,
        ubx: np.ndarray,
        placement: Placement,
        scale: np.ndarray,
        warm_start: tuple[np.ndarray, np.ndarray] | None = None,
        fixed_period: bool = False,
    ) -> NLPResult:
        """One IPOPT solve from the variable values ``start`` (physical units) for the case parameters
        (:attr:`layout` order), physical bounds ``lbx``/``ubx`` and the variables' ``scale``;
        ``warm_start``: the multipliers of a nearby solve; ``fixed_period``: see :meth:`bounds`."""
        lbg, ubg = self.bounds(placement, fixed_period)
        start = self.completed(start)
        x0 = np.array([start[k] for k, _ in self.variables])
        return self.program.solve(x0, lbx, ubx, lbg, ubg, p=case_parameters, scale=scale, warm_start=warm_start)

    def worst_block(
        self, placement: Placement, g: np.ndarray, fixed_period: bool = False
    ) -> tuple[ConstraintBlock, float]:
        """The block with the largest violation at ``g`` (the last iterate), and that violation."""
        lbg, ubg = self.bounds(placement, fixed_period)
        viol = np.maximum(lbg - g, 0) + np.maximum(g - ubg, 0)
        amount = [float(np.max(viol[b.start : b.stop], initial=0.0)) for b in self.blocks]
        k = int(np.argmax(amount))
        return self.blocks[k], amount[k]


def clipped_advance(tau, theta_start, omega_start, omega0, alpha0, j0, j1) -> tuple:  # noqa: ANN001 - SX or MX
    """Crank angle and speed after consecutive linear-jerk segments with start speeds ``omega0``,
    accelerations ``alpha0`` and jerks ``j0 + j1 tau`` (vectors), each run for its ``tau`` (the time
    clipped to the segment: 0 before it, its duration after it), from ``theta_start``, ``omega_start``."""
    th, om, _, _ = advance(0.0, omega0, alpha0, j0, j1, tau)
    return theta_start + ca.sum1(th), omega_start + ca.sum1(om - omega0)


def draw_states(q: dict, w2, fractions: ca.DM) -> tuple:  # noqa: ANN001 - SX or MX
    """The draw's states at ``fractions`` of it: the fixed angles theta2 ... theta3 (one turn on, as the cycle
    reaches them after time 0 at theta3), the constant speed ``w2``, no acceleration, and their times from the
    draw's start [s]. Wherever the cycle closes (as at every solution) these are its states, and every row
    built on them depends on ``w2`` alone."""
    sweep = fractions * (q["theta3"] - q["theta2"])
    n = fractions.shape[0]
    return q["theta2"] + 2 * np.pi + sweep, w2 * ca.DM.ones(n), ca.DM.zeros(n), sweep / w2


@dataclass
class DriveSamples:
    """The drive at an NLP's samples (``press.dynamics``): the model's symbols, the crank torque ``tc``
    [N m], the motor torque ``tm`` [N m] and speed [rad/s]."""

    model: DriveModel
    tc: Any
    tm: Any
    speed: Any


def drive_samples(
    q: dict,
    p_case: Any,
    layout: ParameterLayout,
    theta: Any,
    lift: Lift | None,
    frames: dict | None,
    om: Any,
    al: Any,
    d1: Any,
    d2: Any,
    forming: Any = None,
) -> DriveSamples:
    """The drive's torque at the samples; the forming force enters at the draw's samples, the last
    :data:`~planning.solver.parameters.FORMING_SAMPLES` (``forming``: the force [N] at every sample instead, a
    free draw's); the mechanism's massive links (``layout.links``) at every sample through its ``frames`` (the
    lifted mechanism's, at its series' order; else computed here).
    """
    if forming is None:
        forming = ca.vertcat(ca.DM.zeros(om.shape[0] - FORMING_SAMPLES), p_case[layout.forming])
    # the forming force enters as parameters at the draw's samples: no table, no forming window here
    links = tuple(LinkMass(name, *(q[link_parameter(name, part)] for part in LINK)) for name in layout.links)
    model = DriveModel(
        q["drive_M"],
        q["drive_J0"],
        q["drive_F_cb"],
        q["drive_i"],
        q["drive_eta"],
        q["drive_J_m"],
        (),
        (),
        0.0,
        0.0,
        links,
    )
    terms = None
    if links and lift is not None:  # the links' inertia and weight, lifted (``planning.solver.lifting``)
        J, weight = link_jets(frames, links)
        terms = (lift.quantity(J), lift.quantity(J.derivative()), lift.quantity(weight))
    elif links:
        terms = link_terms(layout.formula.frames(theta, layout.geometry(q)), links)
    tc = crank_torque(om, al, d1, d2, forming, model, terms)
    tm = motor_torque(tc, al, model)
    return DriveSamples(model, tc, tm, motor_speed(om, model))


def sample_states(
    formula: Formula,
    layout: ParameterLayout,
    q: dict,
    p_case: Any,
    states: tuple,
    times: Any,
    draw_count: int,
    forming: Any = None,
) -> tuple[dict[str, Any], DriveSamples | None, Lift | None]:
    """What every transcription hands the limits of its samples (the crank's ``states`` ``(theta, omega,
    alpha)`` and their ``times``, the draw's ``draw_count`` last): with the mechanism's height and its first
    two derivatives there, the case's parameters, and in a drive NLP the motor's torque and speed; the
    :class:`~planning.model.limits.base.Transcription` fields, the drive's samples (None without) and, for a
    mechanism whose NLPs lift it (``Formula.lifted``), its quantities as the derivative functions take
    them (``planning.solver.lifting``: the rows read them as symbols), else None."""
    theta, omega, alpha = states
    geometry = layout.geometry(q)
    lift = Lift.at(theta) if formula.lifted else None
    if lift is not None:
        series, frames = formula.evaluate(lift.angles, geometry, SERIES_ORDER)
        h, d1, d2 = (lift.quantity(j) for j in (series, series.derivative(), series.derivative().derivative()))
    else:
        h, d1, d2, _ = formula.jets(theta, geometry)
        frames = None  # computed where the drive's links need them
    torque = None
    if layout.drive:
        torque = drive_samples(q, p_case, layout, theta, lift, frames, omega, alpha, d1, d2, forming)
    fields = {
        "theta": theta,
        "omega": omega,
        "alpha": alpha,
        "times": times,
        "height": h,
        "slope": d1,
        "curvature": d2,
        "draw_count": draw_count,
        "length_unit": q["length_unit"],
        "param": q.__getitem__,
        "motor_torque": None if torque is None else torque.tm,
        "motor_speed": None if torque is None else torque.speed,
        "crank_torque": None if torque is None else torque.tc,
    }
    return fields, torque, lift


def bus_power_samples(q: dict, drive: DriveSamples) -> Any:
    """The bus power at the samples [W] for the least grid peak (``press.power``): the motor's shaft power and
    copper loss through the converter, ``(T_m omega_m + k T_m^2) / eta_c`` (a braking sample's is lower than
    the converter's ``eta_c`` times, and far from any peak)."""
    return (drive.tm * drive.speed + q["copper_coefficient"] * drive.tm**2) / q["converter_efficiency"]


def objective_terms(q: dict, drive: DriveSamples, al: Any, times: Any, losses: bool = False) -> tuple[Any, Any]:
    """The rate NLP's trapezoidal ``(heat, supply energy)``: integral T_m^2 dt [N^2 m^2 s] and integral
    (r P + (1 - r) smoothmax(P, 0)) dt [J] of the bus power P = conv(T_m omega_m + k T_m^2) (the motors'
    copper loss and the converter, ``press.power``, with ``losses``; else the shaft power), on a
    smooth torque: the gear's loss switches sides where T_c changes sign, and a plan that saves heat or
    energy coasts there (T_c = 0 over stretches), so the kinks are rounded: |x| -> sqrt(x^2 + eps^2) (the
    converter's P / eta_c or P eta_c with the same rounding)."""
    model = drive.model
    up, down = 1 / (model.i * model.eta), model.eta / model.i
    eps_crank = q["power_smoothing"] / (q["motor_base_speed"] * down)  # [N m] at the crank
    through = drive.tc * (up + down) / 2 + ca.sqrt(drive.tc**2 + eps_crank**2) * (up - down) / 2
    smooth_torque = through + model.J_m * model.i * al
    eps = q["power_smoothing"]
    power = smooth_torque * drive.speed
    if losses:  # else P is the shaft power (the terms below vanish: k = 0, eta_c = 1), at less cost per iteration
        electrical = power + q["copper_coefficient"] * smooth_torque**2
        eta_c = q["converter_efficiency"]
        power = electrical * (1 / eta_c + eta_c) / 2 + ca.sqrt(electrical**2 + eps**2) * (1 / eta_c - eta_c) / 2
    drawn = (power + ca.sqrt(power**2 + eps**2)) / 2  # smooth max(P, 0)
    energy = trapezoid(q["regen"] * power + (1 - q["regen"]) * drawn, times)
    return trapezoid(smooth_torque**2, times), energy
