"""Writes sample_shaft.dxf beside this file: the project's own sample turning drawing in the
seed-000 convention (design notes §8), which `engine demo --turning` and the guide import and
users copy to start their own. Real CAD drawings carry no operation layers, so this one shows
them all: run `python seed_templates/drawings/make_sample.py` after changing a table below and
commit both files.

The part: a shaft turned from a Ø44 blank, its front face at Z 0 and the chuck towards −Z —
an M20×1.5 thread with a 1.5 × 45° chamfer, a DIN 76 thread relief groove Ø17 × 4, a Ø25
seat, a Ø40 collar with a R3 rounded edge, 70 mm long. Drawing X is the machine's Z, drawing
Y the radius (programs write X as the diameter); lengths in mm.
"""
from __future__ import annotations

import contextlib
import math
from pathlib import Path

import ezdxf

FILE_NAME = "sample_shaft.dxf"
MILLIMETRES = 4   # $INSUNITS

# Layer 0: the half-profile as one LWPOLYLINE (z, radius, bulge of the segment to the next
# vertex), from the axis at the front face to the axis at the back; closed by the axis.
ROUNDED_EDGE = math.tan(math.radians(90) / 4)   # a quarter circle, counter-clockwise: positive bulge
PROFILE = (
    (0.0, 0.0, 0), (0.0, 8.5, 0),              # front face
    (-1.5, 10.0, 0),                           # chamfer 1.5 × 45° onto the thread's crest Ø20
    (-22.0, 10.0, 0), (-22.0, 8.5, 0),         # thread M20×1.5, 22 long
    (-26.0, 8.5, 0), (-26.0, 12.5, 0),         # relief groove Ø17 × 4 (DIN 76: d − 3 for P 1.5)
    (-45.0, 12.5, 0), (-45.0, 17.0, ROUNDED_EDGE),   # seat Ø25, then the collar's face
    (-48.0, 20.0, 0),                          # R3 edge (centre Z −48, radius 17)
    (-70.0, 20.0, 0), (-70.0, 0.0, 0),         # collar Ø40, back face (parted off)
)
TOOL_CHANGE = (100.0, 100.0)   # layer 0 POINT: Z 100, X 200 (a diameter)

# Layers 1 … n: operation n's @-codes and its tool-centre paths in the direction the tool
# moves, each path (z, radius, bulge) vertices: two make a LINE, more an LWPOLYLINE. @F is
# mm/min (G98): 0.25 mm/rev roughing, 0.05 grooving, 0.1 finishing. The tools are the turret's
# stations (roughing 1, finishing 3, grooving 5, threading 7), so @T is not the layer number.
ROUGH_LEVELS = ((20.5, -70.0), (18.0, -44.5), (15.5, -44.5), (13.0, -44.5), (10.5, -25.5))  # (radius, end Z)
OPERATIONS = (
    ("1", "TEXT", "@GROUGH @S1200 @F300 @T01 @M8",   # from the blank Ø44 to 0.5 mm over the part
     [((1.0, radius, 0), (end_z, radius, 0)) for radius, end_z in ROUGH_LEVELS]),
    ("2", "MTEXT", "@GSLOT\\P@S900 @F45 @T05 @M8",    # a 2 mm grooving tool, two plunges
     [((-23.0, 10.5, 0), (-23.0, 8.5, 0)), ((-25.0, 10.5, 0), (-25.0, 8.5, 0))]),
    ("3", "TEXT", "@GFINISH @S1800 @F180 @T03 @M8",   # along the profile, the groove and faces left out
     [PROFILE[1:4], PROFILE[6:11]]),
    ("4", "MTEXT", "@GTHREAD @S800 @T07\\P@P1.5 @D0.2 @A29.5 @M8",   # crest Ø20, root Ø18.16 (h3 0.92)
     [((0.0, 10.0, 0), (-23.0, 10.0, 0)), ((0.0, 9.08, 0), (-23.0, 9.08, 0))]),   # runs out in the groove
)
LAYER_COLOURS = {"1": 1, "2": 3, "3": 5, "4": 6, "NOTES": 8}   # ACI: red, green, blue, magenta, grey
NOTES = ("nc-template-engine sample drawing (the project's own work): seed-000 convention, "
         "design notes §8.\\PLayer 0: half-profile and the tool-change POINT. Layers 1-4: tool-centre "
         "path of operation n with its codes. Blank Ø44 × 70; thread M20×1.5.")


def sample_drawing(path: Path) -> Path:
    """Write the drawing to `path` (R2010 ASCII, the same bytes on every run) and return it."""
    with without_time_stamps():
        drawing().saveas(path)
    return path


@contextlib.contextmanager
def without_time_stamps():
    """No creation or save time, no GUIDs in the file (ezdxf writes them at new() and at save),
    so a diff of it shows what changed in the drawing."""
    before = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        yield
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = before


def drawing():
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = MILLIMETRES
    doc.header["$MEASUREMENT"] = 1   # metric
    for name, colour in LAYER_COLOURS.items():
        doc.layers.add(name, color=colour)
    msp = doc.modelspace()
    msp.add_lwpolyline([(z, radius, bulge) for z, radius, bulge in PROFILE], format="xyb")
    msp.add_point(TOOL_CHANGE)
    for number, (layer, text_type, codes, paths) in enumerate(OPERATIONS, start=1):
        add_codes(msp, layer, text_type, codes, (10.0, 20.0 + 8.0 * number))
        for tool_path in paths:
            add_path(msp, layer, tool_path)
    msp.add_mtext(NOTES, dxfattribs={"layer": "NOTES", "insert": (-70.0, -10.0), "char_height": TEXT_HEIGHT,
                                     "width": 80})
    return doc


TEXT_HEIGHT = 2.5   # mm on paper; TEXT calls it height, MTEXT char_height


def add_codes(msp, layer: str, text_type: str, codes: str, where: tuple[float, float]) -> None:
    if text_type == "TEXT":
        msp.add_text(codes, height=TEXT_HEIGHT, dxfattribs={"layer": layer, "insert": where})
    else:
        msp.add_mtext(codes, dxfattribs={"layer": layer, "insert": where, "char_height": TEXT_HEIGHT})


def add_path(msp, layer: str, path) -> None:
    if len(path) == 2:
        msp.add_line(path[0][:2], path[1][:2], dxfattribs={"layer": layer})
    else:
        msp.add_lwpolyline(path, format="xyb", dxfattribs={"layer": layer})


if __name__ == "__main__":
    print(sample_drawing(Path(__file__).resolve().parent / FILE_NAME))
