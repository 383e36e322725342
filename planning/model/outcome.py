"""How a run ends, as one type: the CLI's exit statuses, the page's answers and the sweep's and trade-off's
rows all derive from :class:`Outcome` (ruckig's ``Result`` is the model: an enum, not text compared in
many places).

Its value is the word the files and the page show (``sweep.csv``'s ``status`` column, the page's
``status``); a row read back from a file is turned into an :class:`Outcome` by :meth:`Outcome.of`.
"""

from __future__ import annotations

import enum


class Outcome(str, enum.Enum):
    """How a solve (or a request for one) ended.

    - ``VERIFIED``: a plan that the dense verification passed;
    - ``INFEASIBLE``: a limit provably cannot be met (found before or without solving);
    - ``NO_PLAN``: every start stopped without a plan (not a proof that none exists);
    - ``UNVERIFIED``: the solver converged, the dense verification rejected every plan;
    - ``BAD_INPUT``: the case, an option or a request is wrong (nothing solved);
    - ``INTERRUPTED``: stopped before it ended (Ctrl-C; on the page, a newer edit of the same tab);
    - ``TERMINATED``: stopped by SIGTERM;
    - ``ERROR``: a fault of pressplan's own (a sweep row that records it instead of stopping).
    """

    VERIFIED = "verified"
    INFEASIBLE = "infeasible"
    NO_PLAN = "no verified plan"
    UNVERIFIED = "unverified"
    BAD_INPUT = "bad input"
    INTERRUPTED = "interrupted"
    TERMINATED = "terminated"
    ERROR = "error"

    def __str__(self) -> str:
        return self.value

    @property
    def succeeded(self) -> bool:
        """Whether the run ended with a verified plan."""
        return self is Outcome.VERIFIED

    @property
    def exit_code(self) -> int:
        """The CLI's exit status: 0 a verified plan, 2 bad input, 3 no feasible or no verified plan, 130
        interrupted (128 + SIGINT), 143 terminated (128 + SIGTERM), 1 a fault."""
        return EXIT_CODES[self]

    @property
    def without_plan(self) -> bool:
        """A planning outcome without a verified plan (exit 3): infeasible, no plan, unverified."""
        return self in (Outcome.INFEASIBLE, Outcome.NO_PLAN, Outcome.UNVERIFIED)

    @classmethod
    def of(cls, word: object) -> Outcome:
        """The outcome a file or a request writes as ``word`` (an unknown word: :attr:`ERROR`)."""
        try:
            return cls(word)
        except ValueError:
            return cls.ERROR


EXIT_CODES = {
    Outcome.VERIFIED: 0,
    Outcome.BAD_INPUT: 2,
    Outcome.INFEASIBLE: 3,
    Outcome.NO_PLAN: 3,
    Outcome.UNVERIFIED: 3,
    Outcome.INTERRUPTED: 130,
    Outcome.TERMINATED: 143,
    Outcome.ERROR: 1,
}
