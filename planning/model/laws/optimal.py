"""The jerk-limited optimal motion as a law of the registry: outside the draw the crank speed is free.

It has no halves and no fixed shape: its transcription is its own (``FREE``): the solver
(``planning.solver.optimal``) plans a piecewise-constant jerk profile from theta3 round to theta2
(``planning.model.free_profile``, ``planning.solver.free_nlp``) under the case's crank-jerk limit. The class is
here so that the law is named, listed and described like the others.
"""

from __future__ import annotations

from planning.model.laws.base import FREE, Law


class OptimalLaw(Law):
    name = "optimal"
    continuity = "acceleration"
    source = "this project: jerk-limited time-optimal profile, piecewise-constant jerk"
    transcription = FREE
    needs_jerk_limit = True
