"""The number types of a case file: each a float in a stated range, in the unit its key names.

Every number of a case lies in a stated range, wide enough for any press and narrow enough that no
arithmetic on a case can overflow or underflow (the reader's guarantee; see the README). The case model
(``planning.model.case``) and the limits (``planning.model.limits``), which declare their own keys, both
use these types.
"""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field

from planning.tolerances import SAME_RELATIVE

RPM = 2.0 * math.pi / 60.0  # [rad/s] per rpm
HIGHEST_DECIMALS = 4  # a highest allowed value is printed rounded down to this many decimals


def rounded_down(value: float, decimals: int = HIGHEST_DECIMALS) -> str:
    """``value`` printed rounded down to ``decimals`` decimals: a highest allowed value typed back as it is
    printed is allowed (``10.19937`` prints ``10.1993``)."""
    if not math.isfinite(value):
        return str(value)
    scale = 10.0**decimals
    nudged = value * scale * (1 + SAME_RELATIVE)  # a value on a printed digit up to round-off is that digit
    return f"{math.floor(nudged) / scale:.{decimals}f}"


Length = Annotated[float, Field(ge=0.1, le=20_000)]  # [mm] press dimensions
Offset = Annotated[float, Field(ge=-20_000, le=20_000)]  # [mm] a sideways offset, either side
Height = Annotated[float, Field(ge=0, le=40_000)]  # [mm above BDC]
Angle = Annotated[float, Field(ge=0, lt=360)]  # [deg from TDC]
Seconds = Annotated[float, Field(ge=1e-3, le=1e5)]  # [s]
CrankSpeed = Annotated[float, Field(ge=1e-3, le=1e4)]  # [rpm]
SliderSpeed = Annotated[float, Field(ge=1e-3, le=1e6)]  # [mm/s]
SliderAccel = Annotated[float, Field(ge=1e-2, le=1e9)]  # [mm/s^2]
CrankAccel = Annotated[float, Field(ge=1e-4, le=1e6)]  # [rad/s^2]
CrankJerk = Annotated[float, Field(ge=1e-4, le=1e9)]  # [rad/s^3]
ShapeValue = Annotated[float, Field(gt=0, le=1e3)]  # a law's shape parameter (checked per law)
SourceNumber = Annotated[float, Field(ge=-1e9, le=1e9)]  # a number printed by the source
SourceTime = Annotated[float, Field(ge=0, le=1e4)]  # [s] a time printed by the source
SourceDuration = Annotated[float, Field(gt=0, le=1e4)]  # [s]
SourceSpeed = Annotated[float, Field(gt=0, le=1e5)]  # [rpm]
Mass = Annotated[float, Field(ge=0, le=1e7)]  # [kg]
Inertia = Annotated[float, Field(ge=0, le=1e9)]  # [kg m^2]
ForceKN = Annotated[float, Field(ge=0, le=1e6)]  # [kN]
Torque = Annotated[float, Field(ge=1e-3, le=1e8)]  # [N m]
MotorSpeed = Annotated[float, Field(ge=1e-2, le=1e5)]  # [rpm]
ForcePoint = Annotated[list[float], Field(min_length=2, max_length=2)]  # [height above BDC mm, force kN]
ForceTable = Annotated[list[ForcePoint], Field(min_length=2, max_length=500)]
