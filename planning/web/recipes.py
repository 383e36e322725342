"""Recipes: cases saved under a name in the one folder ``pressplan serve --recipes DIR`` is given, and reopened.

A recipe is the case as ``case.yaml`` downloads it (``NAME.yaml`` in the folder). A name is letters, digits,
space, ``_``, ``.`` and ``-``, at most 64 characters, starting with a letter or digit, no space at its end: no name
reaches outside the folder (no separator, no ``..``), and the file is written whole or not at all (a temporary
file renamed), readable as any case file.
"""

from __future__ import annotations

import os
import re
import tempfile
from pathlib import Path

import yaml

RECIPE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9 _.-]{0,63}$")
RECIPE_MODE = 0o644
NAME_RULE = "letters, digits, space, _ . - (at most 64, starting with a letter or digit, no space at the end)"


class RecipeError(ValueError):
    """A recipe name that is not allowed, or a recipe that is not there."""


def recipe_path(folder: Path, name: str) -> Path:
    """The file of recipe ``name`` in ``folder``; :class:`RecipeError` for a name outside the rule."""
    if not isinstance(name, str) or not name.strip():
        raise RecipeError(f"recipe: type a name first ({NAME_RULE})")
    if not RECIPE_NAME.fullmatch(name) or ".." in name or name != name.strip():
        raise RecipeError(f"recipe name {name[:80]!r}: use {NAME_RULE}")
    path = folder / f"{name}.yaml"
    if path.resolve().parent != folder.resolve():  # never outside the folder (a symbolic link included)
        raise RecipeError(f"recipe name {name!r}: outside the recipes' folder")
    return path


def recipe_names(folder: Path) -> list[str]:
    """The recipes in ``folder`` by name, sorted."""
    return sorted(p.stem for p in folder.glob("*.yaml") if p.is_file() and RECIPE_NAME.fullmatch(p.stem))


def save_recipe(path: Path, data: dict) -> None:
    """Write ``data`` (a case already validated) to ``path`` (:func:`recipe_path`'s), replacing a recipe there."""
    text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=".recipe-", suffix=".tmp")
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as out:
            out.write(text)
        os.chmod(temporary, RECIPE_MODE)  # readable as a case file is (mkstemp makes it the owner's only)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
