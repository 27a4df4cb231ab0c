"""The real DXF drawings of tests/data (each with what the reader makes of it, and why) and the
drawing in the seed-000 convention that tests generate (inches, three operations)."""
from __future__ import annotations

import re
from pathlib import Path

import ezdxf

from helpers.shared_data import shared_data

DATA = shared_data()
DXF = DATA / "dxf"


EMCO = ["emco_lathe_testNegDXF_R14.dxf", "emco_lathe_testg02hemisphere_R14.dxf",
        "emco_lathe_testg03hemisphere_R14.dxf"]

# Per real drawing: what happens and why (the why is checked against the file in FACTS).
NOTHING_ON_0 = "no geometry on layer 0"
SCATTERED = "layer 0 is many pieces, none half of it"
FULL_VIEW = "full side view symmetric about the axis, lines meet in T-junctions"
CROSSES = "one polyline crossing the axis"
HALF_PROFILE = "half-profile"
CLOSED = "closed outline on the axis"
# OpenSCAD's revolve convention (rotate_extrude): layer 0 empty, one outline on layer 'Layer_1'
# right of drawing X 0, closed by a line along its smallest X over the whole height (the axis).
VERTICAL = "half-profile with a vertical axis"
REAL = {
    "d2g_132_R14.dxf": (NOTHING_ON_0, None),   # layer 0 empty: layer '81' taken
    "d2g_132_R2000.dxf": (NOTHING_ON_0, None),
    "d2g_132_R2004.dxf": (NOTHING_ON_0, None),
    "d2g_Bogen_Ellipsen_Polylinien_Block_R2007.dxf": (SCATTERED, "no clear profile"),
    "d2g_DEMO_R10.dxf": (SCATTERED, "no clear profile"),
    "d2g_FLH-001_R12.dxf": (NOTHING_ON_0, "layer 0 has no profile"),
    "d2g_Polylinie_R14.dxf": (CROSSES, "crosses the axis"),
    "d2g_SchlittenBack_R10_polyline.dxf": (NOTHING_ON_0, "layer 0 has no profile"),
    "d2g_Spirale_R14_spline.dxf": (NOTHING_ON_0, "layer 0 has no profile"),
    "d2g_Stir_1_R12.dxf": (SCATTERED, "a view along the axis"),
    "d2g_Turbocad_12.5_R14.dxf": (CLOSED, None),
    "d2gp_Drawing2_R2004_mtext.dxf": (NOTHING_ON_0, "layer 0 has no profile"),
    "d2gp_fc_mounting_R12.dxf": (SCATTERED, "not a turned part"),
    "d2gp_fc_mounting_R2013.dxf": (SCATTERED, "not a turned part"),
    "d2gp_pumpenteile_R2000.dxf": (SCATTERED, "not a turned part"),
    "emco_lathe_testNegDXF_R14.dxf": (HALF_PROFILE, None),
    "emco_lathe_testg02hemisphere_R14.dxf": (HALF_PROFILE, None),
    "emco_lathe_testg03hemisphere_R14.dxf": (HALF_PROFILE, None),
    "ezdxf_AC1003_LINE_Example.dxf": (NOTHING_ON_0, None),   # layer '1' without @-codes taken
    "ezdxf_Leica_Disto_S910_R12.dxf": (NOTHING_ON_0, "layer 0 has no profile"),
    "ezdxf_POLI-ALL210_R12_polylines.dxf": (NOTHING_ON_0, "layer 0 has no profile"),
    "ezdxf_binary_dxf_R2000.dxf": (NOTHING_ON_0, "layer 0 has no profile"),   # binary: one TEXT
    "ezdxf_custom_blocks_R2010.dxf": (SCATTERED, "not a turned part"),
    "ezdxf_edgeminer_1_polylines_R2018.dxf": (SCATTERED, "not a turned part"),
    "ezdxf_uncommon_R2018.dxf": (SCATTERED, "no clear profile"),
    "qcad_M4x25_DIN931_f_R2010.dxf": (NOTHING_ON_0, "not a turned surface"),   # hexagon head
    "qcad_flange_R2013.dxf": (SCATTERED, "needs internal turning"),
    "qcad_screw_R2007.dxf": (FULL_VIEW, None),
    "scadchess_bishop_profile_R2007.dxf": (VERTICAL, "the axis looks vertical: rotate the drawing"),   # at X 0.545
    "scadchess_king_profile_R2007.dxf": (VERTICAL, None),
    "scadchess_pawn_profile_R2007.dxf": (VERTICAL, None),    # its ball top is the front: a dome on the axis
    "scadchess_queen_profile_R2007.dxf": (VERTICAL, None),
}


def nc_arc_words(name: str) -> list[str]:
    """The arc G words (02/03) another tool's Emco program made of this drawing."""
    stem = name.removeprefix("emco_lathe_").removesuffix("_R14.dxf")
    text = (DATA / "nc" / "emco_from_dxf" / f"{stem}.cnc").read_text()
    return re.findall(r"^\s*\d+\s+(0[23])\s", text, flags=re.MULTILINE)


INCH = 25.4


def seed_drawing(path: Path, *, rough_codes="@GROUGH @S1000 @F300 @T01 @M8", layer2_codes="@GSLOT\\P@S80 @F20 @T02 @M9",
                 fmt="asc") -> dict[str, str]:
    """A drawing in the seed-000 convention, in inches; returns handles of interest."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 1
    for name in ("1", "2", "3"):
        doc.layers.add(name)
    msp = doc.modelspace()
    msp.add_line((0, 0), (0, 0.5))
    msp.add_lwpolyline([(0, 0.5, 0), (-1, 0.5, 0.5), (-2, 0.5, 0)], format="xyb")
    # OCS centre (2.5, 0.5), 180°→360° with extrusion −Z: in WCS from (−2, .5) down to (−3, .5).
    msp.add_arc((2.5, 0.5), 0.5, 180, 360, dxfattribs={"extrusion": (0, 0, -1)})
    block = doc.blocks.new("STEP")
    block.add_line((1, 0.5), (0, 0.5))
    msp.add_blockref("STEP", (-4, 0))
    msp.add_line((-4, 0), (-4, 0.5))
    msp.add_point((1, 1.5))
    rough = msp.add_text(rough_codes, dxfattribs={"layer": "1", "insert": (1, 2)})
    for y in (0.9, 0.85, 0.8):   # above the bulge (top 0.75): roughing passes stay off the part
        msp.add_line((0.1, y), (-3.9, y), dxfattribs={"layer": "1"})
    slot = msp.add_mtext(layer2_codes, dxfattribs={"layer": "2", "insert": (1, 3)})
    for x in (-2.3, -2.7):
        msp.add_line((x, 0.8), (x, 0.1), dxfattribs={"layer": "2"})
    msp.add_text("@GTHREAD @S700 @T03 @P1.5 @D0.4 @A30", dxfattribs={"layer": "3", "insert": (1, 4)})
    msp.add_line((-0.2, 0.5), (-0.9, 0.5), dxfattribs={"layer": "3"})
    msp.add_line((-0.2, 0.45), (-0.9, 0.45), dxfattribs={"layer": "3"})
    doc.saveas(path, fmt=fmt)
    return {"rough": rough.dxf.handle, "slot": slot.dxf.handle}
