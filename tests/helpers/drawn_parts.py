"""Turned parts the tests draw themselves with ezdxf, in millimetres: a stepped shaft's
half-profile on a named layer, the shaft of the side-view tests (and the diameters a job of it
must finish), two-layer roughing drawings, a side view drawn by a function of the test."""
from __future__ import annotations

from pathlib import Path

import ezdxf

# z, radius in mm: a stepped shaft from the face (z 0) to z -40, closed by the axis.
HALF_PROFILE = [(0, 0), (0, 10), (-15, 10), (-15, 14), (-40, 14), (-40, 0)]


def outline_drawing(path, layer="outline", copy_on=None):
    """The half-profile on `layer` (and again on `copy_on`: two layers that could be the part)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4   # mm
    doc.layers.add("dims")
    msp = doc.modelspace()
    for name in filter(None, (layer, copy_on)):
        doc.layers.add(name)
        msp.add_lwpolyline(HALF_PROFILE[:-1] + [HALF_PROFILE[-1]], dxfattribs={"layer": name})
    msp.add_line((5, 0), (-45, 0), dxfattribs={"layer": "dims"})
    doc.saveas(path)
    return path


# A stepped shaft drawn whole about a centre line at drawing Y = 30: (z, radius) corners of its
# upper half, from the face Z 0 to Z -50.
SHAFT = [(0, 8), (-12, 8), (-12, 12), (-35, 12), (-35, 10), (-50, 10)]
AXIS_Y = 30.0


def profile_only_drawing(path: Path) -> None:
    """A mm half-profile from the axis to the axis: shoulder, taper, convex arc, step."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline(
        [(0, 0, 0), (0, 8, 0), (-10, 8, 0), (-20, 12, 0.5), (-30, 12, 0), (-40, 12, 0), (-40, 15, 0),
         (-50, 15, 0), (-50, 0, 0)], format="xyb")
    doc.saveas(path)


def two_rough_layers(path: Path, tool_two: str = "01") -> None:
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    for layer in ("1", "2"):
        doc.layers.add(layer)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (0, 10), (-50, 10), (-50, 0)])
    msp.add_text("@GROUGH @S500 @F200 @T01", dxfattribs={"layer": "1"})
    for radius in (20, 18, 16):
        msp.add_line((1, radius), (-20, radius), dxfattribs={"layer": "1"})
    msp.add_text(f"@GROUGH @S500 @F200 @T{tool_two}", dxfattribs={"layer": "2"})
    for radius in (25, 23):
        msp.add_line((-25, radius), (-45, radius), dxfattribs={"layer": "2"})
    doc.saveas(path)


# The diameters (mm) a job of SHAFT must finish, as drawn.
DRAWN_DIAMETERS = sorted({2 * r for _, r in SHAFT})


def drawing(path, draw) -> None:
    """A drawing in mm that `draw(modelspace)` fills, with a centre-line layer as German CAD names it."""
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4
    doc.layers.add("Mittellinie", linetype="CENTER")
    draw(doc.modelspace())
    doc.saveas(path)
