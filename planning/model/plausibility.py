"""Entries that are valid but probably not meant: warnings beside the field, never refusals.

A case passes the reader whenever it can be planned; some such cases still look like a typing slip. Each
warning names its field and says why it looks odd and what was probably meant:

- **a key angle in radians**: ``closing_deg`` below 2 pi (6.28) makes the robot's window end a few degrees
  after TDC; read as radians it would be a typical closing angle (``1.15`` -> 65.9 deg);
- **a robot window that barely exists**: the slide above the safety height for less than 10 deg of crank
  on either side of TDC (the safety height within a hair of the stroke's top);
- **a draw that ends in the die zone**: the slide still below the die height at theta3, so the die-height
  speed limit holds the return back until the slide leaves the zone, whatever the motion law.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

RADIANS_LOOK = 2 * math.pi  # [deg] a closing angle below this reads as radians typed into a degree field
NARROW_WINDOW_DEG = 10.0  # [deg] a robot window narrower than this on either side of TDC is odd


@dataclass(frozen=True)
class EntryWarning:
    """Why the value of ``field`` looks unintended (one line)."""

    field: str
    message: str


def warnings_of(case: Any) -> list[EntryWarning]:
    """The warnings of a valid case, in the order of its fields."""
    k = case.key_points
    out = []
    if 0.0 < k.closing_deg < RADIANS_LOOK:
        out.append(
            EntryWarning(
                "key_points.closing_deg",
                f"{k.closing_deg:g} deg ends the robot's window {k.closing_deg:g} deg after TDC; if it was typed in "
                f"radians, {k.closing_deg:g} rad = {math.degrees(k.closing_deg):.1f} deg",
            )
        )
    elif k.closing_deg < NARROW_WINDOW_DEG or 360.0 - k.opening_deg < NARROW_WINDOW_DEG:
        out.append(
            EntryWarning(
                "key_points.closing_deg",
                f"the robot's window runs from {k.opening_deg:g} to {k.closing_deg:g} deg: less than "
                f"{NARROW_WINDOW_DEG:g} deg on one side of TDC",
            )
        )
    m = case.machine
    h3 = float(m.height(math.radians(k.draw_end_deg)))
    die = case.limits.die_height_mm
    if h3 < die < m.stroke:
        leave = math.degrees(float(m.angles_at_height(die)[1]))
        out.append(
            EntryWarning(
                "key_points.draw_end_deg",
                f"the slide is still below limits.die_height_mm = {die:g} mm at theta3 = {k.draw_end_deg:.2f} deg "
                f"({h3:.2f} mm); it leaves the die zone at {leave:.2f} deg. Until then the die-height speed limit "
                "holds the return back, whatever the motion law",
            )
        )
    return out
