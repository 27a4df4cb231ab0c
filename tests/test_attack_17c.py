"""Attacks on issue 17's rapid-through-material check (adversary review adv3): a G00 must run
through air only; a rapid that crosses material left standing by the job's own feeds breaks the
tool, however thin the material is along the rapid's way."""
from __future__ import annotations

import json
import re

import ezdxf
import pytest

from engine.errors import EngineError
from engine.turning.material import Blank, check_rapids_in_air, job_blank
from engine.turning.moves import Move

BLANK_RADIUS = 20.0                       # a Ø40 blank, Z0 … Z-50
FIN_FRONT, FIN_BACK = -5.0, -5.04         # a rib 0.04 mm wide left standing to the full blank
TURNED_RADIUS = 10.0                      # both sides of the rib turned down to Ø20
RAPID_RADIUS = 10.5                       # a G00 along Z at Ø21, below the rib's top (Ø40)


def fin_job(rapid_end_z: float) -> dict[int, list[list[Move]]]:
    """Turns Z0…Z-5 and Z-5.04…Z-10 to Ø20 (leaving the rib up to Ø40), then rapids back along
    Z at Ø21 — through the rib."""
    d = 2 * TURNED_RADIUS
    front = [Move("rapid", 0.0, 42), Move("feed", 0.0, d), Move("feed", FIN_FRONT, d), Move("feed", FIN_FRONT, 42)]
    back = [Move("rapid", FIN_BACK, 42), Move("feed", FIN_BACK, d), Move("feed", -10.0, d), Move("feed", -10.0, 42),
            Move("rapid", -10.0, 2 * RAPID_RADIUS), Move("rapid", rapid_end_z, 2 * RAPID_RADIUS)]
    return {1: [front, back]}


@pytest.mark.parametrize("rapid_end_z", [0.0, -0.013, -0.027])
def test_a_rapid_through_a_thin_rib_left_standing_is_refused_wherever_it_ends(rapid_end_z):
    """The rib is FIN_FRONT - FIN_BACK = 0.04 mm thick along the rapid and 9.5 mm tall above it:
    the tool hits it whatever the rapid's length is (0.05 mm sampling must not decide)."""
    rib = FIN_FRONT - FIN_BACK
    assert rib > 0.01 and BLANK_RADIUS > RAPID_RADIUS > TURNED_RADIUS
    with pytest.raises(EngineError, match="G00"):
        check_rapids_in_air(Blank(0.0, -50.0, BLANK_RADIUS, False), fin_job(rapid_end_z), {1: "ROUGH"}, (100.0, 50.0))


def test_a_rapid_from_one_plunge_to_the_next_across_the_material_between_is_refused():
    """Two plunges to Ø20 at Z-5 and Z-5.04 leave 0.04 mm of blank between them up to Ø40; a
    G00 along Z at Ø20 from one plunge's bottom to the other's runs through it."""
    plunges = [Move("rapid", FIN_FRONT, 42), Move("feed", FIN_FRONT, 20), Move("rapid", FIN_FRONT, 42),
               Move("rapid", FIN_BACK, 42), Move("feed", FIN_BACK, 20), Move("rapid", FIN_BACK, 42),
               Move("rapid", FIN_FRONT, 42), Move("rapid", FIN_FRONT, 20), Move("rapid", FIN_BACK, 20)]
    with pytest.raises(EngineError, match="G00"):
        check_rapids_in_air(Blank(0.0, -50.0, BLANK_RADIUS, False), {1: [plunges]}, {1: "GROOVE"}, (100.0, 50.0))


def test_the_assumed_blank_reaches_as_far_in_z_as_the_job_feeds():
    """Without a stored stock the blank is assumed as large as the job suggests (fail closed):
    its radius covers every feed, and so must its Z. A facing feed at Z+1 in front of a profile
    ending at Z0 says the blank stands 1 mm in front of the part; the rough's approach G00 to
    Z+0.5 at Ø24 runs into that stock before the face is cut."""
    profile_front, profile_back, profile_top = 0.0, -50.0, 15.0
    face_z = 1.0
    rough = [Move("rapid", 0.5, 24), Move("feed", -20.0, 24), Move("feed", -20.0, 40)]
    face = [Move("rapid", face_z, 34), Move("feed", face_z, 0), Move("feed", face_z + 1, 0)]
    passes = {1: [rough], 2: [face]}
    kinds = {1: "ROUGH", 2: "FACE"}   # the blank stands where a FACE operation cuts its face
    blank = job_blank(None, (profile_front, profile_back, profile_top), passes, kinds)
    assert blank.z_front >= face_z
    with pytest.raises(EngineError, match="G00"):
        check_rapids_in_air(blank, passes, kinds, (100.0, 50.0))


FACE_Z, FACE_TOP_RADIUS = 1.0, 17.0   # the drawn facing feed: Z+1 from radius 17 to the axis


def facing_allowance_drawing(path) -> None:
    """A Ø20 bar Z0…Z-50 (layer 0), a ROUGH path at radius 12 from Z+0.5 (layer 1) and a FACE
    path at Z+1 from radius 17 down to the axis (layer 2): the drawing says the blank stands 1 mm
    in front of the part's face and reaches radius 17."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    for name in ("1", "2"):
        doc.layers.add(name)
    msp = doc.modelspace()
    msp.add_line((0, 0), (0, 10))
    msp.add_line((0, 10), (-50, 10))
    msp.add_line((-50, 10), (-50, 0))
    msp.add_text("@GROUGH @S500 @F200 @T01", dxfattribs={"layer": "1", "insert": (5, 40)})
    msp.add_line((0.5, 12), (-20, 12), dxfattribs={"layer": "1"})
    msp.add_text("@GFACE @S500 @F100 @T02", dxfattribs={"layer": "2", "insert": (5, 50)})
    msp.add_line((FACE_Z, FACE_TOP_RADIUS), (FACE_Z, 0), dxfattribs={"layer": "2"})
    doc.saveas(path)


def g0_moves(lines: list[str]):
    """(start, end) in (Z, radius) of every G0 line of a program, from the position before it
    (X as a diameter, both words modal)."""
    z = x = None
    found = []
    for line in lines:
        words = dict(re.findall(r"\b([XZ])(-?\d+(?:\.\d+)?)", line))
        if not words:
            continue
        new_z = float(words.get("Z", z if z is not None else "nan"))
        new_x = float(words.get("X", x if x is not None else "nan"))
        if z is not None and x is not None and re.match(r"\s*(N\d+\s+)?G0?0\b", line):
            found.append(((z, x / 2), (new_z, new_x / 2)))
        z, x = new_z, new_x
    return found


def in_front_stock(point) -> bool:
    return 0.01 < point[0] < FACE_Z - 0.01 and point[1] < FACE_TOP_RADIUS - 0.01


def test_no_rapid_runs_through_the_facing_allowance_the_drawing_shows(run, tmp_path):
    """Without --stock-diameter the engine assumes the blank from the job; the FACE path at Z+1
    shows stock in front of Z0, so the ROUGH's approach G00 down to Ø28 at Z+0.5 runs through it.
    The import must refuse, or emit no G00 through that stock."""
    path = tmp_path / "face.dxf"
    facing_allowance_drawing(path)
    made = run("import-dxf", path, "--machine", "lathe-840d", "--program-name", "FACEA", "--json")
    if made.exit_code == 1:
        return
    assert made.exit_code == 0, made.output
    program = run("instantiate", "--job", json.loads(made.stdout)["job_id"], "--dry-run")
    assert program.exit_code == 0, program.output
    through = [(start, end) for start, end in g0_moves(program.stdout.splitlines())
               if any(in_front_stock((start[0] + (end[0] - start[0]) * k / 100,
                                      start[1] + (end[1] - start[1]) * k / 100))
                      for k in range(101))]
    assert through == []
