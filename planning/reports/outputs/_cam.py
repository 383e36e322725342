"""The options every cam output takes (``--cam`` and its ``--cam-*``), what each target takes, and the
notation of numbers and names in the controllers' files. Light: the CLI's parser reads it."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from planning.model.cam import Interpolation
from planning.reports.arguments import Option, listed, number, whole_or_auto
from planning.tolerances import CAM_TIGHTEST_MM

MOST_POINTS = 100_000
CRANK, MOTOR = "crank", "motor"
SLAVES = (CRANK, MOTOR)
TARGETS = ("csv", "codesys", "twincat", "plcopen")  # the files a cam is written as (one output module each)

CAM = Option(
    "--cam",
    {
        "dest": "cam",
        "type": listed(TARGETS),
        "default": (),
        "metavar": "TARGETS",
        "help": "also write the plan as a controller's cam, proved as the controller runs it: "
        f"{', '.join(TARGETS)} or all, comma-separated (default: none)",
    },
)
INTERPOLATION = Option(
    "--cam-interpolation",
    {
        "dest": "cam_interpolation",
        "choices": [i.value for i in Interpolation],
        "default": Interpolation.POLY5.value,
        "help": "poly5: XYVA points, a quintic between two (CODESYS, TwinCAT, PLCopen); spline or linear: a point "
        "table (csv; linear also twincat) (default poly5)",
    },
)
COUNT = Option(
    "--cam-count",
    {
        "dest": "cam_count",
        "type": whole_or_auto(3, MOST_POINTS),
        "default": "auto",
        "metavar": "N|auto",
        "help": "the cam's points: at most N, or auto: the law's segment ends where they are exact, else the "
        "fewest for which every limit holds (default auto)",
    },
)
TOLERANCE = Option(
    "--cam-tolerance-mm",
    {
        "dest": "cam_tolerance_mm",
        "type": number(CAM_TIGHTEST_MM, 100.0, "mm"),
        "default": None,
        "metavar": "MM",
        "help": "XYVA: the fewest points that keep the slide within MM of the plan (instead of --cam-count)",
    },
)
SPEED = Option(
    "--cam-speed",
    {
        "dest": "cam_speed_pct",
        "type": number(1.0, 800.0, "%"),
        "default": 100.0,
        "metavar": "PCT",
        "help": "the master speed the cam is proved at, %% of the plan's (default 100)",
    },
)
CYCLE = Option(
    "--cam-cycle-ms",
    {
        "dest": "cam_cycle_ms",
        "type": number(0.05, 100.0, "ms"),
        "default": 1.0,
        "metavar": "MS",
        "help": "the controller's cycle: a linear table's speed steps reach the drive over it (default 1)",
    },
)
SLAVE = Option(
    "--cam-slave",
    {
        "dest": "cam_slave",
        "choices": SLAVES,
        "default": None,
        "help": "the cam's slave: the crank's angle, or the motor's (times the gear ratio; the default with a drive)",
    },
)
OPTIONS = (CAM, INTERPOLATION, COUNT, TOLERANCE, SPEED, CYCLE, SLAVE)
COMMAND_OPTIONS = (  # ``pressplan cam``'s: the same, the targets with a default
    Option(
        "--cam",
        {
            **CAM.kwargs,
            "default": ("csv",),
            "help": f"the files to write: {', '.join(TARGETS)} or all, comma-separated (default csv)",
        },
    ),
    *OPTIONS[1:],
)
FORMATS = {  # the interpolations each target takes
    "csv": tuple(Interpolation),
    "codesys": (Interpolation.POLY5,),
    "twincat": (Interpolation.POLY5, Interpolation.LINEAR),
    "plcopen": (Interpolation.POLY5,),
}


class CamOptionError(ValueError):
    """Cam options that do not go together (the CLI's one line, exit 2): ``option`` is the one to change."""

    def __init__(self, option: str, message: str):
        super().__init__(f"{option}: {message}")
        self.option = option


def real(value: float) -> str:
    """A number as IEC 61131-3 takes a REAL/LREAL literal (a decimal point, an upper-case exponent), with every
    digit Python's shortest round trip gives."""
    text = repr(float(value)).upper()
    mantissa, _, exponent = text.partition("E")
    if "." not in mantissa:
        mantissa += ".0"
    return mantissa + (f"E{int(exponent)}" if exponent else "")


def variable_name(case_name: str) -> str:
    """An IEC identifier from the case's name (letters, digits, underscores; a letter first)."""
    name = "".join(ch if ch.isalnum() else "_" for ch in case_name)
    name = "_".join(part for part in name.split("_") if part)
    return "Cam_" + (name or "Press")


def text_writers(w: Any, target: str, name: str, text: Callable[[Any], str]) -> dict[str, Callable[[Path], None]]:
    """The file ``name`` holding ``text`` of the proved cam when ``--cam`` asks for ``target`` (else none)."""
    if target not in w.option("cam"):
        return {}
    content = text(w.cam)
    return {name: lambda path: path.write_text(content, encoding="utf-8")}
