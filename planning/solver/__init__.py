"""Solving: the cycle NLP of each motion law and the time-optimal bound (CasADi expressions), the
IPOPT wrapper, the orchestrator of named steps, the independent dense verification and the typed
outcomes."""
