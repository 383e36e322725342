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

    def saving_pct(self, key: str) -> float:
        """How much lower this plan's drive figure ``key`` (``rms_motor_torque_Nm``, ``supply_energy_kJ`` or,
        from the power figures, ``grid_peak_kW``: what an objective at a rate saves) is than the baseline's at
        the same rate [%] (needs ``at_rate``)."""
        base, ours = ((s.drive.power if key == GRID_PEAK else s.drive) for s in (self.at_rate.baseline, self))
        base, ours = getattr(base, key), getattr(ours, key)
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
    if objective == "min-energy" and d.power is not None:
        return d.power.bus_supply_energy_kJ
    return d.rms_motor_torque_Nm**2 if objective == "min-rms-torque" else d.supply_energy_kJ
