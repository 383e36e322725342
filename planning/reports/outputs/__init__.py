"""The files of a solved plan, as a registry: each output declared once, in a module of its own here.

An :class:`Output` names its file (or files), says what it is, what it needs (a drive, a published
solution, the figures' library) and the command-line options that shape it (``--cam-points``,
``--format``). ``pressplan solve``'s options, the output folder's owned names (:func:`owned_files`) and
the web page's downloads (:func:`downloads`) all come from :data:`OUTPUTS`; a new output is a new module
that defines one ``OUTPUT`` (discovered at import, in the order of its ``order``), and its test.

Every output reads the solution (its plan and its evaluation, made once by the verification) through a
:class:`Written`, which makes ``result.json``'s data and the trajectory's columns once for all of them;
nothing here solves, verifies or evaluates a plan again.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from planning.reports.arguments import Option

if TYPE_CHECKING:  # the registry is read by the CLI's parser: nothing heavy (the solver, CasADi) loads here
    from planning.model.case import Case
    from planning.solver.solution import Solution

Writer = Callable[[Path], None]  # writes one file at the path it is given


@dataclass(frozen=True)
class Output:
    """One output of ``pressplan solve``: ``name`` (its file, or the first of them), ``title`` (what it is, for
    people: the page's button), ``files`` (the glob patterns it owns in the output folder), ``writers`` (the
    files to write for a solution: name -> writer; none where the case has nothing for it), ``order`` (its
    place), ``page`` (downloadable on the web page), ``figure`` (drawn with matplotlib: left out with
    ``--no-plots``), ``options`` (the CLI options it reads)."""

    name: str
    title: str
    files: tuple[str, ...]
    writers: Callable[[Written], dict[str, Writer]]
    order: int
    page: bool = False
    figure: bool = False
    options: tuple[Option, ...] = ()


@dataclass
class Written:
    """What the outputs of one solution read: the ``solution`` (its evaluation made once), its ``case``,
    the CLI ``options`` by dest (defaults where not given); ``result`` (``result.json``'s data), ``columns``
    (the trajectory) and ``published`` (the source's solution, rebuilt) are made once, on first use.
    ``side_by_side_workers``: the figures drawn in two forked workers at once (``pressplan solve`` asks; a library
    caller's process is not forked unless it asks)."""

    solution: Solution
    case: Case
    options: dict[str, Any] = field(default_factory=dict)
    side_by_side_workers: bool = False

    @cached_property
    def result(self) -> dict[str, Any]:
        from planning.reports.report import result_dict

        return result_dict(self.solution, self.case)

    @cached_property
    def columns(self) -> dict[str, np.ndarray]:
        from planning.reports.report import trajectory

        return trajectory(self.solution, self.case)

    @cached_property
    def cam(self) -> Any:
        """The proved cam the ``--cam`` options ask for (``planning.reports.cam_export.CamExport``; None
        without ``--cam``): made once for every cam output."""
        from planning.reports.cam_export import export_of

        return export_of(self)

    @cached_property
    def published(self) -> np.ndarray | None:
        """The source's published solution rebuilt (``planning.reports.source_solution``) on a 1 ms grid, with
        the trajectory's kinematic columns; None where the case has none. Not a plan of ours."""
        from planning.reports.report import sample_profile
        from planning.reports.source_solution import rebuild_profile

        rebuilt = rebuild_profile(self.case)
        return sample_profile(rebuilt, self.case.machine) if rebuilt is not None else None

    def option(self, name: str) -> Any:
        """The option ``name`` as given, else its default."""
        if name in self.options:
            return self.options[name]
        for output in OUTPUTS:
            for option in output.options:
                if option.kwargs.get("dest") == name:
                    return option.kwargs.get("default")
        raise KeyError(name)


def _discover() -> tuple[Output, ...]:
    found = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        output = getattr(module, "OUTPUT", None)
        if isinstance(output, Output):
            found.append(output)
    return tuple(sorted(found, key=lambda output: output.order))


OUTPUTS: tuple[Output, ...] = _discover()
BY_NAME: dict[str, Output] = {output.name: output for output in OUTPUTS}


def owned_files() -> tuple[str, ...]:
    """The names (glob patterns) ``pressplan solve`` owns in its output folder: every output's files."""
    return tuple(pattern for output in OUTPUTS for pattern in output.files)


def downloads() -> tuple[Output, ...]:
    """The outputs the web page offers as downloads."""
    return tuple(output for output in OUTPUTS if output.page)


def options() -> tuple[Option, ...]:
    """Every output's command-line options, once each."""
    seen: dict[str, Option] = {}
    for output in OUTPUTS:
        for option in output.options:
            seen.setdefault(option.flag, option)
    return tuple(seen.values())


def solution_writers(
    solution: Solution, case: Case, options: dict[str, Any] | None = None, figures: bool = True
) -> dict[str, Writer]:
    """The files ``pressplan solve`` writes for ``solution``: every output's writers, in order (``figures``
    False: without the figures); ``options``: the outputs' options by dest."""
    return writers_of(Written(solution, case, dict(options or {})), figures)


def writers_of(written: Written, figures: bool = True) -> dict[str, Writer]:
    """Every output's writers for ``written``, in order (``figures`` False: without the figures)."""
    writers: dict[str, Writer] = {}
    for output in OUTPUTS:
        if output.figure and not figures:
            continue
        writers.update(output.writers(written))
    return writers


def writer_of(solution: Solution, case: Case, name: str, options: dict[str, Any] | None = None) -> Writer | None:
    """The writer of the one file ``name`` (an output the page offers), built alone (``options``: the outputs'
    options by dest); None when the solution has no such file."""
    output = next((o for o in OUTPUTS if o.name == name or name in o.files), None)
    if output is None:
        return None
    return output.writers(Written(solution, case, dict(options or {}))).get(name)


def write_outputs(
    solution: Solution, case: Case, out: str | Path, options: dict[str, Any] | None = None, figures: bool = True
) -> list[Path]:
    """Write every file of ``pressplan solve`` into the folder ``out``, all or nothing; the paths written
    (``options``: the outputs' options by dest, e.g. ``{"cam_points": 720, "plot_format": "svg"}``)."""
    from planning.reports.folder import write_atomic

    return write_atomic(Path(out), solution_writers(solution, case, options, figures), owned_files())


__all__ = [
    "OUTPUTS",
    "Option",
    "Output",
    "Written",
    "downloads",
    "options",
    "owned_files",
    "solution_writers",
    "write_outputs",
    "writer_of",
    "writers_of",
]
