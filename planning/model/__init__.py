"""The model of the motion: the case (read and validated), its limits (``planning.model.limits``: each
states its rows, checks and bound parts once), the motion laws, the press cycle, the closed-form
profile, the solved plan and the drive's figures of it. Pure data and formulas: nothing here imports
the solver, and no file is read but the case."""
