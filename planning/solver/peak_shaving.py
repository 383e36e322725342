"""From the motor to the grid: the power chain of a planned cycle, and the storage schedule that shaves the
grid's peak (the model and its signs: ``press.power``; the README's "From the motor to the grid").

**Peak shaving.** The cycle is cut into ``N`` equal intervals (edges ``t_0 = 0 .. t_N = T``, at most
:data:`SHAVING_STEP_S` long, :data:`SHAVING_MIN_INTERVALS` .. :data:`SHAVING_MAX_INTERVALS` of them); the storage
takes ``c_k`` from the bus or gives it ``d_k`` on interval ``k`` (constant there). The linear programme

    min z   s.t.  z >= P_bus(t_k) + c_k - d_k,  z >= P_bus(t_k+1) + c_k - d_k          (the grid at both ends)
                  E_k+1 = E_k + (eta_s c_k - d_k / eta_s) (t_k+1 - t_k),  E_N = E_0     (periodic)
                  0 <= E_k <= usable,  0 <= c_k, d_k <= max power

gives the lowest grid peak any schedule of the storage reaches on those samples (a periodic cycle: the storage
starts where it ends, the start free). Among the schedules with that peak (within :data:`PEAK_SLACK`), a second
programme takes the one that draws the least energy from the grid (``r x + (1 - r) max(x, 0)``, the interval's
mean ``x``), so that the storage does not cycle for nothing. The first is solved exactly in O(N) per trial
cap (:func:`least_peak`: the least storage a cap needs is a running sum's deepest fall, :func:`storage_needed`;
the tests hold it against the programme and SciPy's ``linprog``), the second by HiGHS through CasADi
(``casadi.conic``). Without storage the schedule is zero and the grid sees the bus.

**Energies per stroke** integrate the chain by the drive's Gauss-Legendre quadrature
(``planning.model.drive.quadrature``) with the schedule's edges among its breakpoints (the storage's power jumps
there); the storage's own terms are exact sums over the intervals. Over a cycle
``grid energy = forming work + gear + copper + converter + storage + resistor losses + storage change`` (the kinetic
energies return to their start; the verification checks it). Peaks are taken on the verification's dense grid and
on the edges together.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from planning.model.case import Case
from planning.model.drive import PowerFigures, quadrature
from planning.model.profile import Profile
from planning.tolerances import PEAK_BISECTION_TOL, PEAK_FALLBACK_SLACK, PEAK_SLACK
from press.dynamics import drive_state
from press.power import chain as bus_chain
from press.power import (
    grid_power,
    resistor_power,
    storage_loss,
    storage_rate,
)

SHAVING_STEP_S = 5e-3  # [s] the peak-shaving intervals are at most this long ...
SHAVING_MIN_INTERVALS = 400  # ... and at least this many ...
SHAVING_MAX_INTERVALS = 4000  # ... and at most this many per cycle
CAP_BISECTIONS = 30  # steps of bus_cap_for_limit: the cap to 1e-9 of the bus peak's overshoot
FLAT_SHARE = 0.05  # storage_to_flatten: the grid's peak within this share of the mean bus power
SCALE_W = 1e3  # the programmes in kW and kJ (HiGHS's tolerances are absolute)
# HiGHS's primal simplex: 2.5x its default (dual) on these programmes (1300 intervals: 0.05 s against 0.13 s)
_HIGHS = {"highs": {"output_flag": False, "log_to_console": False, "simplex_strategy": 4}}


@dataclass(frozen=True)
class Storage:
    """A DC-bus storage in inside units: ``usable`` [J], ``efficiency`` per direction, ``max_power`` [W]
    (``inf``: none)."""

    usable: float
    efficiency: float
    max_power: float = math.inf

    @classmethod
    def of(cls, case: Case) -> Storage | None:
        s = case.drive.storage
        if s is None:
            return None
        top = math.inf if s.max_power_kW is None else s.max_power_kW * 1e3
        return cls(s.usable_energy_kJ * 1e3, s.efficiency, top)


@dataclass(frozen=True)
class Schedule:
    """The storage's schedule on intervals between ``edges`` [s] (from the cycle's start): it takes
    ``charge`` [W] from the bus and gives ``discharge`` [W] on each; ``energy`` [J] at the edges;
    ``peak`` [W] the programme's grid peak on the edges."""

    edges: np.ndarray
    charge: np.ndarray
    discharge: np.ndarray
    energy: np.ndarray
    peak: float

    def interval(self, t: np.ndarray) -> np.ndarray:
        """The interval of each time ``t`` [s] (an edge belongs to the interval it starts)."""
        return np.clip(np.searchsorted(self.edges, t, side="right") - 1, 0, self.charge.size - 1)

    def offset(self, t: np.ndarray) -> np.ndarray:
        """The storage's draw on the bus at ``t`` [W]: charging minus discharging."""
        k = self.interval(t)
        return self.charge[k] - self.discharge[k]

    def energy_at(self, t: np.ndarray) -> np.ndarray:
        """The stored energy at ``t`` [J] (linear on each interval)."""
        return np.interp(t, self.edges, self.energy)


def shaving_edges(period: float) -> np.ndarray:
    """The peak-shaving intervals' edges over a cycle of ``period`` [s] (module docstring)."""
    n = int(np.clip(math.ceil(period / SHAVING_STEP_S), SHAVING_MIN_INTERVALS, SHAVING_MAX_INTERVALS))
    return np.linspace(0.0, period, n + 1)


def end_peaks(bus_W: np.ndarray) -> np.ndarray:
    """Each interval's peak bus power [W] from its two end samples ``bus_W`` alone."""
    return np.maximum(bus_W[1:], bus_W[:-1])


def interval_peaks(edges: np.ndarray, bus_W: np.ndarray, t: np.ndarray, bus_t_W: np.ndarray) -> np.ndarray:
    """Each interval's peak bus power [W]: its end samples ``bus_W`` at ``edges`` and the further samples
    ``bus_t_W`` at times ``t`` [s] inside it (the verification's dense grid), so that the grid's peak on every
    sample is what the programmes hold."""
    top = end_peaks(bus_W).copy()
    k = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, top.size - 1)
    np.maximum.at(top, k, bus_t_W)
    return top


def least_peak(edges: np.ndarray, top_W: np.ndarray, storage: Storage) -> float:
    """The lowest grid peak [W] any schedule of ``storage`` reaches over intervals between ``edges`` [s] with
    peak bus powers ``top_W`` (the first programme's optimum, module docstring), exactly: the least cap for
    which :func:`storage_needed` is within the usable energy, by bisection to :data:`PEAK_BISECTION_TOL`
    (the feasible end returned)."""
    lo, hi = float(np.min(top_W)), float(np.max(top_W))  # at the top the storage need not give anything
    tol = PEAK_BISECTION_TOL * max(abs(hi), abs(lo), SCALE_W)
    while hi - lo > tol:
        mid = (lo + hi) / 2
        if storage_needed(edges, top_W, mid, storage.efficiency, storage.max_power) <= storage.usable:
            hi = mid
        else:
            lo = mid
    return hi


def peak_programme(edges: np.ndarray, bus_W: np.ndarray, storage: Storage) -> float:
    """The first programme on the end samples ``bus_W`` solved as a linear programme (HiGHS) [W]: an
    independent check of :func:`least_peak` (the tests) and its fallback."""
    solver, args, ubx, _ = _programme(edges, bus_W, end_peaks(bus_W), storage)
    g = np.zeros(ubx.size)
    g[0] = 1.0
    first = solver(g=g, ubx=ubx, **args)
    _solved(solver, "peak")
    return float(first["cost"]) * SCALE_W


def shave(
    edges: np.ndarray,
    bus_W: np.ndarray,
    storage: Storage,
    regen_efficiency: float,
    top_W: np.ndarray | None = None,
    least_energy: bool = True,
) -> Schedule:
    """The storage schedule with the lowest grid peak over the intervals between ``edges`` [s] (bus power
    ``bus_W`` [W] at the edges, each interval's peak ``top_W``, by default its ends': :func:`least_peak`), and
    among those the one that draws the least energy from the grid (the second programme; module docstring).
    ``least_energy`` False: the lazy schedule at that peak instead (:func:`lazy_schedule`; the search's
    verifications, which need the peak and a schedule that reaches it, not the least energy)."""
    top = end_peaks(bus_W) if top_W is None else top_W
    peak = least_peak(edges, top, storage)
    if not least_energy:
        return lazy_schedule(edges, top, storage, peak)
    dt = np.diff(edges)
    r = regen_efficiency
    solver, args, ubx, (ic, id_, ie, iw) = _programme(edges, bus_W, top, storage)
    g = np.zeros(ubx.size)  # the least grid energy at that peak: sum dt (r (w - wbar) + ...) with x = mean + c - d
    g[ic:id_] = r * dt
    g[id_:ie] = -r * dt
    g[iw:] = (1 - r) * dt
    ubx[0] = (peak + PEAK_SLACK * max(abs(peak), SCALE_W)) / SCALE_W
    second = solver(g=g, ubx=ubx, **args)
    if not solver.stats().get("success", False):  # the exact peak at HiGHS's tolerances: a hair more room
        ubx[0] = (peak + PEAK_FALLBACK_SLACK * max(abs(peak), SCALE_W)) / SCALE_W
        second = solver(g=g, ubx=ubx, **args)
    _solved(solver, "grid energy")
    x = np.asarray(second["x"]).ravel()
    charge, discharge = x[ic:id_] * SCALE_W, x[id_:ie] * SCALE_W
    energy = np.append(x[ie:iw], x[ie]) * SCALE_W
    return Schedule(edges, charge, discharge, energy, float(np.max(top + charge - discharge)))


def lazy_schedule(edges: np.ndarray, top_W: np.ndarray, storage: Storage, cap_W: float) -> Schedule:
    """A periodic schedule that holds the grid at ``cap_W`` over intervals with peak bus powers ``top_W``
    (``cap_W`` at least :func:`least_peak`), in O(N): the storage gives what the cap needs, ``(P_k - cap)+``,
    and takes only what it will need, as late as it can. ``L_k``, the least energy before interval ``k`` from
    which the rest of the cycle can be served, follows backwards from
    ``L_k = max(0, L_k+1 + ((P_k - cap)+ / eta_s - eta_s (cap - P_k)+) dt_k)`` (two passes over the periodic
    cycle reach its fixed point); the schedule keeps ``E_k = L_k``, so it stays within ``[0, usable]`` (the
    deepest need, :func:`storage_needed`) and ends where it starts."""
    dt = np.diff(edges)
    eta = storage.efficiency
    need = np.maximum(top_W - cap_W, 0.0)
    room = np.minimum(np.maximum(cap_W - top_W, 0.0), storage.max_power)
    n = dt.size
    level = np.zeros(n + 1)
    for _ in range(2):  # the second pass starts from the first's level at the cycle's start
        level[n] = level[0]
        for k in range(n - 1, -1, -1):
            level[k] = max(0.0, level[k + 1] + (need[k] / eta - eta * room[k]) * dt[k])
    level[n] = level[0]
    rise = np.diff(level)  # = (eta c - d / eta) dt
    discharge = need
    charge = np.clip((rise / dt + discharge / eta) / eta, 0.0, room)  # clipped: rounding of the differences
    return Schedule(edges, charge, discharge, level, float(np.max(top_W + charge - discharge)))


def _programme(
    edges: np.ndarray, bus_W: np.ndarray, top_W: np.ndarray, storage: Storage
) -> tuple[ca.Function, dict, np.ndarray, tuple[int, int, int, int]]:
    """The peak-shaving programmes' rows (module docstring; the grid held at each interval's peak ``top_W``,
    the interval's mean from the end samples ``bus_W``) and a HiGHS solver for them: the solver, its fixed
    arguments, the variables' upper bounds (``z`` first) and the first columns of ``c, d, E, w``."""
    n = edges.size - 1
    dt = np.diff(edges)
    p = np.asarray(bus_W, dtype=float) / SCALE_W
    eta = storage.efficiency
    usable = storage.usable / SCALE_W
    top = storage.max_power / SCALE_W  # inf: no limit
    # variables: z, c (n), d (n), E (n; E_n = E_0), w (n; w >= 0, w >= the interval's mean net power)
    iz, ic, id_, ie, iw = 0, 1, 1 + n, 1 + 2 * n, 1 + 3 * n
    nv = 1 + 4 * n
    k = np.arange(n)
    rows, cols, vals, lo, hi = [], [], [], [], []

    def block(start: int, entries: list[tuple[np.ndarray, float | np.ndarray]], low: np.ndarray, high: np.ndarray):
        for col, val in entries:
            rows.append(start + k)
            cols.append(col)
            vals.append(np.broadcast_to(val, (n,)).astype(float))
        lo.append(low)
        hi.append(high)

    inf = np.full(n, np.inf)
    peaks = np.asarray(top_W, dtype=float) / SCALE_W
    block(0, [(np.full(n, iz), 1.0), (ic + k, -1.0), (id_ + k, 1.0)], peaks, inf)  # z - c + d >= the interval's peak
    block(n, [(ie + (k + 1) % n, 1.0), (ie + k, -1.0), (ic + k, -eta * dt), (id_ + k, dt / eta)], 0 * dt, 0 * dt)
    mean = (p[:-1] + p[1:]) / 2
    block(2 * n, [(iw + k, 1.0), (ic + k, -1.0), (id_ + k, 1.0)], mean, inf)  # w - c + d >= mean P
    A = ca.DM.triplet(
        np.concatenate(rows).tolist(), np.concatenate(cols).tolist(), ca.DM(np.concatenate(vals)), 3 * n, nv
    )
    solver = ca.conic("shaving", "highs", {"a": A.sparsity(), "h": ca.Sparsity(nv, nv)}, _HIGHS)
    lbx = np.concatenate([[-np.inf], np.zeros(3 * n), np.zeros(n)])
    ubx = np.concatenate([[np.inf], np.full(2 * n, top), np.full(n, usable), inf])
    args = {"a": A, "lba": np.concatenate(lo), "uba": np.concatenate(hi), "lbx": lbx}
    return solver, args, ubx, (ic, id_, ie, iw)


def _solved(solver: ca.Function, what: str) -> None:
    stats = solver.stats()
    if not stats.get("success", False):
        raise ArithmeticError(f"the peak-shaving programme ({what}) failed: {stats.get('return_status')}")


def storage_needed(edges: np.ndarray, top_W: np.ndarray, cap_W: float, efficiency: float, max_power_W: float) -> float:
    """The least usable energy [J] with which a storage of ``efficiency`` and ``max_power_W`` holds the grid at or
    below ``cap_W`` over the intervals between ``edges`` with peak bus powers ``top_W`` (``inf``: no size does),
    exactly: on interval ``k`` the grid peaks at ``P_k`` plus ``c_k - d_k``, so the storage must give ``(P_k - cap)+``
    (within its power) and may take up to ``(cap - P_k)+``; charging as much as it may, its store changes by
    ``a_k = (eta_s min((cap - P_k)+, max) - (P_k - cap)+ / eta_s) dt``, and the least store that never runs dry
    over the periodic cycle is the deepest fall of the running sum of ``a`` over any stretch of up to a cycle
    (none when a cycle's sum is negative: the storage would not end where it started)."""
    dt = np.diff(edges)
    need = np.maximum(top_W - cap_W, 0.0)
    if float(np.max(need)) > max_power_W:
        return math.inf
    room = np.minimum(np.maximum(cap_W - top_W, 0.0), max_power_W)
    a = (efficiency * room - need / efficiency) * dt
    if float(np.sum(a)) < 0:
        return math.inf
    walk = np.concatenate([[0.0], np.cumsum(np.concatenate([a, a]))])
    return float(np.max(np.maximum.accumulate(walk) - walk))


def bus_cap_for_limit(edges: np.ndarray, top_W: np.ndarray, storage: Storage, limit_W: float) -> float:
    """The highest cap [W] on the bus power such that, were the plan's bus power (its intervals' peaks ``top_W``)
    clipped at it, the storage could
    hold the grid at ``limit_W`` (bisection, :data:`CAP_BISECTIONS` steps, on :func:`storage_needed`): where the
    search sends the grid limit's NLP cap when the plan's grid peak is above the limit
    (``planning.model.limits.grid``)."""
    lo, hi = limit_W, float(np.max(top_W))
    for _ in range(CAP_BISECTIONS):
        mid = (lo + hi) / 2
        clipped = np.minimum(top_W, mid)
        if storage_needed(edges, clipped, limit_W, storage.efficiency, storage.max_power) <= storage.usable:
            lo = mid
        else:
            hi = mid
    return lo


def storage_to_flatten(edges: np.ndarray, bus_W: np.ndarray, top_W: np.ndarray, storage: Storage) -> float | None:
    """The least usable energy [J] of a storage like ``storage`` (its efficiency and power limit) with which the
    grid's peak over the intervals (peaks ``top_W``) comes within :data:`FLAT_SHARE` of the mean bus power (from
    the end samples ``bus_W``; :func:`storage_needed`); None when no size does (the storage's losses or its power
    limit keep the grid higher)."""
    dt = np.diff(edges)
    mean = float(np.sum(dt * (bus_W[1:] + bus_W[:-1]) / 2)) / float(edges[-1] - edges[0])
    needed = storage_needed(edges, top_W, (1 + FLAT_SHARE) * mean, storage.efficiency, storage.max_power)
    return None if math.isinf(needed) else needed


def no_schedule(edges: np.ndarray, bus_W: np.ndarray) -> Schedule:
    """Without storage: nothing taken or given; the grid peak is the bus's."""
    zero = np.zeros(edges.size - 1)
    return Schedule(edges, zero, zero, np.zeros(edges.size), float(np.max(bus_W)))


def chain(state: dict, case: Case) -> dict[str, np.ndarray]:
    """The power chain [W] at drive states (``press.dynamics.drive_state``): ``copper_loss_W``,
    ``electrical_power_W``, ``bus_power_W``."""
    d = case.drive
    loss = d.motor.copper_loss_at_rated_kW * 1e3
    return bus_chain(
        state["motor_torque_Nm"], state["motor_power_W"], d.motor.rated_torque_Nm, loss, d.converter_efficiency
    )


def _state(
    profile: Profile, case: Case, t: np.ndarray, forming: Any = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """The crank's state and the drive's with its power chain at times ``t`` [s from the cycle's start]
    (``forming(theta, omega)`` [N]: a pendulum stroke's forming force on either swing; None: a rotary cycle's)."""
    th, om, al, _ = profile.at_time(profile.t0 + t)
    s = drive_state(th, om, al, case.machine, case.drive_model, None if forming is None else forming(th, om))
    return th, om, al, {**s, **chain(s, case)}


def schedule_of(profile: Profile, case: Case) -> Schedule:
    """The storage schedule of a plan's cycle (``profile`` from TDC): :func:`shave` on the bus power at
    :func:`shaving_edges` (each interval's peak from its ends), or :func:`no_schedule` without storage."""
    edges = shaving_edges(profile.duration)
    return _schedule(edges, _state(profile, case, edges)[3]["bus_power_W"], None, case, True)


def _schedule(edges: np.ndarray, bus: np.ndarray, top: np.ndarray | None, case: Case, least_energy: bool) -> Schedule:
    storage = Storage.of(case)
    if storage is None:
        return no_schedule(edges, bus if top is None else top)
    return shave(edges, bus, storage, case.drive.regen_efficiency, top, least_energy)


def power_columns(schedule: Schedule, state: dict, t: np.ndarray, case: Case) -> dict[str, np.ndarray]:
    """The chain at times ``t`` [s] from the cycle's start with drive states ``state`` there [W, J]:
    ``copper_loss_W``, ``bus_power_W``, ``grid_power_W``, ``resistor_W``, ``storage_energy_J``."""
    c = chain(state, case)
    net = c["bus_power_W"] + schedule.offset(t)
    r = case.drive.regen_efficiency
    return {
        "copper_loss_W": c["copper_loss_W"],
        "bus_power_W": c["bus_power_W"],
        "grid_power_W": grid_power(net, r),
        "resistor_W": resistor_power(net, r),
        "storage_energy_J": schedule.energy_at(t),
    }


def _sizing(
    edges: np.ndarray, top: np.ndarray, storage: Storage | None, limit_kW: float | None, grid_peak_W: float
) -> tuple[float | None, float | None]:
    """``(bus cap [kW], storage [kJ])`` for the grid's limit: where the grid's peak is above it, the bus's cap
    at which the storage could hold it; the least storage that holds it on this plan (None where there is no
    limit or no storage, or no size would do: JSON has no infinity)."""
    if limit_kW is None or storage is None:
        return None, None
    needed = storage_needed(edges, top, limit_kW * 1e3, storage.efficiency, storage.max_power)
    cap = bus_cap_for_limit(edges, top, storage, limit_kW * 1e3) / 1e3 if grid_peak_W > limit_kW * 1e3 else None
    return cap, (needed / 1e3 if math.isfinite(needed) else None)


def power_figures(
    profile: Profile,
    case: Case,
    dense_t: np.ndarray,
    dense_state: dict,
    least_energy: bool = True,
    swings: Any = None,
) -> PowerFigures:
    """The power chain of a plan's cycle (``profile`` from TDC) per stroke, with the storage's schedule;
    peaks on the dense grid ``dense_t`` [s from the start] (drive states ``dense_state`` there) and on the
    schedule's edges, which the schedule holds (:func:`interval_peaks`). ``least_energy`` False: the lazy
    schedule at the same peak (:func:`shave`; a search's verification), whose energies differ. ``swings``: a
    pendulum stroke's ``(breakpoints [s], forming(theta, omega) [N])`` (``planning.model.drive.cycle_integrals``'
    own): the energies a cycle's, two strokes (the per-1000-strokes figure halved)."""
    d = case.drive
    breakpoints, forming = (None, None) if swings is None else swings
    strokes = 1 if swings is None else 2
    edges = shaving_edges(profile.duration)
    edge_state = _state(profile, case, edges, forming)[3]
    edge_bus = edge_state["bus_power_W"]
    dense_chain = {**dense_state, **chain(dense_state, case)}
    top = interval_peaks(edges, edge_bus, dense_t, dense_chain["bus_power_W"])
    schedule = _schedule(edges, edge_bus, top, case, least_energy)
    storage = Storage.of(case)
    nodes, weights = quadrature(profile, case, extra_edges=profile.t0 + schedule.edges, edges=breakpoints)
    t = nodes - profile.t0
    _, om, al, s = _state(profile, case, t, forming)
    cols = power_columns(schedule, s, t, case)
    i = case.drive_model.i

    def integral(values: np.ndarray) -> float:
        return float(np.sum(weights * values)) / 1e3  # [kJ]

    shaft = s["motor_power_W"]
    crank = s["crank_torque_Nm"] * om
    motor_kinetic = d.motor_inertia_kg_m2 * i * i * al * om  # d/dt of 1/2 J_m omega_m^2
    dt = np.diff(schedule.edges)
    eta_s = storage.efficiency if storage is not None else 1.0
    stored = storage_rate(schedule.charge, schedule.discharge, eta_s)
    edge_cols = power_columns(schedule, edge_state, schedule.edges, case)
    dense_cols = power_columns(schedule, dense_chain, dense_t, case)
    bus_peak = max(float(np.max(dense_cols["bus_power_W"])), float(np.max(edge_cols["bus_power_W"])))
    grid = np.concatenate([dense_cols["grid_power_W"], edge_cols["grid_power_W"]])
    times = np.concatenate([dense_t, schedule.edges])
    k = int(np.argmax(grid))
    th_peak = profile.at_time(profile.t0 + np.array([times[k]]))[0][0]
    grid_energy = integral(cols["grid_power_W"])
    limit = d.grid.peak_power_kW if d.grid is not None else None
    cap, for_limit = _sizing(edges, top, storage, limit, float(grid[k]))
    flatten = storage_to_flatten(edges, edge_bus, top, storage) if storage is not None else None
    return PowerFigures(
        copper_loss_kJ=integral(cols["copper_loss_W"]),
        converter_loss_kJ=integral(cols["bus_power_W"] - (shaft + cols["copper_loss_W"])),
        gear_loss_kJ=integral(shaft - crank - motor_kinetic),
        storage_loss_kJ=float(np.sum(dt * storage_loss(schedule.charge, schedule.discharge, eta_s))) / 1e3,
        resistor_loss_kJ=integral(cols["resistor_W"]),
        storage_change_kJ=float(np.sum(dt * stored)) / 1e3,
        bus_energy_kJ=integral(cols["bus_power_W"]),
        bus_supply_energy_kJ=integral(grid_power(cols["bus_power_W"], d.regen_efficiency)),
        grid_energy_kJ=grid_energy,
        grid_energy_kWh_per_1000_strokes=grid_energy / strokes / 3.6,
        mean_bus_power_kW=integral(cols["bus_power_W"]) / profile.duration,
        mean_grid_power_kW=grid_energy / profile.duration,
        bus_peak_kW=bus_peak / 1e3,
        grid_peak_kW=float(grid[k]) / 1e3,
        grid_peak_angle_deg=float(math.degrees(th_peak) % 360.0),
        grid_peak_sampled_kW=schedule.peak / 1e3,
        storage_usable_kJ=storage.usable / 1e3 if storage is not None else 0.0,
        storage_swing_kJ=float(np.ptp(schedule.energy)) / 1e3,
        storage_start_kJ=float(schedule.energy[0]) / 1e3,
        storage_min_kJ=float(np.min(schedule.energy)) / 1e3,
        storage_max_kJ=float(np.max(schedule.energy)) / 1e3,
        storage_peak_power_kW=float(max(np.max(schedule.charge), np.max(schedule.discharge), 0.0)) / 1e3,
        grid_limit_kW=limit,
        bus_cap_for_limit_kW=cap,
        storage_for_limit_kJ=for_limit,
        storage_to_flatten_kJ=None if flatten is None else flatten / 1e3,
        schedule=schedule,
    )
