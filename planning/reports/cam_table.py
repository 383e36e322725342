"""The cam table for a drive: crank angle and its derivatives against a virtual master axis.

One stroke is one master revolution, master 0 ... < 360 deg, with master 0 at the first row of
``trajectory.csv`` (TDC). A drive that turns the master at ``SPM * 6`` deg/s reproduces the plan. A pendulum
plan's master turn is its cycle of two swings (from the forward swing's start): ``SPM * 3`` deg/s.
The derivatives are with respect to the master angle in degrees (the form PLCopen XYVA tables and
TwinCAT motion functions take): with the master speed ``w_m = 2 pi / period`` [rad/s],

    dcrank_dmaster    = omega / w_m                          [deg/deg]
    d2crank_dmaster2  = alpha / w_m^2 * (pi / 180)           [deg/deg^2]
    d3crank_dmaster3  = jerk / w_m^3 * (pi / 180)^2          [deg/deg^3]
"""

from __future__ import annotations

import math

import numpy as np

from planning.model.laws import LAWS
from planning.model.plan import Plan

CAM_COLUMNS = ("master_deg", "crank_angle_deg", "dcrank_dmaster", "d2crank_dmaster2", "d3crank_dmaster3")
DEFAULT_POINTS = 3600


def cam_table(plan: Plan, points: int = DEFAULT_POINTS) -> np.ndarray:
    """``points`` rows over one stroke; columns :data:`CAM_COLUMNS`."""
    if points < 2:
        raise ValueError("a cam table needs at least 2 points")
    master = np.arange(points) * (360.0 / points)
    t = master / 360.0 * plan.period
    th, om, al, je = plan.profile.at_time(t)
    w_m = 2 * math.pi / plan.period
    k = math.pi / 180.0
    return np.column_stack([master, np.degrees(th), om / w_m, al / w_m**2 * k, je / w_m**3 * k**2])


def cam_header(plan: Plan, case_name: str, points: int) -> str:
    """The ``#`` comment lines that head ``cam_table.csv`` (the column row follows them)."""
    origin = (
        "the forward swing's start (at rest, first row of trajectory.csv); one master turn is two swings"
        if plan.slave_turn_deg == 0.0
        else "TDC (crank 0 deg, first row of trajectory.csv)"
    )
    return "\n".join(
        [
            f"# pressplan cam table for {case_name}",
            f"# period_s = {plan.period:.9f}; spm = {plan.spm:.6f}; master speed = {360.0 / plan.period:.6f} deg/s",
            f"# points = {points}; master 0 = {origin}; master 0 ... <360 deg",
            "# units: master_deg, crank_angle_deg [deg]; dcrank_dmaster [deg/deg]; d2crank_dmaster2 [deg/deg^2]; "
            "d3crank_dmaster3 [deg/deg^3]",
            "# angle datum: crank angle from top dead centre (TDC = 0 deg), increasing with rotation",
            "# continuity: " + _continuity(plan),
        ]
    )


def _continuity(plan: Plan) -> str:
    """The header's continuity statement, from the plan's motion law."""
    law = LAWS[plan.motion_law]
    where = f"({plan.motion_law}, {len(plan.profile.segments)} segments)"
    over = "the two swings" if plan.slave_turn_deg == 0.0 else "the stroke"
    if law.continuity == "jerk":
        return f"crank position, speed, acceleration and jerk continuous (C3), cyclic over {over} {where}"
    return f"crank position, speed and acceleration continuous (C2), cyclic over {over}; jerk steps {where}"
