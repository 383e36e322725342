"""What a solve returns: a verified plan with what was computed of it, once.

pvlib's ModelChainResult is the model: one field per step, computed once and carried, so the reports,
``result.json``, the sweep and the trade-off read the figures and never compute them again.
"""

from __future__ import annotations

from dataclasses import dataclass

from planning.model.drive import DriveFigures
from planning.model.plan import Plan
from planning.solver.verify import Evaluation, Verification

GRID_PEAK = "grid_peak_kW"  # the power figures' key of the grid's peak
ENERGY = "energy_kJ"  # the energy per stroke the objectives weigh (Solution.energy_kJ)


@dataclass(frozen=True)
class Solution:
    """A verified ``plan``, its ``evaluation`` (the dense re-simulation, every check and, with a drive, the
    drive's figures: ``planning.solver.verify.Evaluation``, made once) and, for an objective at the line's
    rate, what that solve found (``at_rate``)."""

    plan: Plan
    evaluation: Evaluation
    at_rate: AtRate | None = None

    @property
    def verification(self) -> Verification:
        """The checks of the plan (the evaluation's)."""
        return self.evaluation.verification

    @property
    def drive(self) -> DriveFigures | None:
        """The drive's figures of the plan (the evaluation's; a case with a drive)."""
        return self.evaluation.drive

    @property
    def energy_kJ(self) -> float:
        """The energy per stroke the objectives weigh and report [kJ]: with the drive's electrical side at the
        bus, its copper and converter losses counted (``power.bus_supply_energy_kJ``), else at the motors'
        shaft (``drive.supply_energy_kJ``); both take back ``drive.regen_efficiency`` of what is returned."""
        power = self.drive.power
        return power.bus_supply_energy_kJ if power is not None else self.drive.supply_energy_kJ

    def figure(self, key: str) -> float:
        """A drive figure by name: :attr:`energy_kJ` (``energy_kJ``), the grid's peak (``grid_peak_kW``), or
        a field of the drive's figures (``rms_motor_torque_Nm``, ...)."""
        if key == ENERGY:
            return self.energy_kJ
        if key == GRID_PEAK:
            return self.drive.power.grid_peak_kW
        return getattr(self.drive, key)

    def saving_pct(self, key: str) -> float:
        """How much lower this plan's drive figure ``key`` (:meth:`figure`: ``rms_motor_torque_Nm``,
        ``energy_kJ``, ``grid_peak_kW``: what an objective at a rate saves) is than the baseline's at the
        same rate [%] (needs ``at_rate``)."""
        base, ours = self.at_rate.baseline.figure(key), self.figure(key)
        return 100.0 * (base - ours) / base if base else 0.0


@dataclass(frozen=True)
class AtRate:
    """What a solve at the line's rate found: the ``objective``, ``target_spm``, the fastest rate the
    limits allow (``fastest_spm``), the ``baseline`` it beats (the max-SPM plan run at the rate, spare time
    in the transfer dwell), and whether the answer is the optimiser's plan (``improved``; False when no
    solve beat the baseline)."""

    objective: str
    target_spm: float
    fastest_spm: float
    baseline: Solution
    improved: bool


def objective_value(solution: Solution, objective: str) -> float:
    """The exact objective of a verified plan: RMS torque squared [N^2 m^2] (the heat over the fixed cycle
    time) for ``min-rms-torque``, the grid's peak [kW] with the case's storage for ``min-grid-peak`` (its
    power figures, ``Case.electrical``), else the energy drawn from the supply per stroke [kJ] (with the
    drive's electrical side: at the bus, its losses counted, before any storage)."""
    d = solution.drive
    if objective == "min-grid-peak":
        return d.power.grid_peak_kW
    return d.rms_motor_torque_Nm**2 if objective == "min-rms-torque" else solution.energy_kJ
