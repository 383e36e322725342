"""What a solve ends with when there is no verified plan: one exception type per outcome.

Each carries data, not only text: the case field that cannot be met, the value, what would be needed;
or the verification check that failed; and its :class:`~planning.model.outcome.Outcome`, from which the
CLI's exit status, the page's answer and a sweep's row derive.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from planning.model.outcome import Outcome

if TYPE_CHECKING:
    from planning.solver.verify import Check


class PlanningError(Exception):
    """No verified plan for a case. ``outcome`` says which, ``reason`` is the one-line message."""

    outcome: ClassVar[Outcome] = Outcome.NO_PLAN

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(f"{self.outcome}: {reason}")

    def __reduce__(self) -> tuple:
        """Pickled as it is, its data too (a call made in a worker process raises it there: ``planning.solver.ahead``);
        an exception's default pickling calls the class with its message alone, which a subclass does not take."""
        return _restored, (type(self), self.args, self.__dict__)


def _restored(cls: type[PlanningError], args: tuple, state: dict) -> PlanningError:
    """A :class:`PlanningError` of ``cls`` with its message ``args`` and data ``state`` (its ``__reduce__``)."""
    error = cls.__new__(cls)
    error.args = args
    error.__dict__.update(state)
    return error


class Infeasible(PlanningError):
    """A limit provably cannot be met (found before or without solving).

    ``limit``: the dotted case field that cannot be met (None when several conflict); ``value``: its
    value in the case; ``needed``: what it would have to be, when one number says it; ``angle_deg``:
    where on the cycle, when one angle says it.
    """

    outcome = Outcome.INFEASIBLE

    def __init__(
        self,
        reason: str,
        limit: str | None = None,
        value: float | None = None,
        needed: float | None = None,
        angle_deg: float | None = None,
    ):
        super().__init__(reason)
        self.limit = limit
        self.value = value
        self.needed = needed
        self.angle_deg = angle_deg


class NoPlanFound(PlanningError):
    """Every start of the solver stopped without a plan (``attempts`` say how each ended). Not a proof
    that the limits cannot be met: the message says so and names the closest limit."""

    outcome = Outcome.NO_PLAN

    def __init__(self, reason: str, attempts: tuple[Attempt, ...] = ()):
        super().__init__(reason)
        self.attempts = attempts


class Unverified(PlanningError):
    """The solver converged but the dense verification rejected the plan: ``check`` is the first
    failed check (its value, limit and unit)."""

    outcome = Outcome.UNVERIFIED

    def __init__(self, reason: str, check: Check):
        super().__init__(reason)
        self.check = check


@dataclass(frozen=True)
class Attempt:
    """How one start of the cycle NLP ended without a verified plan.

    ``solver_status``: IPOPT's return status when it stopped unconverged (else None), with the
    constraint block ``worst_block`` violated most and by how much (``violation``); ``check``: the
    failed verification check when it converged to a plan that did not verify.
    """

    solver_status: str | None = None
    worst_block: str = ""
    violation: float = 0.0
    check: Check | None = None
    case_field: str = ""  # the case field behind the worst block or the failed check

    def describe(self) -> str:
        """One line: what stopped this start, with the case field a user can change."""
        if self.check is not None:
            c = self.check
            where = f" ({self.case_field})" if self.case_field else ""
            return f"verification failed: {c.name} = {c.value:.6g} {c.unit} (limit {c.limit:.6g}){where}"
        return f"the solver stopped ({self.solver_status}) short of {self.case_field or self.worst_block}"
