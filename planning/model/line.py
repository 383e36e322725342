"""A press line: stations (press cases, each with its robots) joined by transfer robots, on one master.

The model (docs/line.md). Station k's unloader and station k+1's loader are one robot, the transfer between
them. In one master cycle of period ``T`` it unloads station k (its occupancy there ``o_u(k)``: in, dwell and
out along its path, as in the case), moves from station k's waiting point to station k+1's (the transfer
move, ``t_k``: a rest-to-rest move of ``path_mm`` within its limits (``press.robot.fastest_move``), or a time
the line file gives), loads station k+1 (``o_l(k+1)``) and moves back (``t_k`` again). Its loop
``L_k = o_u(k) + t_k + o_l(k+1) + t_k`` must fit the period. The line's ends: the first station's loader
(the feeder) is away ``feeder.time_s`` a cycle fetching a blank, ``L = o_l(1) + f``; the last station's
unloader (the exit) ``exit.time_s`` placing the part, ``L = o_u(N) + e``.

Each press runs once per master cycle, shifted on the master by its phase offset ``phi_k`` [s] (station k's
master time is the line's minus ``phi_k``), its robots starting at its own plan's times. The chain has no
loop: whatever station k's timing, station k+1's offset can put transfer k's load anywhere in the window
``[end of unload + t_k, next unload - o_l - t_k]``, of length ``T - L_k >= 0``. So the line's period is

    T = max( max_k T_k, max_j L_j ),

``T_k`` the shortest period of station k alone with its robots (its own plan): a press that can run at
``T_k`` runs at any longer period its minimum crank speed allows (its plan at ``T``:
``planning.solver.objectives.solve_at_period``; a longer period is refused, ``planning.solver.line``). The
offsets put each load in the middle of its window (the slack split evenly before and after it):

    phi_(k+1) = phi_k + s_u(k) + o_u(k) + t_k + (T - L_k) / 2 - s_l(k+1)   (mod T),  phi_1 = 0,

``s_u``, ``s_l``: the unloader's and the loader's starts in their station's plan [s from its TDC].
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, StringConstraints

from planning.model.case import Case, PathAccel, PathJerk, PathSpeed
from planning.model.units import Length
from press.robot import Move, MoveLimits, Robot, fastest_move

StationName = Annotated[str, StringConstraints(pattern=r"^[A-Za-z0-9][A-Za-z0-9_-]{0,39}$")]  # no ".": a --set's
LineTime = Annotated[float, Field(ge=0, le=1e4)]  # [s]
MAX_STATIONS = 12


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


class StationModel(_Model):
    """One press of the line: ``name`` (unique in the line) and its ``case`` file (relative to the line file)."""

    name: StationName = Field(title="name", description="The station's name, unique in the line (draw, trim, ...).")
    case: Annotated[str, StringConstraints(min_length=1, max_length=1000)] = Field(
        title="case file", description="The press's case file (with its robots: section), relative to the line file."
    )


class TransferModel(_Model):
    """The robot that ``unloads`` one station and ``loads`` the next: its move between their waiting points,
    ``path_mm`` within ``speed_mm_s``, ``accel_mm_s2`` (and ``jerk_mm_s3``), or ``time_s`` [s] each way."""

    unloads: StationName = Field(title="unloads", description="The station it takes the part out of.")
    loads: StationName = Field(title="loads", description="The next station, which it puts the part into.")
    path_mm: Length | None = Field(None, title="path [mm]", description="From one waiting point to the other.")
    speed_mm_s: PathSpeed | None = Field(None, title="speed [mm/s]")
    accel_mm_s2: PathAccel | None = Field(None, title="acceleration [mm/s²]")
    jerk_mm_s3: PathJerk | None = Field(None, title="jerk [mm/s³]", description="Empty: none (trapezoid moves).")
    time_s: Annotated[float, Field(gt=0, le=1e4)] | None = Field(
        None, title="time [s]", description="The move's time each way, instead of a path."
    )


class EndModel(_Model):
    """A line's end: the time its robot spends away from the press each cycle (fetching a blank, placing a part);
    a line without one: 0 (the robot's occupancy in the press alone, as for one press)."""

    time_s: LineTime = Field(title="time away [s]")


class LineModel(_Model):
    """A whole line file."""

    name: StationName = Field(title="name")
    title: Annotated[str, StringConstraints(max_length=300)] = ""
    stations: Annotated[list[StationModel], Field(min_length=2, max_length=MAX_STATIONS)]
    transfers: Annotated[list[TransferModel], Field(max_length=MAX_STATIONS)]
    feeder: EndModel | None = None
    exit: EndModel | None = None


@dataclass(frozen=True)
class Station:
    """A press of the line: its name, its case (robots on their curves) and the file it came from."""

    name: str
    case: Case
    path: Path


@dataclass(frozen=True)
class LineRobot:
    """A robot of the line: the station it unloads (None: the feeder) and the one it loads (None: the exit), by
    index; ``away_s`` [s] each time it is away between them (the transfer move; the feeder's or the exit's
    time); ``move``: the transfer move (None: a time given)."""

    name: str
    unloads: int | None
    loads: int | None
    away_s: float
    move: Move | None = None

    def loop_s(self, stations: tuple[Station, ...]) -> float:
        """``L``: its occupancies in the stations it serves and its time away (twice between two presses)."""
        loop = sum(occupancy_s(stations[k], "unloader") for k in (self.unloads,) if k is not None)
        loop += sum(occupancy_s(stations[k], "loader") for k in (self.loads,) if k is not None)
        trips = 2 if self.unloads is not None and self.loads is not None else 1
        return loop + trips * self.away_s


@dataclass(frozen=True)
class Line:
    """A line read from its file: ``stations`` in the parts' order and its ``robots`` (the feeder, one transfer
    between each two stations, the exit)."""

    name: str
    title: str
    stations: tuple[Station, ...]
    robots: tuple[LineRobot, ...]
    path: Path


def tool(station: Station, role: str) -> Robot:
    """``station``'s ``role`` robot (unloader, loader) on its path in that press."""
    return next(r for r in station.case.robots_on_path if r.name == role)


def occupancy_s(station: Station, role: str) -> float:
    """How long ``station``'s ``role`` robot (unloader, loader) is off its waiting point per cycle [s]."""
    return tool(station, role).occupancy_s


def transfer_robot(model: TransferModel, index: int) -> LineRobot:
    """The transfer robot from station ``index`` to the next, its move from the file's path and limits."""
    name = f"{model.unloads}->{model.loads}"  # unique: a station's name has no ">"
    if model.time_s is not None:
        return LineRobot(name, index, index + 1, model.time_s)
    limits = MoveLimits(model.speed_mm_s, model.accel_mm_s2, model.jerk_mm_s3)
    move = fastest_move(model.path_mm, limits)
    return LineRobot(name, index, index + 1, move.duration_s, move)


def phase_offsets_s(
    period_s: float, robots: tuple[LineRobot, ...], stations: tuple[Station, ...], starts: list[dict[str, float]]
) -> np.ndarray:
    """Each station's phase offset [s] on the line's master, the first 0 (the module's equation); ``starts``:
    each station's robot starts [s from its TDC] in its plan at ``period_s``."""
    offsets = np.zeros(len(stations))
    for robot in robots:
        if robot.unloads is None or robot.loads is None:
            continue
        k = robot.unloads
        slack = period_s - robot.loop_s(stations)
        unloaded = starts[k]["unloader"] + occupancy_s(stations[k], "unloader")
        load = offsets[k] + unloaded + robot.away_s + slack / 2
        offsets[k + 1] = np.mod(load - starts[k + 1]["loader"], period_s)
    return offsets
