"""What a solve returns: a verified plan with what was computed of it, once.

pvlib's ModelChainResult is the model: one field per step, computed once and carried, so the reports,
``result.json``, the sweep and the trade-off read the figures and never compute them again.
"""

from __future__ import annotations

from dataclasses import dataclass

from planning.model.drive import DriveFigures
from planning.model.plan import Plan
from planning.solver.verify import Verification


@dataclass(frozen=True)
class Solution:
    """A verified ``plan``, its ``verification``, the drive's figures of it (``drive``, a case with a drive;
    ``planning.model.drive``) and, for an objective at the line's rate, what that solve found
    (``at_rate``)."""

    plan: Plan
    verification: Verification
    drive: DriveFigures | None = None
    at_rate: AtRate | None = None

    def saving_pct(self, key: str) -> float:
        """How much lower this plan's drive figure ``key`` (``rms_motor_torque_Nm`` or ``supply_energy_kJ``,
        what an objective at a rate saves) is than the baseline's at the same rate [%] (needs ``at_rate``)."""
        base = getattr(self.at_rate.baseline.drive, key)
        return 100.0 * (base - getattr(self.drive, key)) / base if base else 0.0


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
    time) for ``min-rms-torque``, else the energy drawn from the supply per stroke [kJ]."""
    d = solution.drive
    return d.rms_motor_torque_Nm**2 if objective == "min-rms-torque" else d.supply_energy_kJ
