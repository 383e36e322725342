"""``cam_plcopen.xml`` (``--cam plcopen``): the proved XYVA cam in the PLCopen XML exchange format (TC6, version
2.01, namespace ``http://www.plcopen.org/xml/tc6_0201``).

A project with one configuration whose global variables hold the cam: an ``ARRAY [0..n] OF SMC_CAMXYVA``
(members ``dX``, ``dY``, ``dV``, ``dA``: the XYVA element of CODESYS SoftMotion, which imports PLCopen XML)
with every point as its initial value; the header's statements in the content header's comment. The file
validates against the TC6 schema (``tc6_xml_v201.xsd``)."""

from __future__ import annotations

import datetime as dt
import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

from planning.reports.outputs import Output, Writer, Written
from planning.reports.outputs._cam import OPTIONS, real, text_writers, variable_name

if TYPE_CHECKING:
    from planning.reports.cam_export import CamExport

FILE = "cam_plcopen.xml"
NAMESPACE = "http://www.plcopen.org/xml/tc6_0201"
MEMBERS = ("dX", "dY", "dV", "dA")


def _element(parent: ET.Element, tag: str, **attributes: str) -> ET.Element:
    return ET.SubElement(parent, f"{{{NAMESPACE}}}{tag}", attributes)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("pressplan")
    except PackageNotFoundError:
        return "unknown"


def text(export: CamExport, created: dt.datetime | None = None) -> str:
    """The XML document (``created``: the file header's time, now by default)."""
    ET.register_namespace("", NAMESPACE)
    cam, name = export.cam, variable_name(export.case.name)
    when = (created or dt.datetime.now(dt.timezone.utc)).replace(microsecond=0).isoformat()
    project = ET.Element(f"{{{NAMESPACE}}}project")
    _element(
        project,
        "fileHeader",
        companyName="pressplan",
        productName="pressplan",
        productVersion=_version(),
        creationDateTime=when,
        contentDescription=export.header_lines()[0],
    )
    header = _element(project, "contentHeader", name=name)
    _element(header, "Comment").text = "\n".join(export.header_lines())
    coordinates = _element(header, "coordinateInfo")
    for language in ("fbd", "ld", "sfc"):
        _element(_element(coordinates, language), "scaling", x="1", y="1")
    types = _element(project, "types")
    _element(types, "dataTypes")
    _element(types, "pous")
    configurations = _element(_element(project, "instances"), "configurations")
    variables = _element(_element(configurations, "configuration", name=name), "globalVars", name=name)
    variable = _element(variables, "variable", name=f"{name}_Points")
    array = _element(_element(variable, "type"), "array")
    _element(array, "dimension", lower="0", upper=str(cam.master_deg.size - 1))
    _element(_element(array, "baseType"), "derived", name="SMC_CAMXYVA")
    values = _element(_element(variable, "initialValue"), "arrayValue")
    for point in zip(cam.master_deg, cam.slave_deg, cam.slope, cam.curvature, strict=True):
        struct = _element(_element(values, "value"), "structValue")
        for member, number in zip(MEMBERS, point, strict=True):
            _element(_element(struct, "value", member=member), "simpleValue", value=real(number))
    ET.indent(project, space="  ")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(project, encoding="unicode") + "\n"


def _writers(w: Written) -> dict[str, Writer]:
    return text_writers(w, "plcopen", FILE, text)


OUTPUT = Output(FILE, "cam (PLCopen XML)", (FILE,), _writers, order=35, options=OPTIONS)
