"""Which math module evaluates an expression: numpy for numbers and arrays, CasADi for its symbols.

Every pure function of the project (kinematics, law shapes, segments) works on both, so one formula
serves the optimizer and the verification. CasADi is not imported here: a value can only be a CasADi
symbol when CasADi is already loaded, so numpy-only users never load it.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np


def math_module(*values: Any) -> Any:
    """``casadi`` when any of ``values`` is a CasADi SX/MX/DM, else ``numpy`` (sin, cos, sqrt, exp, log)."""
    ca = sys.modules.get("casadi")
    if ca is None:
        return np
    try:
        symbols = (ca.SX, ca.MX, ca.DM)
    except AttributeError:  # CasADi half imported by another thread (the server's): no value is its symbol yet
        return np
    return ca if any(isinstance(v, symbols) for v in values) else np
