"""``pressplan new``: a first case file, commented field by field, that passes ``check`` and solves.

One template per mechanism (its press section, key angles where that press reaches the usual heights,
a process and limits that suit it) and, with a drive, the drive section of a press of that size. The
figures are the shipped examples' (``cases/``): a starting point to edit, not a recommendation.
"""

from __future__ import annotations

from pathlib import Path

MECHANISMS = ("crank-slider", "link-drive", "knuckle-joint")

_HEAD = """\
# {name}: a pressplan case. Edit the numbers for your press and process, then
#   pressplan check {path}     (the key points and the limits at the draw speed, no solve)
#   pressplan solve {path}     (the fastest verified cycle, written to out/{name}/)
# Units are in the key names: mm, deg, s, rpm, mm/s, mm/s^2, kN, kg, N m. Crank angles count from top dead
# centre (TDC) in the direction of rotation; heights from bottom dead centre (BDC), upward.
name: {name}
title: {title}
"""

# the side panel's process and limits (the published case's), for the presses that draw it
_SIDE_PANEL_PROCESS = """\
process:
  safety_height_mm: 700              # the slide stays at or above this while the robot moves a part
  transfer_time_s: 2.0               # the robot needs at least this long from theta4 to theta1
"""
_SIDE_PANEL_LIMITS = """\
limits:
  draw_start_speed_mm_s: 300         # the slide's speed when the die meets the blank, at most
  die_height_mm: 10                  # at and below this height ...
  die_speed_mm_s: 80                 # ... the slide moves slower than this
  slider_accel_mm_s2: 3500           # |slide acceleration| everywhere, at most
"""
_SIDE_PANEL_FORCE = "  forming_force_kN: [[200, 0], [180, 4500], [60, 6000], [10, 4000], [0, 1500]]"

_PRESS = {
    "crank-slider": """\
press:
  mechanism: crank-slider
  crank_radius_mm: 450               # half the stroke
  rod_length_mm: 1200                # crank pin to the slide's pin
  offset_mm: 0                       # the slide's line to the side of the crank axis (0: in line)
  # capacity:                        # optional: the press's rating, its tonnage curve (a forming force table
  #   rated_force_kN: 8000           #   above it is refused) and, with a drive, the crank torque it allows
  #   rated_distance_mm: 13          #   (rated force x the crank's lever at the rated distance above BDC)
key_points:                          # crank angle from TDC [deg], in this order
  closing_deg: 66                    # theta1: the slide passes the robot's safety height going down
  draw_start_deg: 131.5              # theta2: the upper die meets the blank; the draw starts
  draw_end_deg: 195                  # theta3: the draw ends (BDC is at 180 deg on an in-line press)
  opening_deg: 294                   # theta4: the slide is back above the safety height
"""
    + _SIDE_PANEL_PROCESS
    + "  # draw_speed_rpm: 6.7              # a fixed crank speed for the draw; leave out to let the planner choose\n"
    + "  # hold_time_s: 0.3                 # a hold at the bottom (coining): the slide stands this long after the\n"
    + "  # hold_height_mm: 0                #   draw, here at BDC (theta3 must lie before it: docs/modes.md)\n"
    + "  # draw_slide_speed_mm_s: 60        # or the draw at a constant slide speed (planner.motion_law: optimal)\n"
    + _SIDE_PANEL_LIMITS
    + """\
  # crank_speed_rpm: 30              # optional: the crank's top speed, acceleration, jerk, the slide's top
  # crank_accel_rad_s2: 10           #   speed anywhere (slider_speed_mm_s); the optimal law needs a jerk
  # crank_jerk_rad_s3: 60            #   limit
""",
    "link-drive": """\
press:
  mechanism: link-drive              # a six-bar link drive; sketch and letters: docs/link-drive.svg
  link_drive:
    crank_radius_mm: 235             # (a) the eccentric
    ternary_rocker_side_mm: 720      # (b) ternary link, crank pin to the rocker's joint
    rocker_mm: 810                   # (c)
    rocker_pivot_x_mm: 1060          # (d) the rocker's pivot at (-d, -f) from the crank centre
    rocker_pivot_y_mm: 340           # (f)
    ternary_angle_deg: 134           # (tht) between the ternary link's two sides
    ternary_rod_side_mm: 1060        # (m) ternary link, crank pin to the connecting rod's joint
    rod_length_mm: 1060              # (g) connecting rod to the slide
    slide_offset_mm: 0               # (h)
key_points:                          # crank angle from this press's TDC [deg] (`check` prints where BDC is)
  closing_deg: 56                    # theta1: the slide passes the robot's safety height going down
  draw_start_deg: 143.5              # theta2: the upper die meets the blank; the draw starts
  draw_end_deg: 233                  # theta3: the draw ends (BDC is at 220.9 deg on this press)
  opening_deg: 316.3                 # theta4: the slide is back above the safety height
"""
    + _SIDE_PANEL_PROCESS
    + _SIDE_PANEL_LIMITS,
    "knuckle-joint": """\
press:
  mechanism: knuckle-joint           # a knuckle-joint (toggle) press; sketch and letters: docs/knuckle-joint.svg
  knuckle_joint:
    crank_radius_mm: 205             # (a)
    rod_length_mm: 1010              # (b) crank pin to the knuckle
    rocker_mm: 910                   # (c) the upper link, from its pivot to the knuckle
    rocker_pivot_x_mm: 800           # (d) the upper link's pivot at (d, e) from the crank centre
    rocker_pivot_y_mm: 810           # (e)
    main_rod_mm: 910                 # (g) knuckle to the slide
    slide_offset_mm: 0               # (h) the slide's line, to the side of the pivot
key_points:                          # crank angle from this press's TDC [deg] (`check` prints where BDC is)
  closing_deg: 49                    # theta1: the slide passes the transfer's safety height going down
  draw_start_deg: 127.8              # theta2: the die closes on the blank
  draw_end_deg: 216                  # theta3: the part is struck and released (BDC at 179.9 deg)
  opening_deg: 307                   # theta4: the slide is back above the safety height
process:
  safety_height_mm: 120              # the slide stays at or above this while the transfer moves
  transfer_time_s: 0.8               # the transfer needs at least this long from theta4 to theta1
limits:
  draw_start_speed_mm_s: 60          # the slide's speed when the die meets the blank, at most
  die_height_mm: 2                   # at and below this height ...
  die_speed_mm_s: 40                 # ... the slide moves slower than this
  slider_accel_mm_s2: 10000          # |slide acceleration| everywhere, at most
""",
}

_PLANNER = """\
planner:
  motion_law: improved-s-curve       # or seven-segment, quintic, cycloidal, logistic, optimal (`pressplan laws`)
  placement: free                    # free: the motion may pass theta1/theta4 anywhere in its stages
  # mode: pendulum                   # swing through BDC and back, each swing a stroke (docs/modes.md)
"""

_FORCE = {
    "crank-slider": _SIDE_PANEL_FORCE,
    "link-drive": _SIDE_PANEL_FORCE,
    "knuckle-joint": "  forming_force_kN: [[2.8, 0], [1.5, 800], [0.6, 3000], [0.2, 5200], [0, 6000]]",
}

_DRIVE = {
    "crank-slider": """\
drive:                               # the motor and what it moves; with it the plan keeps the motor's limits
  slide_mass_kg: 65000               # slide and upper die
  rod_mass_kg: 8000                  # the connecting rods
  rod_cg_from_crank_pin_mm: 480      # the rods' centre of gravity, from the crank pin
  crank_inertia_kg_m2: 30000         # crankshaft, eccentrics and bull gears
  counterbalance_kN: 600             # air cylinders carrying the slide and die
  gear_ratio: 30                     # motor turns per crank turn
  gear_efficiency: 0.93
  motor_inertia_kg_m2: 8             # the motors and their pinions, about the motor axis
  motor:                             # the servo motors together
    peak_torque_Nm: 72000
    rated_torque_Nm: 20000           # the RMS torque over a cycle stays at or below this
    base_speed_rpm: 500
    max_speed_rpm: 1000
""",
    "link-drive": """\
drive:                               # the motor and what it moves; with it the plan keeps the motor's limits
  slide_mass_kg: 40000               # slide and upper die
  crank_inertia_kg_m2: 12000         # eccentric shaft and bull gears
  counterbalance_kN: 390             # air cylinders carrying the slide and die
  gear_ratio: 25                     # motor turns per crank turn
  gear_efficiency: 0.93
  motor_inertia_kg_m2: 5             # the motors and their pinions, about the motor axis
  links:                             # each link's mass, centre of gravity (from its first joint toward its
                                     # second, and to the left) and inertia about it
    ternary: {mass_kg: 3000, cg_along_mm: 0, cg_across_mm: 250, inertia_kg_m2: 350}
    rocker: {mass_kg: 1800, cg_along_mm: 405, inertia_kg_m2: 110}
    rod: {mass_kg: 2200, cg_along_mm: 480, inertia_kg_m2: 220}
  motor:                             # the servo motors together
    peak_torque_Nm: 50000
    rated_torque_Nm: 20000           # the RMS torque over a cycle stays at or below this
    base_speed_rpm: 500
    max_speed_rpm: 1000
""",
    "knuckle-joint": """\
drive:                               # the motor and what it moves; with it the plan keeps the motor's limits
  slide_mass_kg: 12000               # slide and upper die
  crank_inertia_kg_m2: 800           # crankshaft and bull gear
  counterbalance_kN: 115             # air cylinders carrying the slide and die
  gear_ratio: 12                     # motor turns per crank turn
  gear_efficiency: 0.93
  motor_inertia_kg_m2: 1.5           # the motor and its pinion
  links:                             # each link's mass, centre of gravity (from its first joint toward its
                                     # second) and inertia about it
    rod: {mass_kg: 1200, cg_along_mm: 450, inertia_kg_m2: 100}
    rocker: {mass_kg: 1500, cg_along_mm: 455, inertia_kg_m2: 110}
    main_rod: {mass_kg: 1500, cg_along_mm: 455, inertia_kg_m2: 110}
  motor:
    peak_torque_Nm: 15000
    rated_torque_Nm: 5000            # the RMS torque over a cycle stays at or below this
    base_speed_rpm: 1000
    max_speed_rpm: 2000
""",
}

TITLES = {
    "crank-slider": "Deep drawing on a 450/1200 mm crank servo press",
    "link-drive": "Deep drawing on a six-bar link-drive servo press",
    "knuckle-joint": "Coining on a knuckle-joint servo press",
}


def new_case_text(
    name: str, path: str, mechanism: str = "crank-slider", drive: bool = False, robots: bool = False
) -> str:
    """The text of a first case for ``mechanism`` (one of :data:`MECHANISMS`), with a drive section when
    ``drive``, with an unloader and a loader on their interference curves instead of the safety height and
    the transfer time when ``robots``; ``name`` is the case's name, ``path`` where it is written (for the
    commands in its head)."""
    text = _HEAD.format(name=name, path=path, title=TITLES[mechanism]) + _PRESS[mechanism]
    if drive:  # the forming force the motor works against, in the process section
        force = "  # the forming force against the slide's height above BDC [mm, kN]\n" + _FORCE[mechanism] + "\n"
        text = text.replace("limits:\n", force + "limits:\n", 1)
    tail = ""
    if robots:
        text, tail = _with_robots(text)
    return text + tail + _PLANNER + (_DRIVE[mechanism] if drive else "")


def _with_robots(text: str) -> tuple[str, str]:
    """The template without its safety height and transfer time, and the robots' section that replaces them:
    two robots whose moves, one after the other with their tools needing the safety height, take the transfer
    time (a move of 0.45 f s, a dwell of 0.1 f s, f half the transfer time; the path and the curve's positions
    scale with f^2 at the same acceleration)."""
    lines, safety, transfer = [], 700.0, 2.0
    for line in text.splitlines(keepends=True):
        key = line.strip().split(":")[0]
        if key in ("closing_deg", "opening_deg"):  # no height is tied to them with robots
            stage = "the feed stage starts" if key == "closing_deg" else "the return stage ends"
            line = line.split("#")[0] + f"# {'theta1' if key == 'closing_deg' else 'theta4'}: {stage} (the law's)\n"
        if key in ("safety_height_mm", "transfer_time_s"):
            value = float(line.split(":")[1].split("#")[0])
            safety, transfer = (value, transfer) if key == "safety_height_mm" else (safety, value)
            continue
        lines.append(line)
    f = transfer / 2
    robot = _robot_text(
        path=1000 * f * f, speed=4000 * f, dwell=0.1 * f, over=600 * f * f, clear=750 * f * f, need=safety
    )
    section = _ROBOTS_HEAD + "  unloader:                          # takes the drawn part out\n" + robot
    section += "  loader:                            # brings the next blank in\n" + robot
    return "".join(lines), section


_ROBOTS_HEAD = """\
robots:                              # the robots on their interference curves (docs/robots.md); they replace
                                     # process.safety_height_mm and process.transfer_time_s
  order: overlapping                 # overlapping: the loader comes in while the unloader goes out; in-turns
"""
_ROBOT = (  # (field line, comment): the comments aligned as the other sections'
    ("    path_mm: {path:g}", "from the die centre (0) to its waiting point outside the press"),
    ("    speed_mm_s: {speed:g}", "along its path, at most"),
    ("    accel_mm_s2: 20000", "along its path, at most"),
    ("    # jerk_mm_s3: 400000", "optional: its jerk limit (smooth double-S moves instead of trapezoids)"),
    ("    dwell_s: {dwell:g}", "standing at the die centre to grip or drop"),
    ("    interference_mm:", "[position from the die centre mm, slide height its tool needs mm above BDC]"),
    ("      - [0, {need:g}]", "over the die ..."),
    ("      - [{over:g}, {need:g}]", ""),
    ("      - [{clear:g}, 0]", "... clear of it from here out (zero beyond the last row)"),
)
COMMENT_COLUMN = 37  # where a template's comments start


def _robot_text(**values: float) -> str:
    """One robot's lines of the template (:data:`_ROBOT`) with ``values``."""
    lines = []
    for field, comment in _ROBOT:
        text = field.format(**values)
        lines.append(text.ljust(COMMENT_COLUMN - 1) + (f" # {comment}" if comment else "") + "\n")
    return "".join(line.rstrip() + "\n" for line in lines)


def drive_template(mechanism: str) -> dict:
    """The drive section :func:`new_case_text` writes for ``mechanism``, with its forming force (the page's
    "add a drive": a press of that size, to be replaced by the user's own figures)."""
    import yaml

    drive = yaml.safe_load(_DRIVE[mechanism])["drive"]
    force = yaml.safe_load(_FORCE[mechanism].strip())["forming_force_kN"]
    return {"drive": drive, "forming_force_kN": force}


def robots_template(mechanism: str) -> dict:
    """The robots' section :func:`new_case_text` writes for ``mechanism`` and the one-height model's fields it
    replaces (the page's "add robots" and "remove the robots")."""
    import yaml

    text, section = _with_robots(_PRESS[mechanism])
    process = yaml.safe_load(_PRESS[mechanism])["process"]
    one_height = {key: process[key] for key in ("safety_height_mm", "transfer_time_s")}
    return {"robots": yaml.safe_load(section)["robots"], "one_height": one_height}


def write_new_case(path: Path, mechanism: str = "crank-slider", drive: bool = False, robots: bool = False) -> None:
    """Write :func:`new_case_text` to ``path`` (named after the file); never over an existing file
    (``FileExistsError``)."""
    text = new_case_text(path.stem, str(path), mechanism, drive, robots)
    with path.open("x", encoding="utf-8") as f:
        f.write(text)
