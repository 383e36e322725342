"""The limits of a press cycle: one class each (``base.Limit``), in the modules of this package.

Every module here but ``base`` is read at import and each :class:`~planning.model.limits.base.Limit`
subclass it defines becomes one entry of :data:`LIMITS`, in the order of its ``order`` attribute. A new
limit is a new module: the case model takes its keys (``section_fields``), and the NLPs, the bound, the
verification, the prechecks and ``pressplan check`` take its parts, without a change anywhere else.
"""

from __future__ import annotations

import importlib
import pkgutil
from typing import Any

from planning.model.limits.base import Check, Draw, Limit


def _discover() -> tuple[Limit, ...]:
    found: list[Limit] = []
    for info in pkgutil.iter_modules(__path__):
        if info.name == "base" or info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        for value in vars(module).values():
            is_limit = isinstance(value, type) and issubclass(value, Limit) and value.__module__ == module.__name__
            if is_limit and "id" in vars(value):  # a limit, not a form of them (``canonical``)
                found.append(value())
    return tuple(sorted(found, key=lambda limit: limit.order))


LIMITS: tuple[Limit, ...] = _discover()
BY_ID: dict[str, Limit] = {limit.id: limit for limit in LIMITS}


def limits_of(case: Any) -> tuple[Limit, ...]:
    """The limits ``case`` sets, in :data:`LIMITS` order."""
    return tuple(limit for limit in LIMITS if limit.applies(case))


def field_of(check_id: str) -> str:
    """The case field behind a check id (a limit's ``field``; '' for a check that is no limit's)."""
    limit = BY_ID.get(check_id)
    return limit.field if limit is not None else ""


def draw_speed_bounds(case: Any) -> dict[str, float]:
    """The highest constant draw speed [rad/s] each limit of ``case`` allows, by limit id."""
    draw = Draw.of(case)
    bounds = {limit.id: limit.draw_speed_bound(draw) for limit in limits_of(case)}
    return {key: value for key, value in bounds.items() if value is not None}


__all__ = ["BY_ID", "LIMITS", "Check", "Draw", "Limit", "draw_speed_bounds", "field_of", "limits_of"]
