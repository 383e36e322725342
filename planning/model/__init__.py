"""The model of the motion: the case (read and validated), the motion laws, the press cycle, the
closed-form profile and the solved plan. Pure data and formulas; no solver, no files but the case."""
