"""At the line's rate: the gentlest verified plan at a target SPM, and the baseline it beats.

In a press line the rate is set by the line, not by one press's maximum. At a target rate (cycle time
``60 / target_spm``, the cycle-time row of the rate NLP (``planning.solver.halves_nlp``, ``rate=True``)
held fixed) the planner minimises

- ``min-rms-torque``: the heat ``integral T_m^2 dt`` over the cycle (the RMS torque squared times the
  cycle time, which is fixed);
- ``min-energy``: the energy drawn from the supply per stroke ``E+ - r |E-|`` (``r`` =
  ``drive.regen_efficiency``) of the bus power (the motors' copper loss and the converter counted, where the
  drive states them; no storage). ``max(P, 0)`` has a kink where the power changes sign: the NLP uses the
  smooth ``(P + sqrt(P^2 + eps^2)) / 2`` on its samples; the verification and every output use the
  exact integral (``planning.model.drive``, ``planning.solver.peak_shaving``);
- ``min-grid-peak``: the grid's peak power with the case's storage (``planning.solver.peak_shaving``). The NLP
  (the rate NLP's peak variant) minimises the bus power's peak at its samples, an epigraph variable
  ``bus_peak >= (T_m omega_m + k T_m^2) / eta_c`` at every sample, with the heat as a tie-break; the
  answer is chosen by the exact grid peak on the dense grid (with a storage: the least peak its schedule
  reaches, which the NLP does not model).

Every limit of ``max-spm`` still holds. Steps: the fastest plan (``max-spm``; a target above its rate
is :class:`Infeasible`, naming the limits that bind there); the **baseline**, the max-SPM plan run at
the target rate the way a controller does, with the spare time spent at the transfer speed: at the
target cycle time, the plan with the longest constant-speed transfer dwell (every other limit as
before), started from the fastest plan run slower (every speed divided and every time multiplied by
the ratio of the cycle times, so the key angles stay put); then the objective, started from a
neighbouring rate's plan, the slowed fastest plan and the baseline (feasible at the rate, but from it
IPOPT often crawls for hundreds of iterations where the baseline's dwell is long). The answer
is the verified plan with the lowest exact objective (``planning.solver.solution.objective_value``, from
the drive's figures every verified plan carries); the baseline is one candidate, so the answer never
does worse than waiting, and ``AtRate.improved`` says whether a solve beat it.

Under the optimal law the same steps run on its free profile's rate NLP (``planning.solver.free_nlp``,
``rate``; ``min-grid-peak`` is refused with it): its baseline lengthens the robot's window phase instead of a
dwell (it has none, :func:`dwell_s`), its starts are its plans sampled onto the rate NLP's layout, and a draw at
constant slide speed weighs its draw time first (:data:`DRAW_FIRST`), so the slide keeps its set speed.
"""

from __future__ import annotations

import math
from dataclasses import replace

from planning.model.case import Case, Placement
from planning.model.free_profile import FreeProfileParameters, draws_freely, holds
from planning.model.laws import FREE, get_law
from planning.model.plan import Plan
from planning.solver.free_nlp import free_nlp_for, layout_of
from planning.solver.halves_nlp import PEAK_VARIABLE, ROBOT_VARIABLES, VARIABLE_INDEX, halves_nlp_for
from planning.solver.max_spm import solve_max_spm
from planning.solver.neighbour import can_start
from planning.solver.optimal import seed_values, solve_optimal
from planning.solver.outcomes import Infeasible, NoPlanFound, Unverified
from planning.solver.search import Search, prepare
from planning.solver.solution import AtRate, Solution, objective_value
from planning.solver.starts import guesses_at_period
from planning.solver.verify import evaluate, field_of_check
from planning.tolerances import RATE_TOLERANCE, SAME_PERIOD_S

HEAT_TIE_BREAK = 1e-3  # min-energy, min-grid-peak: the heat's weight against the objective's (both normalised)
PEAK_START_HEADROOM = 1.05  # min-grid-peak: a start's bus peak this much above the slower starts' grid peak
BASELINE_SCORE = 1.0  # the objective's score of the baseline (the objectives are normalised by its figures)
# a draw at constant slide speed at a rate: the draw's time, relative to the baseline's, weighs this many times
# the objective (1 at the baseline), so the slide keeps its set speed wherever the crank's limits allow (as at
# the most strokes) and the heat or energy is saved elsewhere
DRAW_FIRST = 100.0


def solve_at_rate(
    case: Case,
    placement: Placement | None = None,
    neighbour: Plan | None = None,
    fastest: Solution | None = None,
    neighbour_baseline: Plan | None = None,
    confirm: bool = True,
) -> Solution:
    """The verified plan of ``case`` at ``planner.target_spm`` with the least ``planner.objective``, with
    its :class:`AtRate`; raises a :class:`PlanningError` when there is none.

    ``fastest``: the case's max-SPM solution when the caller has it (a trade-off computes it once);
    ``neighbour`` / ``neighbour_baseline``: the plan and baseline of a neighbouring rate (warm starts).
    ``confirm``: run the objective's starts until two agree on the optimum (else the first verified
    start is the answer: a trade-off's speed).
    """
    placement = "free" if _free(case) else placement or case.planner.placement
    objective, target = case.planner.objective, case.planner.target_spm
    if fastest is None:
        fastest = solve_fastest(case.with_objective("max-spm"), placement)
    if case.electrical and fastest.drive.power is None:  # the max-SPM case leaves the grid out: its figures here
        fastest = replace(fastest, evaluation=evaluate(fastest.plan, case))
    check_reachable(target, fastest, case)
    period = 60.0 / target
    baseline = _baseline(case, placement, fastest, period, neighbour_baseline, confirm)
    scale = objective_value(baseline, objective)

    if baseline is fastest:  # at the fastest rate the limits leave (generically) that one plan
        return replace(fastest, at_rate=AtRate(objective, target, fastest.plan.spm, fastest, False))
    peak = objective == "min-grid-peak"
    search = _rate_search(case, placement, period, peak)
    # normalised by the baseline: its objective is 1 (heat [N^2 m^2 s], energy [J], bus peak [W] in the NLP)
    heat_weight = 1.0 / (baseline.drive.rms_motor_torque_Nm**2 * period)
    if objective == "min-rms-torque":
        search.parameters[search.parameter("weight_heat")] = heat_weight
    elif peak:  # the peak leaves whole stretches of the cycle free: the heat breaks ties
        search.parameters[search.parameter("weight_peak")] = 1.0 / (baseline.drive.power.bus_peak_kW * 1e3)
        search.parameters[search.parameter("weight_heat")] = HEAT_TIE_BREAK * heat_weight
    else:  # the energy has flat directions (a plan's speeds can trade without changing it): the heat breaks ties
        search.parameters[search.parameter("weight_energy")] = 1.0 / (scale * 1e3)
        search.parameters[search.parameter("weight_heat")] = HEAT_TIE_BREAK * heat_weight
    if case.free_draw:  # the slide at its set speed first: the draw's time weighed far above the objective
        search.parameters[search.parameter("weight_draw")] = DRAW_FIRST / _draw_time_s(baseline.plan)
    search.score = lambda solution: objective_value(solution, objective) / scale
    search.consider(baseline, BASELINE_SCORE)
    starts = [_slowed(fastest.plan, period / fastest.plan.period, search), baseline.plan.nlp_values]
    if peak:  # the bus peak's start: above what either start draws
        top = PEAK_START_HEADROOM * 1e3 * max(baseline.drive.power.bus_peak_kW, fastest.drive.power.bus_peak_kW)
        starts = [{**values, PEAK_VARIABLE[0]: top} for values in starts]
        if neighbour is not None and PEAK_VARIABLE[0] not in neighbour.nlp_values:
            neighbour = replace(neighbour, nlp_values={**neighbour.nlp_values, PEAK_VARIABLE[0]: top})
    _run_starts(search, starts, neighbour, placement, confirm, to_beat=BASELINE_SCORE)
    improved = search.best is not baseline
    answer = search.answer()
    info = answer.plan.solver
    totals = replace(
        info,
        iterations=info.iterations + baseline.plan.solver.iterations,
        starts=info.starts + baseline.plan.solver.starts,
    )
    answer = replace(answer, plan=replace(answer.plan, solver=totals))
    return replace(answer, at_rate=AtRate(objective, target, fastest.plan.spm, baseline, improved))


def _free(case: Case) -> bool:
    """The case's law plans a free profile (the optimal law), in free placement."""
    return get_law(case.planner.motion_law).transcription == FREE


def solve_fastest(case: Case, placement: Placement) -> Solution:
    """The case's max-SPM solution by its law's solve (the optimal law's in free placement)."""
    return solve_optimal(case) if _free(case) else solve_max_spm(case, placement)


def dwell_s(plan: Plan) -> float:
    """[s] where a plan run slower spends its spare time: a law's constant-speed transfer dwell, the optimal
    law's window phase (theta4 -> theta1)."""
    p = plan.parameters
    return p.window_time if isinstance(p, FreeProfileParameters) else float(p.transfer_dwell)


def check_reachable(target: float, fastest: Solution, case: Case) -> None:
    """:class:`Infeasible` when the target rate is above what the limits allow, naming the ones that bind."""
    if target <= fastest.plan.spm * (1 + RATE_TOLERANCE):
        return
    binding = [field_of_check(c.id) or c.name for c in fastest.verification.binding()]
    named = ", ".join(dict.fromkeys(binding)) or "the key points and limits together"
    raise Infeasible(
        f"planner.target_spm = {target:g} is above the {fastest.plan.spm:.3f} strokes/min the limits allow "
        f"(binding there: {named})",
        limit=binding[0] if binding else "planner.target_spm",
        value=target,
        needed=fastest.plan.spm,
    )


def _rate_search(case: Case, placement: Placement, period: float, peak: bool = False) -> Search:
    """The rate NLP's search (``peak``: its peak variant) with the cycle time held at ``period`` [s] and every
    objective weight 0."""
    drive = case.drive is not None  # a kinematic case (a press in a line): its baseline only
    if _free(case):  # the optimal law's free profile at the rate (min-grid-peak refused with it)
        search = prepare(case, "free", free_nlp_for(case, drive=drive, rate=True))
    else:
        search = prepare(case, placement, halves_nlp_for(case, drive=drive, rate=True, peak=peak))
    search.parameters = search.parameters.copy()
    search.parameters[search.parameter("target_period")] = period
    search.parameters[search.parameter("weight_period")] = 0.0
    search.fixed_period = True
    return search


def solve_at_period(case: Case, period_s: float, fastest: Solution | None = None) -> Solution:
    """``case``'s max-SPM plan run at cycle time ``period_s`` [s] (a press in a line; a drive is not needed):
    the longest transfer dwell (:func:`_baseline`), else (its optimum out of the solver's reach) the verified
    plan at that period with the longest dwell the starts reach; its fastest plan where ``period_s`` is that
    plan's own.
    ``fastest``: the case's max-SPM solution when the caller has it. :class:`Infeasible` for a period
    shorter than the fastest plan's."""
    case = case.with_objective("max-spm")
    placement = "free" if _free(case) else case.planner.placement
    if fastest is None:
        fastest = solve_fastest(case, placement)
    check_reachable(60.0 / period_s, fastest, case)
    at_rate = case.with_objective(None, 60.0 / period_s)
    draw_speed = fastest.plan.nlp_values["draw_speed"]
    guesses = [] if _free(case) else guesses_at_period(case, draw_speed, period_s)
    try:
        return _baseline(at_rate, placement, fastest, period_s, None, True)
    except (NoPlanFound, Unverified):  # far slower than the fastest: starts built for the period (draw speed kept)
        pass
    try:
        return _baseline(at_rate, placement, fastest, period_s, None, True, guesses, slowed=False)
    except (NoPlanFound, Unverified):  # the dwell's optimum out of IPOPT's reach ("infeasible" near a degenerate half)
        return _at_period_feasible(at_rate, placement, fastest, period_s, guesses)


def _at_period_feasible(
    case: Case, placement: Placement, fastest: Solution, period: float, guesses: list[dict[str, float]]
) -> Solution:
    """A verified plan at cycle time ``period`` [s] without the dwell's objective (the rate NLP as a feasibility
    problem, every weight 0), from the slowed fastest plan and the period's guesses; of those verified, the
    longest transfer dwell."""
    search = _rate_search(case, placement, period)
    search.score = lambda solution: -dwell_s(solution.plan) / period
    starts = [_slowed(fastest.plan, period / fastest.plan.period, search), *guesses]
    _run_starts(search, starts, None, placement, True)
    try:
        return search.answer()
    except NoPlanFound as exc:
        raise NoPlanFound(f"no plan at {60 / period:.4g} strokes/min: {exc.reason}", exc.attempts) from None


def _baseline(
    case: Case,
    placement: Placement,
    fastest: Solution,
    period: float,
    neighbour: Plan | None,
    confirm: bool,
    more_starts: tuple[dict[str, float], ...] | list[dict[str, float]] = (),
    slowed: bool = True,
) -> Solution:
    """The max-SPM plan run at cycle time ``period`` [s] with the spare time spent at the transfer speed:
    the longest transfer dwell (see the module docstring). At the fastest rate it is the fastest plan.
    ``more_starts``: after the slowed fastest plan's (``slowed`` False: instead of it)."""
    if abs(fastest.plan.period - period) <= SAME_PERIOD_S:
        return fastest
    search = _rate_search(case, placement, period)
    search.parameters[search.parameter("weight_dwell")] = 1.0 / _dwell_unit(search)
    search.score = lambda solution: -dwell_s(solution.plan) / period
    starts = [_slowed(fastest.plan, period / fastest.plan.period, search)] if slowed else []
    starts += list(more_starts)
    _run_starts(search, starts, neighbour, placement, confirm)
    try:
        return search.answer()
    except NoPlanFound as exc:
        raise NoPlanFound(f"no baseline at {60 / period:.4g} strokes/min: {exc.reason}", exc.attempts) from None


def _draw_time_s(plan: Plan) -> float:
    """[s] a plan's draw, theta2 -> theta3."""
    t2, t3 = plan.key_times()[1:3]
    return float((t3 - t2) % plan.period)


def _dwell_unit(search: Search) -> float:
    """[s] the scale of the dwell the baseline lengthens: a law's dwell variable's, the optimal law's window
    phase's (its step's scale times its segments)."""
    if not _free(search.case):
        return float(search.scale[VARIABLE_INDEX["transfer_dwell"]])
    names = [name for name, _ in search.nlp.variables]
    segments = sum(1 for name in names if name.startswith("transfer_jerk_"))
    return float(search.scale[names.index("transfer_step")]) * segments


SLOWED_POWER = {"speed": -1, "half": 1, "time": 1, "step": 1, "accel": -2, "jerk": -3}  # a kind's time power


def _slowed(plan: Plan, factor: float, search: Search) -> dict[str, float]:
    """``plan``'s NLP values run ``factor`` times slower: every angle, so every key point and the cycle's
    closure, stays where it was (a start; values held within their bounds, the draw speed's in particular, and a
    hold's standstill at its time, so a cycle with a hold is not quite ``factor`` times longer); the robots'
    starts, where it has robots, at the same angles too (their times ``factor`` times later). Each value scales by
    ``factor`` to the power of its kind's time (:data:`SLOWED_POWER`: a speed's -1, a time's 1, an acceleration's
    -2, a jerk's -3); an optimal plan on another layout than the search's is sampled onto it first."""
    given = _on_layout(search, plan) if _free(search.case) else plan.nlp_values
    values = {name: given[name] * factor for name, _ in ROBOT_VARIABLES if name in given}
    for j, (name, kind) in enumerate(search.nlp.variables):
        if name not in given:
            continue
        value = given[name] * factor ** SLOWED_POWER.get(kind, 0)
        values[name] = float(min(max(value, search.lbx[j]), search.ubx[j]))
    return values


def _on_layout(search: Search, plan: Plan) -> dict[str, float]:
    """An optimal plan's values on the layout of ``search``'s NLP (its own, or sampled from its profile where it
    was planned on another: a finer layout's names include the first's, with other meanings)."""
    layout = layout_of(search.nlp)
    if getattr(plan.parameters, "layout", None) == layout:
        return plan.nlp_values
    return seed_values(plan, layout, search.case)


def _neighbour_fits(search: Search, neighbour: Plan | None, placement: Placement) -> Plan | None:
    """``neighbour`` as a start of ``search`` (None where it cannot start it): an optimal plan of the same draw and
    hold on the search's layout (its values sampled there from its profile)."""
    if not can_start(neighbour, search.case, placement):
        return None
    if not _free(search.case):
        return neighbour
    layout, own = layout_of(search.nlp), getattr(neighbour.parameters, "layout", None)
    if own is None or (draws_freely(own), holds(own)) != (draws_freely(layout), holds(layout)):
        return None
    return replace(neighbour, nlp_values=_on_layout(search, neighbour))


def _run_starts(
    search: Search,
    starts: list[dict[str, float]],
    neighbour: Plan | None,
    placement: Placement,
    confirm: bool,
    to_beat: float = math.inf,
) -> None:
    """One answer per case (``confirm``): the ``starts`` until two agree, exactly as with no neighbour (the
    cold solve), then a start from a neighbouring rate's plan competes with them; the search keeps the
    best, so the answer is the cold solve's or better. ``confirm`` False (fast, unconfirmed): the
    neighbour's start alone when it leads to a verified plan scoring below ``to_beat`` (the objective's
    ``to_beat`` is the baseline's score: a neighbour's start can end in a local optimum worse than
    waiting), else the ``starts`` until one verifies."""
    neighbour = _neighbour_fits(search, neighbour, placement)
    fits = neighbour is not None
    if confirm:
        search.multi_start(starts, placement, confirm=True)
        if fits and not search.stopped:
            search.attempt(neighbour.nlp_values, placement)
        return
    if fits:
        found = search.attempt(neighbour.nlp_values, placement)
        if found is not None and found[1] < to_beat:
            return
    search.multi_start(starts, placement, confirm=False)
