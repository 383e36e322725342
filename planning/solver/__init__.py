"""Solving: the NLPs of the motion laws and the time-optimal bound (CasADi expressions), the IPOPT
wrapper, the search over starts, the solves (``optimize.solve`` dispatches), the independent dense
verification and the typed outcomes.

IPOPT's linear solver calls the OpenBLAS that CasADi ships, which starts a thread per core. The
systems here are small (at most a few thousand rows), so the threads only contend: a solve is 10-25 %
faster on one, and a sweep's or trade-off's worker processes, each with a thread per core, would
oversubscribe the cores (a 7-rate trade-off on 2 workers took 16 s instead of 10 s). OpenBLAS reads
its thread count when CasADi's IPOPT plugin loads it, at the first solver built; a value set by the
user is kept.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
