"""A press job as read from a case file: pydantic models in engineering units, and their checks.

Field names carry their units (``crank_radius_mm``, ``transfer_time_s``). Unknown keys, wrong types,
NaN and infinities are rejected by pydantic; the checks that need more than one field (rod longer
than crank, angles in cycle order, safety height met at theta1 and theta4, heights within the stroke,
a given draw speed within the speed limits) are in :func:`cross_checks`. Every problem is reported as
a :class:`CaseError` naming the dotted field.
"""

from __future__ import annotations

import math
import re
from functools import cache
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, create_model

from planning.model.errors import CaseError, show_value
from planning.model.laws import DEFAULT_LAW, LAWS, LawName
from planning.model.laws.base import HALVES
from planning.model.limits import LIMITS, Draw
from planning.model.limits.robots import span_s
from planning.model.units import (
    RPM,
    Angle,
    CrankSpeed,
    ForceKN,
    ForceTable,
    Height,
    Inertia,
    Length,
    Mass,
    MotorSpeed,
    Offset,
    Seconds,
    ShapeValue,
    SliderSpeed,
    SourceDuration,
    SourceNumber,
    SourceSpeed,
    SourceTime,
    Torque,
)
from press.crank_slider import CrankSlider
from press.dynamics import DriveModel, LinkMass
from press.linkage import KnuckleJoint, LinkageError, LinkDrive
from press.mechanism import Mechanism
from press.robot import InterferenceCurve, MoveLimits, Robot

Placement = Literal["free", "published"]  # where theta1 / theta4 may fall (the paper's Fig. 6, or anywhere)
Objective = Literal["max-spm", "min-rms-torque", "min-energy", "min-grid-peak"]  # what the planner optimises
Mode = Literal["rotary", "pendulum"]  # the crank turns round, or swings through BDC and back (planning.model.pendulum)
OBJECTIVES: tuple[str, ...] = Objective.__args__
__all__ = ["RPM", "Case", "CaseError", "show_value"]  # RPM and CaseError: where the model's users find them


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


MechanismKind = Literal["crank-slider", "link-drive", "knuckle-joint"]
Coordinate = Annotated[float, Field(ge=-20_000, le=20_000)]  # [mm] a position either side of the crank axis


class LinkDriveModel(_Model):
    """``press.link_drive``: the six-bar link drive (``press.linkage.LinkDrive``; the letters of
    ``mechpress.ld.LD``): crank (eccentric) radius a, the ternary link's side b to the rocker and side m to the
    connecting rod with the angle tht between them, the rocker c pivoting at (-d, -f) from the crank centre,
    the connecting rod g to the slide, the slide's line h to the side; [mm], [deg]."""

    crank_radius_mm: Length = Field(
        title="crank radius a [mm]",
        description="The eccentric's radius: the crank pin's distance from the crank axis.",
    )  # a
    ternary_rocker_side_mm: Length = Field(
        title="ternary link, side to the rocker b [mm]",
        description="The ternary link's side from the crank pin to the rocker's joint.",
    )  # b
    rocker_mm: Length = Field(
        title="rocker c [mm]", description="The rocker's length, from its fixed pivot to the ternary link."
    )  # c
    rocker_pivot_x_mm: Coordinate = Field(
        title="rocker pivot, left of the crank d [mm]",
        description="The rocker's fixed pivot at (-d, -f) from the crank axis.",
    )  # d
    rocker_pivot_y_mm: Coordinate = Field(
        title="rocker pivot, below the crank f [mm]",
        description="The rocker's fixed pivot at (-d, -f) from the crank axis.",
    )  # f
    ternary_angle_deg: Annotated[float, Field(gt=-360, lt=360)] = Field(
        title="ternary link's angle tht [deg]",
        description="The angle between the ternary link's two sides (to the rocker, to the rod).",
    )  # tht
    ternary_rod_side_mm: Length = Field(
        title="ternary link, side to the rod m [mm]",
        description="The ternary link's side from the crank pin to the connecting rod's joint.",
    )  # m
    rod_length_mm: Length = Field(
        title="connecting rod g [mm]", description="The connecting rod from the ternary link to the slide."
    )  # g
    slide_offset_mm: Coordinate = Field(
        0.0,
        title="slide's line to the side h [mm]",
        description="The slide's line of action, to the side of the crank axis (0: through it).",
    )  # h


class KnuckleJointModel(_Model):
    """``press.knuckle_joint``: the knuckle joint (``press.linkage.KnuckleJoint``; the letters of presslink's
    ``ModularKnuckleJoint``): crank radius a, the rod b from the crank pin to the knuckle, the upper link
    (rocker) c pivoting at (d, e) from the crank centre, the main rod g from the knuckle to the slide, the
    slide's line h to the side of the rocker's pivot; [mm]."""

    crank_radius_mm: Length = Field(
        title="crank radius a [mm]", description="The crank pin's distance from the crank axis."
    )  # a
    rod_length_mm: Length = Field(
        title="crank rod b [mm]", description="The rod from the crank pin to the knuckle."
    )  # b
    rocker_mm: Length = Field(
        title="upper link c [mm]", description="The upper link (rocker) from its fixed pivot to the knuckle."
    )  # c
    rocker_pivot_x_mm: Coordinate = Field(
        title="upper link's pivot, across d [mm]",
        description="The upper link's fixed pivot at (d, e) from the crank axis.",
    )  # d
    rocker_pivot_y_mm: Coordinate = Field(
        title="upper link's pivot, up e [mm]",
        description="The upper link's fixed pivot at (d, e) from the crank axis.",
    )  # e
    main_rod_mm: Length = Field(
        title="main rod g [mm]", description="The main rod from the knuckle down to the slide."
    )  # g
    slide_offset_mm: Coordinate = Field(
        0.0,
        title="slide's line to the side h [mm]",
        description="The slide's line of action, to the side of the upper link's pivot.",
    )  # h


class CapacityModel(_Model):
    """The press's own capacity (``press.capacity``): its tonnage curve, from the rated force at the rated
    distance above BDC or as the builder's table of force against height, and its crank (gear) torque
    capacity (by default the torque the rating implies)."""

    rated_force_kN: ForceKN | None = Field(
        None,
        title="rated force [kN]",
        description="The press's nominal force, allowed up to the rated distance above BDC.",
    )
    rated_distance_mm: Height | None = Field(
        None,
        title="rated distance [mm above BDC]",
        description="Where the rated force is allowed up to; above it the force falls as the crank's lever grows.",
    )
    force_table_kN: ForceTable | None = Field(
        None,
        title="tonnage curve [mm, kN]",
        description="The builder's curve instead of the rating: (height above BDC, allowed force) pairs.",
    )
    crank_torque_kNm: Annotated[float, Field(gt=0, le=1e6)] | None = Field(
        None,
        title="crank torque capacity [kN m]",
        description="The crank's (the gears') torque capacity; empty: the torque the rating implies.",
    )


class PressModel(_Model):
    """The machine: ``mechanism`` (crank-slider by default). A crank-slider of ``crank_radius_mm`` [mm] and
    ``rod_length_mm`` [mm], its slide's line ``offset_mm`` [mm] to the side of the crank axis (0: in line;
    ``press.crank_slider``); a link drive's dimensions in ``link_drive``, a knuckle joint's in
    ``knuckle_joint`` (``press.linkage``); its ``capacity`` (tonnage curve, crank torque), optional."""

    mechanism: MechanismKind = Field(
        "crank-slider",
        title="mechanism",
        description=(
            "crank-slider, link-drive or knuckle-joint; a case's mechanism comes with its file (each has its own "
            "dimensions)."
        ),
    )
    crank_radius_mm: Length | None = Field(
        None, title="crank radius R [mm]", description="Half the stroke of an in-line crank-slider."
    )
    rod_length_mm: Length | None = Field(
        None,
        title="connecting rod L [mm]",
        description="From the crank pin to the slide's joint; longer than the crank radius.",
    )
    offset_mm: Offset = Field(
        0.0,
        title="slide offset e [mm]",
        description="The slide's line of action to the side of the crank axis (0: in line); |e| < L - R.",
    )
    link_drive: LinkDriveModel | None = None
    knuckle_joint: KnuckleJointModel | None = None
    capacity: CapacityModel | None = None


class KeyPointsModel(_Model):
    """The four key crank angles [deg from TDC]."""

    closing_deg: Angle = Field(
        title="θ1 closing [deg from TDC]", description="The slide passes the robot's safety height going down."
    )
    draw_start_deg: Angle = Field(
        title="θ2 draw start [deg from TDC]",
        description="The slide meets the blank; from here the crank turns at the draw speed.",
    )
    draw_end_deg: Angle = Field(
        title="θ3 draw end [deg from TDC]", description="The end of the draw at constant crank speed."
    )
    opening_deg: Angle = Field(
        title="θ4 opening [deg from TDC]",
        description="The slide is back above the safety height; the robot's window begins.",
    )


HOLD_TURNS = 5  # with a hold, the longest cycle in turns at the least crank speed (Case.longest_cycle_s)
MAX_HOLD_S = 600.0  # [s] the longest hold at the bottom (ten minutes: a cycle's times stay within the NLP's precision)


class ProcessModel(_Model):
    """``safety_height_mm`` [mm above BDC], ``transfer_time_s`` [s] (both required without robots, refused with
    them), ``draw_speed_rpm`` [rpm] or None."""

    safety_height_mm: Annotated[float, Field(gt=0, le=40_000)] | None = Field(
        None,
        title="safety height [mm above BDC]",
        description=(
            "The transfer robot's height: the slide stays at or above it from θ4 through TDC to θ1 (required "
            "without a robots: section, which replaces it)."
        ),
    )
    transfer_time_s: Seconds | None = Field(
        None,
        title="transfer time [s]",
        description="The least time the robot needs from θ4 to θ1 (required without a robots: section).",
    )
    draw_speed_rpm: CrankSpeed | None = Field(
        None,
        title="draw speed [rpm]",
        description=(
            "The crank's constant speed in the draw; empty: the planner chooses it, at most the highest the "
            "limits allow (pressplan check prints it)."
        ),
    )
    forming_force_kN: ForceTable | None = Field(
        None,
        title="forming force [kN] against height [mm]",
        description=(
            "Rows of height above BDC and force, linear between rows, zero outside; acts while the slide goes down "
            "from θ2 to BDC. Needs a drive to matter."
        ),
    )  # [[height above BDC mm, force kN], ...], linear between points
    draw_slide_speed_mm_s: SliderSpeed | None = Field(
        None,
        title="draw at slide speed [mm/s]",
        description=(
            "A draw at constant slide speed: the slide's speed from θ2 to θ3 held at this, as far as the crank's "
            "limits allow near BDC (the optimal law; instead of draw_speed_rpm); empty: a constant crank speed."
        ),
    )
    hold_time_s: Annotated[float, Field(ge=1e-3, le=MAX_HOLD_S)] | None = Field(
        None,
        title="hold at the bottom [s]",
        description=(
            "The slide stands still this long after the draw (coining, calibrating), the crank stopped at "
            "process.hold_height_mm; at most 600 s; empty: no hold."
        ),
    )
    hold_height_mm: Height | None = Field(
        None,
        title="hold height [mm above BDC]",
        description="Where the slide stands in the hold: empty or 0 at BDC, else this high on its way down.",
    )


def _limits_model() -> type[_Model]:
    """The ``limits:`` section: the keys each limit declares (``planning.model.limits``), in their order."""
    fields: dict[str, Any] = {}
    for limit in LIMITS:
        fields.update(limit.section_fields)
    return create_model("LimitsModel", __base__=_Model, **fields)


LimitsModel = _limits_model()
LimitsModel.__doc__ = """Process and machine limits [units in the names]: the keys of the limit classes
(``planning.model.limits``; a limit on a field elsewhere, as the motor's, adds none here);
``min_crank_speed_rpm`` keeps the crank turning forward; ``crank_speed_rpm``, ``crank_accel_rad_s2``,
``crank_jerk_rad_s3`` are the drive's limits (optional)."""


class MotorModel(_Model):
    """All motors together: ``peak_torque_Nm`` up to ``base_speed_rpm``, constant power above it up to
    ``max_speed_rpm``; ``rated_torque_Nm`` the thermal (RMS) limit."""

    peak_torque_Nm: Torque = Field(
        title="peak torque [N m]",
        description="All motors together, up to the base speed; above it the peak power stays constant.",
    )
    rated_torque_Nm: Torque = Field(
        title="rated torque [N m]", description="The thermal limit: the cycle's RMS motor torque stays at or below it."
    )
    base_speed_rpm: MotorSpeed = Field(
        title="base speed [rpm]", description="Up to this motor speed the peak torque is available."
    )
    max_speed_rpm: MotorSpeed = Field(title="top speed [rpm]", description="The motor's highest speed.")
    copper_loss_at_rated_kW: Annotated[float, Field(ge=0, le=1e5)] = Field(
        0.0,
        title="copper loss at the rated torque [kW]",
        description="All motors together; the loss grows with the torque squared (P_cu = this x (T / rated)²).",
    )


class LinkMassModel(_Model):
    """A link's mass ``mass_kg`` [kg] at its centre of gravity, ``cg_along_mm`` [mm] from the link's first
    joint toward its second and ``cg_across_mm`` [mm] to the left of that line, and its ``inertia_kg_m2``
    [kg m^2] about the centre of gravity (``press.dynamics.LinkMass``; the links and their joints: README)."""

    mass_kg: Mass
    cg_along_mm: Coordinate = 0.0
    cg_across_mm: Coordinate = 0.0
    inertia_kg_m2: Inertia = 0.0


class StorageModel(_Model):
    """Energy storage on the DC bus (capacitors or a flywheel): ``usable_energy_kJ`` between its voltage (or
    speed) limits, ``efficiency`` per direction, optionally ``max_power_kW`` in either direction."""

    usable_energy_kJ: Annotated[float, Field(ge=0, le=1e7)] = Field(
        title="usable energy [kJ]", description="The energy the storage holds between its lower and upper limits."
    )
    efficiency: Annotated[float, Field(gt=0, le=1)] = Field(
        1.0,
        title="storage efficiency",
        description="Per direction: charging stores this share of the power in, discharging takes power out / it.",
    )
    max_power_kW: Annotated[float, Field(gt=0, le=1e6)] | None = Field(
        None, title="storage power limit [kW]", description="The most the storage takes or gives; empty: no limit."
    )


class GridModel(_Model):
    """The plant's connection: ``peak_power_kW`` the most the press may draw from the grid."""

    peak_power_kW: Annotated[float, Field(gt=0, le=1e6)] | None = Field(
        None, title="grid peak power [kW]", description="The most the press may draw from the plant; empty: no limit."
    )


class DriveSection(_Model):
    """The drive (masses, gear, motor); see ``press.dynamics`` for the model and its signs. A crank-slider's
    rod as two point masses (``rod_mass_kg``, ``rod_cg_from_crank_pin_mm``) or as a rigid link (``links``);
    a linkage's links in ``links`` (massless where not given)."""

    slide_mass_kg: Mass = Field(
        title="slide mass [kg]", description="The slide and the upper die."
    )  # slide + upper die
    rod_mass_kg: Mass | None = Field(
        None,
        title="rod mass [kg]",
        description="A crank-slider's connecting rod, split between the crank pin and the slide.",
    )
    rod_cg_from_crank_pin_mm: Annotated[float, Field(ge=0, le=100_000)] | None = Field(
        None,
        title="rod's centre of gravity from the crank pin [mm]",
        description="Where the rod's mass sits along it.",
    )
    links: dict[str, LinkMassModel] | None = None
    crank_inertia_kg_m2: Inertia = Field(
        title="crank inertia [kg m²]", description="Crankshaft, eccentric and bull gears, about the crank axis."
    )  # crankshaft, eccentric, bull gears, about the crank axis
    counterbalance_kN: ForceKN = Field(
        title="counterbalance [kN]", description="A constant upward force on the slide."
    )  # constant, upward
    gear_ratio: Annotated[float, Field(ge=1e-3, le=1e4)] = Field(
        title="gear ratio [motor turns per crank turn]",
        description="The reduction between the motors and the crank.",
    )  # motor turns per crank turn
    gear_efficiency: Annotated[float, Field(gt=0, le=1)] = Field(
        title="gear efficiency",
        description="Share of the power the gears pass on (0 ... 1].",
    )
    motor_inertia_kg_m2: Inertia = Field(
        title="motor inertia [kg m²]", description="All motors and pinions, about the motor axis."
    )  # all motors and pinions, about the motor axis
    motor: MotorModel
    # the share of the braking energy the supply takes back: 0 a braking resistor, 1 a perfect store
    regen_efficiency: Annotated[float, Field(ge=0, le=1)] = Field(
        0.0,
        title="regeneration efficiency",
        description="Share of the braking energy the supply takes back: 0 a braking resistor, 1 a perfect store.",
    )
    converter_efficiency: Annotated[float, Field(gt=0, le=1)] = Field(
        1.0,
        title="converter efficiency",
        description="Between the DC bus and the motors, in both directions (0 ... 1].",
    )
    storage: StorageModel | None = Field(None, title="DC-bus storage", description="Capacitors or a flywheel.")
    grid: GridModel | None = Field(None, title="grid", description="The plant's connection.")

    @property
    def electrical(self) -> bool:
        """The drive has an electrical side beyond the shaft (:func:`states_electrical`): the outputs then carry
        the power chain from the motors to the grid."""
        return states_electrical(self.model_dump())

    @property
    def has_losses(self) -> bool:
        """The motors' copper or the converter loses power between the bus and the shafts: the energy at the bus
        then differs from the shafts' (an objective of energy weighs the bus's)."""
        return self.motor.copper_loss_at_rated_kW > 0 or self.converter_efficiency < 1


ELECTRICAL_KEYS = ("motor.copper_loss_at_rated_kW", "converter_efficiency", "storage", "grid")  # within drive:


def states_electrical(drive: dict[str, Any]) -> bool:
    """A ``drive:`` section (as data) with an electrical side beyond the shaft (:data:`ELECTRICAL_KEYS`): a
    copper loss, a converter loss, a storage or a grid (their defaults, 0 loss and efficiency 1, state none)."""
    motor = drive.get("motor") or {}
    return bool(
        motor.get("copper_loss_at_rated_kW", 0.0) > 0
        or drive.get("converter_efficiency", 1.0) < 1
        or drive.get("storage") is not None
        or drive.get("grid") is not None
    )


class PlannerModel(_Model):
    """``motion_law``, ``placement`` of the key points (free | published) and ``law_parameter``: the
    law's shape parameter held fixed (seven-segment jerk share, logistic flexible); omitted: optimised.
    ``objective``: the most strokes (``max-spm``), or at ``target_spm`` [strokes/min] the least RMS motor
    torque (``min-rms-torque``), the least energy drawn from the supply per stroke (``min-energy``) or the
    least peak power drawn from the grid (``min-grid-peak``, with the case's storage)."""

    motion_law: LawName = Field(
        DEFAULT_LAW,
        title="motion law",
        description="The law the crank speed follows between the stages; optimal needs a crank jerk limit.",
    )
    placement: Placement = Field(
        "free",
        title="placement of θ1 and θ4",
        description="free: anywhere in the transfer stage or its S-curves; published: the paper's structure.",
    )
    law_parameter: ShapeValue | None = Field(
        None,
        title="law's shape parameter",
        description="Held fixed: seven-segment jerk share r in [0.01, 1], logistic a in [1.317, 30]; empty: optimised.",
    )
    objective: Objective = Field(
        "max-spm",
        title="objective",
        description=(
            "max-spm: the most strokes; min-rms-torque, min-energy or min-grid-peak: the gentlest plan at the "
            "target rate (needs a drive)."
        ),
    )
    target_spm: Annotated[float, Field(gt=0, le=1e4)] | None = Field(
        None,
        title="target rate [strokes/min]",
        description="The line's rate for min-rms-torque, min-energy and min-grid-peak.",
    )
    mode: Mode = Field(
        "rotary",
        title="stroke mode",
        description=(
            "rotary: the crank turns round through TDC; pendulum: it swings through BDC and back, each swing a "
            "stroke, turning where the planner decides after the slide has passed the safety height."
        ),
    )


class PublishedKeyPoint(_Model):
    """A published key point: ``height_mm`` [mm], ``slider_speed_mm_s`` [mm/s] (magnitude)."""

    height_mm: SourceNumber | None = None
    slider_speed_mm_s: SourceNumber | None = None


class PublishedKeyPoints(_Model):
    closing: PublishedKeyPoint | None = None
    draw_start: PublishedKeyPoint | None = None
    draw_end: PublishedKeyPoint | None = None
    opening: PublishedKeyPoint | None = None


class PublishedSolution(_Model):
    """The paper's X = [x1..x5, wm1, wm2, T1, T5, T9, T10, T14, J]: times [s], speeds [rpm], J [rpm/s^2].
    Sub-segment lengths and speeds are positive (the rebuilt profile divides by them)."""

    x1_s: SourceTime
    x2_s: SourceTime
    x3_s: SourceTime
    x4_s: SourceTime
    x5_s: SourceDuration
    wm1_rpm: SourceSpeed
    wm2_rpm: SourceSpeed
    T1_s: SourceDuration
    T5_s: SourceDuration
    T9_s: SourceDuration
    T10_s: SourceDuration
    T14_s: SourceDuration
    J_rpm_s2: SourceNumber


class PublishedModel(_Model):
    """The source's own numbers, kept for comparison only (never read by the solver)."""

    spm: Annotated[float, Field(gt=0, le=1e4)] | None = None
    key_points: PublishedKeyPoints | None = None
    solution: PublishedSolution | None = None


MAX_CURVE_POINTS = 16  # points of an interference curve (its crossings are rows of the NLP: a fixed share)
CurvePoint = Annotated[list[float], Field(min_length=2, max_length=2)]  # [position mm, needed height mm]
CurveTable = Annotated[list[CurvePoint], Field(min_length=1, max_length=MAX_CURVE_POINTS)]
PathSpeed = Annotated[float, Field(ge=1.0, le=1e5)]  # [mm/s] a robot's speed along its path
PathAccel = Annotated[float, Field(ge=1.0, le=1e7)]  # [mm/s^2]
PathJerk = Annotated[float, Field(ge=1.0, le=1e10)]  # [mm/s^3]
RobotOrder = Literal["overlapping", "in-turns"]  # how the loader follows the unloader


class RobotModel(_Model):
    """A press-tending robot on its path (``press.robot``): from the die centre (0) to its waiting point
    (``path_mm``), its limits along the path, its dwell at the die centre and its interference curve."""

    path_mm: Length = Field(
        title="path [mm]", description="From the die centre, where the tool grips or drops, to the waiting point."
    )
    speed_mm_s: PathSpeed = Field(title="speed [mm/s]", description="The robot's top speed along its path.")
    accel_mm_s2: PathAccel = Field(title="acceleration [mm/s²]", description="Its acceleration limit along the path.")
    jerk_mm_s3: PathJerk | None = Field(
        None, title="jerk [mm/s³]", description="Its jerk limit along the path; empty: none (trapezoid moves)."
    )
    dwell_s: Annotated[float, Field(ge=0, le=1e4)] = Field(
        0.0, title="dwell at the die [s]", description="The time the tool stands at the die centre to grip or drop."
    )
    interference_mm: CurveTable = Field(
        title="interference curve [mm, mm]",
        description=(
            "Rows of the tool's position (mm from the die centre) and the slide height it needs there (mm above "
            "BDC), linear between rows, zero beyond the last (the tool clear of the die)."
        ),
    )


class RobotsModel(_Model):
    """The robots that tend the press (``planning.model.limits.robots``): an ``unloader`` (takes the part out)
    and a ``loader`` (brings the blank in), either may be left out; ``order``: ``overlapping`` (the loader
    reaches the die centre once the unloader's tool is clear of the die) or ``in-turns`` (the loader leaves its
    waiting point once the unloader is back at its own)."""

    order: RobotOrder = Field(
        "overlapping",
        title="order",
        description="overlapping: the loader comes in while the unloader goes out; in-turns: one after the other.",
    )
    unloader: RobotModel | None = None
    loader: RobotModel | None = None


class Case(_Model):
    """A whole case file."""

    name: Annotated[str, Field(min_length=1, max_length=100)]
    title: Annotated[str, Field(max_length=2000)] = ""
    source: Annotated[str, Field(max_length=2000)] = ""
    press: PressModel
    key_points: KeyPointsModel
    process: ProcessModel = ProcessModel()
    limits: LimitsModel
    drive: DriveSection | None = None
    robots: RobotsModel | None = None
    planner: PlannerModel = PlannerModel()
    published: PublishedModel | None = None

    # ---- derived quantities in inside units ----
    @property
    def machine(self) -> Mechanism:
        """The press mechanism of the case (``press.mechanism``): the crank-slider (in line or offset), the
        link drive or the knuckle joint."""
        return _machine(self.press)

    @property
    def electrical(self) -> bool:
        """The plan's power chain to the grid is computed and written: the drive states its electrical side
        (``DriveSection.electrical``) or the objective is the grid's peak."""
        return self.drive is not None and (self.drive.electrical or self.planner.objective == "min-grid-peak")

    @property
    def key_angles(self) -> np.ndarray:
        """theta1..theta4 [rad]."""
        k = self.key_points
        return np.radians([k.closing_deg, k.draw_start_deg, k.draw_end_deg, k.opening_deg])

    @property
    def hold_angle(self) -> float | None:
        """The crank angle [rad] of the hold (``process.hold_time_s``): the bottom dead centre's, or where the
        slide passes ``process.hold_height_mm`` on its way down; None without a hold."""
        if self.process.hold_time_s is None:
            return None
        m, height = self.machine, self.hold_height_mm
        return float(m.bdc_angle) if height == 0 else float(m.angles_at_height(height)[0])

    @property
    def hold_height_mm(self) -> float:
        """Where the slide stands in a hold [mm above BDC]: ``process.hold_height_mm``, BDC (0) when empty."""
        return self.process.hold_height_mm or 0.0

    @property
    def pendulum(self) -> bool:
        """The crank swings through BDC and back (``planner.mode: pendulum``, ``planning.model.pendulum``)."""
        return self.planner.mode == "pendulum"

    @property
    def free_draw(self) -> bool:
        """The draw runs at a constant slide speed (``process.draw_slide_speed_mm_s``): the optimal law plans the
        crank's speed through it, no constant draw speed."""
        return self.process.draw_slide_speed_mm_s is not None

    @property
    def longest_cycle_s(self) -> float:
        """[s] the longest cycle the least crank speed allows: a turn at it; with a hold the crank stops, and
        the brake and the rise from rest each sweep less than a turn at an average speed of at least half the
        least (a half from w to 0 sweeps D w / 2): at most :data:`HOLD_TURNS` turns at it and the hold's time."""
        turn = 2 * math.pi / (self.limits.min_crank_speed_rpm * RPM)
        return turn if self.hold_angle is None else HOLD_TURNS * turn + self.standstill_s

    @property
    def standstill_s(self) -> float:
        """The hold's time [s] (``process.hold_time_s``), 0 without a hold: a bound adds it to the fastest
        motion that stops at the hold's angle."""
        return self.process.hold_time_s or 0.0

    @property
    def transfer_time_s(self) -> float:
        """The time [s] the transfer needs between the draws: ``process.transfer_time_s``, or with robots the
        least time from the first leaving its waiting point to the last back (``limits.robots.span_s``): what
        the starts and the storage's smoothing scale with."""
        if self.robots is None:
            return self.process.transfer_time_s
        return span_s(self)

    @property
    def robots_on_path(self) -> tuple[Robot, ...]:
        """The case's robots (``press.robot.Robot``), the unloader first; empty without a ``robots:`` section."""
        if self.robots is None:
            return ()
        out = []
        for name in ROBOT_NAMES:
            r = getattr(self.robots, name)
            if r is not None:
                limits = MoveLimits(r.speed_mm_s, r.accel_mm_s2, r.jerk_mm_s3)
                table = r.interference_mm
                curve = InterferenceCurve(tuple(float(p) for p, _ in table), tuple(float(h) for _, h in table))
                out.append(Robot(name, r.path_mm, limits, r.dwell_s, curve))
        return tuple(out)

    @property
    def drive_model(self) -> DriveModel | None:
        """The drive in inside units (``press.dynamics``), None without a ``drive:`` section."""
        d = self.drive
        if d is None:
            return None
        machine = self.machine
        lumped = (0.0, 0.0)
        if d.rod_mass_kg is not None:  # a crank-slider's rod as two point masses
            lumped = machine.rod_split(d.rod_mass_kg, d.rod_cg_from_crank_pin_mm)
        links = tuple(
            LinkMass(name, link.mass_kg, link.cg_along_mm, link.cg_across_mm, link.inertia_kg_m2)
            for name, link in (d.links or {}).items()
        )
        return DriveModel.from_parts(
            machine,
            d.slide_mass_kg,
            d.crank_inertia_kg_m2,
            d.counterbalance_kN,
            d.gear_ratio,
            d.gear_efficiency,
            d.motor_inertia_kg_m2,
            self.process.forming_force_kN,
            math.radians(self.key_points.draw_start_deg),
            lumped,
            links,
        )

    def with_objective(self, objective: str | None, target_spm: float | None = None) -> Case:
        """The same case with ``planner.objective`` (None: kept) and ``planner.target_spm`` (None: kept),
        checked as a case file's would be (:class:`CaseError`)."""
        update = {k: v for k, v in (("objective", objective), ("target_spm", target_spm)) if v is not None}
        if not update:
            return self
        planner = PlannerModel.model_validate({**self.planner.model_dump(), **update})
        case = self.model_copy(update={"planner": planner})
        _objective_checks(case)
        _pendulum_checks(case)
        return case

    def with_law(self, law: str) -> Case:
        """The same case under motion law ``law``; a fixed ``law_parameter`` is kept for the same law only.
        :class:`CaseError` when the case lacks what the law needs (the optimal law: a crank-jerk limit)."""
        if law == self.planner.motion_law:
            return self
        planner = self.planner.model_copy(update={"motion_law": law, "law_parameter": None})
        case = self.model_copy(update={"planner": planner})
        _law_checks(case)
        _slide_draw_checks(case)
        _hold_checks(case)
        _objective_checks(case)
        _pendulum_checks(case)
        return case


HOLD_BRAKE_MIN_DEG = 0.5  # [deg] the crank brakes from the draw speed to the hold over at least this angle
ROBOT_NAMES = ("unloader", "loader")  # the robots a case may have, in the order they move
KEY_POINT_NAMES = ("closing", "draw_start", "draw_end", "opening")
KEY_POINT_FIELDS = ("closing_deg", "draw_start_deg", "draw_end_deg", "opening_deg")


def cross_checks(case: Case) -> None:
    """Checks that need several fields; raises :class:`CaseError` naming the first bad field: the geometry
    and the key points' order, each limit's own (``Limit.validate``), the law, the drive, the objective,
    and a given draw speed against the limits that refuse it (``Limit.refuse_draw_speed``)."""
    _press_checks(case.press)
    angles = [getattr(case.key_points, f) for f in KEY_POINT_FIELDS]
    for i in range(1, 4):
        if not angles[i] > angles[i - 1]:
            raise CaseError(
                f"key_points.{KEY_POINT_FIELDS[i]}",
                f"must be greater than key_points.{KEY_POINT_FIELDS[i - 1]} = {angles[i - 1]:g} deg (cycle order)",
                angles[i],
            )
    _transfer_checks(case)
    _pendulum_checks(case)
    _slide_draw_checks(case)
    _hold_checks(case)
    for limit in LIMITS:
        limit.validate(case)
    fixed = case.planner.law_parameter
    if fixed is not None:
        law = LAWS[case.planner.motion_law]
        if law.parameter is None:
            raise CaseError("planner.law_parameter", f"the {law.name} law has no shape parameter", fixed)
        lo, hi = law.parameter.valid
        if not lo <= fixed <= hi:
            raise CaseError(
                "planner.law_parameter",
                f"{law.parameter.name} of the {law.name} law must lie in [{lo:g}, {hi:g}]",
                fixed,
            )
    _drive_checks(case)
    _objective_checks(case)
    _law_checks(case)
    if case.process.draw_speed_rpm is not None:
        draw = Draw.of(case)
        for limit in LIMITS:
            if not limit.applies(case):
                continue
            problem = limit.refuse_draw_speed(draw, case.process.draw_speed_rpm * RPM)
            if problem is not None:
                raise CaseError("process.draw_speed_rpm", problem, case.process.draw_speed_rpm)


LINKAGES = {"link-drive": ("link_drive", LinkDrive), "knuckle-joint": ("knuckle_joint", KnuckleJoint)}


def _press_checks(press: PressModel) -> None:
    """The mechanism's own section and no other; its dimensions make a press (it assembles at every crank
    angle, the slide goes down once and up once)."""
    kind = press.mechanism
    given = {key: getattr(press, key) for key in ("crank_radius_mm", "rod_length_mm", "link_drive", "knuckle_joint")}
    given["offset_mm"] = press.offset_mm or None
    wanted = ("crank_radius_mm", "rod_length_mm", "offset_mm") if kind == "crank-slider" else (LINKAGES[kind][0],)
    for key in wanted[:2] if kind == "crank-slider" else wanted:
        if given[key] is None:
            raise CaseError(f"press.{key}", f"is required for a {kind} press", None, False)
    for key, value in given.items():
        if value is not None and key not in wanted:
            raise CaseError(f"press.{key}", f"belongs to another mechanism than press.mechanism = {kind}", "given")
    if kind == "crank-slider":
        R, L, e = press.crank_radius_mm, press.rod_length_mm, press.offset_mm
        if not L > R:
            raise CaseError("press.rod_length_mm", f"must be longer than the crank radius {R:g} mm", L)
        if not abs(e) < L - R:
            raise CaseError("press.offset_mm", f"must be less than rod length - crank radius = {L - R:g} mm", e)
        return
    section, _ = LINKAGES[kind]
    try:
        _machine(press)
    except LinkageError as error:
        keys = [_linkage_key(section, name) for name in error.names]
        if not keys:  # the dimensions together
            raise CaseError(f"press.{section}", str(error), None, False) from None
        names = [k.split(".")[-1] for k in keys]
        fit = f": {names[0]} does not fit with {', '.join(names[1:])}" if len(names) > 1 else ""
        value = getattr(getattr(press, section), names[0])
        raise CaseError(keys[0], f"{error}{fit}", value) from None


def _linkage_key(section: str, name: str) -> str:
    """The case's key of a linkage's dimension ``name`` (``press.linkage``): its unit appended."""
    return f"press.{section}.{name}_deg" if name.endswith("_angle") else f"press.{section}.{name}_mm"


def _drive_checks(case: Case) -> None:
    """The forming-force table and the drive section against the press and each other."""
    table = case.process.forming_force_kN
    if table is not None:
        stroke = case.machine.stroke
        heights = [h for h, _ in table]
        for k, (h, f) in enumerate(table):
            if not 0 <= h <= stroke:
                raise CaseError(
                    f"process.forming_force_kN.{k}", f"height must lie within the stroke 0 ... {stroke:g} mm", h
                )
            if not 0 <= f <= 1e6:
                raise CaseError(f"process.forming_force_kN.{k}", "force must lie in 0 ... 1e6 kN", f)
        if len(set(heights)) != len(heights):
            raise CaseError("process.forming_force_kN", "each height at most once", heights)
    d = case.drive
    if d is None:
        return
    _drive_mass_checks(case)
    if d.rod_mass_kg is not None and d.rod_cg_from_crank_pin_mm > case.press.rod_length_mm:
        raise CaseError(
            "drive.rod_cg_from_crank_pin_mm",
            f"must lie on the rod (at most press.rod_length_mm = {case.press.rod_length_mm:g})",
            d.rod_cg_from_crank_pin_mm,
        )
    if d.motor.rated_torque_Nm > d.motor.peak_torque_Nm:
        raise CaseError(
            "drive.motor.rated_torque_Nm",
            f"must not exceed drive.motor.peak_torque_Nm = {d.motor.peak_torque_Nm:g}",
            d.motor.rated_torque_Nm,
        )
    if d.motor.base_speed_rpm > d.motor.max_speed_rpm:
        raise CaseError(
            "drive.motor.base_speed_rpm",
            f"must not exceed drive.motor.max_speed_rpm = {d.motor.max_speed_rpm:g}",
            d.motor.base_speed_rpm,
        )


def _drive_mass_checks(case: Case) -> None:
    """A crank-slider's rod as two point masses or as a link, a linkage's links by their names."""
    d, kind = case.drive, case.press.mechanism
    split = (d.rod_mass_kg, d.rod_cg_from_crank_pin_mm)
    if kind == "crank-slider":
        if d.links is None:
            for key, value in zip(("rod_mass_kg", "rod_cg_from_crank_pin_mm"), split, strict=True):
                if value is None:
                    raise CaseError(
                        f"drive.{key}", "is required for a crank-slider (or the rod in drive.links)", None, False
                    )
        elif d.rod_mass_kg is not None:
            raise CaseError("drive.rod_mass_kg", "the rod is given in drive.links already", d.rod_mass_kg)
    else:
        for key, value in zip(("rod_mass_kg", "rod_cg_from_crank_pin_mm"), split, strict=True):
            if value is not None:
                raise CaseError(f"drive.{key}", f"a {kind} press gives its links' masses in drive.links", value)
    if (d.rod_mass_kg is None) != (d.rod_cg_from_crank_pin_mm is None):
        missing = "rod_cg_from_crank_pin_mm" if d.rod_cg_from_crank_pin_mm is None else "rod_mass_kg"
        raise CaseError(f"drive.{missing}", "goes with the other rod key", None, False)
    names = case.machine.formula.link_names
    for name in d.links or {}:
        if name not in names:
            raise CaseError(f"drive.links.{name}", f"a {kind} press's links are {', '.join(names)}", name)


def _transfer_checks(case: Case) -> None:
    """The old model's two fields without robots, none with them; a robot's interference curve a table of
    positions along its path (from the die centre, increasing, within the path) and heights below the stroke,
    clear at its waiting point."""
    process = case.process
    if case.robots is None:
        for key in ("safety_height_mm", "transfer_time_s"):
            if getattr(process, key) is None:
                raise CaseError(f"process.{key}", "is required (or a robots: section, which replaces it)", None, False)
        return
    for key in ("safety_height_mm", "transfer_time_s"):
        if getattr(process, key) is not None:
            reason = "is the one-height model: the robots: section replaces it; leave it out"
            raise CaseError(f"process.{key}", reason, getattr(process, key))
    if case.robots.unloader is None and case.robots.loader is None:
        raise CaseError("robots", "names no robot: give an unloader:, a loader: or both", None, False)
    stroke = case.machine.stroke
    for name in ROBOT_NAMES:
        robot = getattr(case.robots, name)
        if robot is not None:
            _curve_checks(f"robots.{name}", robot, stroke)


def _curve_checks(where: str, robot: RobotModel, stroke: float) -> None:
    """One robot's interference curve (:func:`_transfer_checks`)."""
    field = f"{where}.interference_mm"
    positions = [p for p, _ in robot.interference_mm]
    for k, (x, need) in enumerate(robot.interference_mm):
        if not 0 <= x <= robot.path_mm:
            raise CaseError(f"{field}.{k}", f"position must lie on the path 0 ... {robot.path_mm:g} mm", x)
        if need < 0:
            raise CaseError(f"{field}.{k}", "height must be at least 0 mm above BDC", need)
        if need >= stroke:
            reason = f"needs the slide {need:g} mm above BDC, at or above the stroke {stroke:g} mm (TDC, an instant)"
            raise CaseError(f"{field}.{k}", reason, need)
    if any(b <= a for a, b in zip(positions, positions[1:], strict=False)):
        raise CaseError(field, "positions must increase from row to row", positions)
    if positions[0] != 0:
        raise CaseError(f"{field}.0", "the first row is the die centre: position 0 mm", positions[0])
    last_x, last_need = robot.interference_mm[-1]
    if last_x >= robot.path_mm and last_need > 0:
        reason = (
            f"the tool needs {last_need:g} mm at its waiting point ({where}.path_mm = {robot.path_mm:g}): it must "
            "be clear of the die there (end the curve before the path's end, or at 0 mm)"
        )
        raise CaseError(field, reason, last_need)


def _hold_checks(case: Case) -> None:
    """A hold stands below the stroke's top, after the draw's end and before the opening (the crank brakes
    from the draw to stand at it: a law's half, ``planning.model.cycle``, or the optimal law's brake phase,
    ``planning.model.free_profile``)."""
    process = case.process
    if process.hold_time_s is None:
        if process.hold_height_mm is not None:
            reason = "needs process.hold_time_s (how long the slide stands)"
            raise CaseError("process.hold_height_mm", reason, process.hold_height_mm)
        return
    if not case.hold_height_mm < case.machine.stroke:
        reason = f"must lie below the stroke's top ({case.machine.stroke:.1f} mm above BDC)"
        raise CaseError("process.hold_height_mm", reason, process.hold_height_mm)
    hold_deg = math.degrees(case.hold_angle)
    k = case.key_points
    if not k.draw_end_deg < hold_deg - HOLD_BRAKE_MIN_DEG:
        reason = (
            f"must lie before the hold at {hold_deg:.2f} deg (process.hold_height_mm = {case.hold_height_mm:g}): "
            "the draw ends, then the crank brakes to stand there"
        )
        raise CaseError("key_points.draw_end_deg", reason, k.draw_end_deg)
    if not hold_deg < k.opening_deg:
        reason = f"must lie after the hold at {hold_deg:.2f} deg (process.hold_height_mm = {case.hold_height_mm:g})"
        raise CaseError("key_points.opening_deg", reason, k.opening_deg)


PENDULUM_NOT_WITH = (  # what a pendulum stroke does not plan with yet: (field, its value when set, what with, why)
    (
        "process.hold_time_s",
        lambda c: c.process.hold_time_s if c.planner.motion_law == "optimal" else None,
        "planner.motion_law: optimal in pendulum strokes",
        "the optimal law's swings have no hold yet: a law with halves plans a hold in a swing",
    ),
    (
        "planner.placement",
        lambda c: c.planner.placement if c.planner.placement == "published" else None,
        "planner.mode: pendulum",
        "the paper's structure is a rotary cycle's",
    ),
    (
        "process.transfer_time_s",
        lambda c: t if (t := c.process.transfer_time_s) is not None and t > MAX_HOLD_S else None,
        "planner.mode: pendulum",
        f"at most {MAX_HOLD_S:g} s: the swings stand at the turns, a cycle's times within the plan's precision",
    ),
    (
        "process.draw_slide_speed_mm_s",
        lambda c: c.process.draw_slide_speed_mm_s,
        "planner.mode: pendulum",
        "a swing draws at a crank speed",
    ),
)


def _pendulum_checks(case: Case) -> None:
    """A pendulum stroke (``planner.mode: pendulum``) plans with a law with halves or the optimal law, at the most
    strokes or at a line's rate (the motor's heat or energy), against the safety height and the transfer time or the
    robots on their curves; what it does not plan with yet is refused naming the field."""
    if not case.pendulum:
        return
    for name, value_of, what, why in PENDULUM_NOT_WITH:
        value = value_of(case)
        if value is not None:
            raise CaseError(name, f"not with {what} ({why})", value)


def _slide_draw_checks(case: Case) -> None:
    """A draw at constant slide speed: planned by the optimal law (its draw a free profile; a law's halves end at
    a constant crank speed), without a given draw speed (with a hold: the draw to theta3, then the brake)."""
    speed = case.process.draw_slide_speed_mm_s
    if speed is None:
        return
    if case.process.draw_speed_rpm is not None:
        reason = "and process.draw_slide_speed_mm_s ask for two draws: a constant crank speed or a constant slide speed"
        raise CaseError("process.draw_speed_rpm", reason, case.process.draw_speed_rpm)
    if LAWS[case.planner.motion_law].transcription == HALVES:
        reason = (
            "a draw at constant slide speed is planned by the optimal law (planner.motion_law: optimal, with "
            "limits.crank_jerk_rad_s3); a law with halves draws at a constant crank speed"
        )
        raise CaseError("planner.motion_law", reason, case.planner.motion_law)


def _law_checks(case: Case) -> None:
    """The optimal law plans under a jerk limit: the case must give one."""
    if LAWS[case.planner.motion_law].needs_jerk_limit and case.limits.crank_jerk_rad_s3 is None:
        raise CaseError(
            "limits.crank_jerk_rad_s3",
            f"the {case.planner.motion_law} law needs a crank-jerk limit (the jerk it may use)",
            None,
            False,
        )


def _objective_checks(case: Case) -> None:
    """An objective at the line's rate needs the rate and the drive whose torque or energy it weighs."""
    planner = case.planner
    if planner.objective == "max-spm":
        return
    if planner.target_spm is None:
        raise CaseError("planner.target_spm", f"the {planner.objective} objective needs the line's rate", None, False)
    if case.drive is None:
        raise CaseError("planner.objective", "needs a drive: section (the motor it weighs)", planner.objective)
    if planner.objective == "min-grid-peak" and LAWS[planner.motion_law].transcription != HALVES:
        reason = "the optimal law plans min-rms-torque and min-energy at a rate, not yet the least grid peak"
        raise CaseError("planner.objective", reason, planner.objective)


def _machine(press: PressModel) -> Mechanism:
    """One mechanism object per geometry (its derived figures are computed once; keyed on the geometry alone, so
    that the press's other sections, a tonnage table among them, need not be hashable); raises
    ``press.linkage.LinkageError`` for a linkage that cannot be a press (:func:`_press_checks` names the
    field)."""
    if press.mechanism == "crank-slider":
        return _mechanism(press.mechanism, (press.crank_radius_mm, press.rod_length_mm, press.offset_mm))
    section, _ = LINKAGES[press.mechanism]
    return _mechanism(press.mechanism, tuple(getattr(press, section).model_dump().items()))


@cache
def _mechanism(mechanism: str, geometry: tuple) -> Mechanism:
    """The mechanism of kind ``mechanism`` with ``geometry``: a crank-slider's (radius, rod, offset) [mm], a
    linkage's section as (key, value) pairs."""
    if mechanism == "crank-slider":
        return CrankSlider(*geometry)
    _, kind = LINKAGES[mechanism]
    dimensions = {
        key.removesuffix("_mm").removesuffix("_deg"): math.radians(v) if key.endswith("_deg") else v
        for key, v in geometry
    }
    return kind(**dimensions)


_SLUG = re.compile(r"[^A-Za-z0-9._-]+")


def output_name(case: Case) -> str:
    """A folder-safe version of the case name."""
    return _SLUG.sub("-", case.name).strip("-.") or "case"
