"""A rapid (G0) of a turning job runs through air only (engine.turning.material): the blank less
what the job's feeds before it have cut. A rapid into uncut material breaks the tool or the
machine, so the job is refused, naming the operation, the move and how far it runs through the
material. Every expected length is computed here from the blank and the move drawn in the test."""
from __future__ import annotations

import json
import math
import re

import ezdxf
import psycopg
import pytest
from helpers.lathe_programs import INSIDE_MM, SAMPLES_PER_MOVE, motions
from psycopg.types.json import Jsonb

from engine.errors import EngineError
from engine.paths import SAMPLE_DRAWING
from engine.turning.defaults import CLEARANCE
from engine.turning.material import Blank, check_rapids_in_air, job_blank
from engine.turning.moves import Move

BLANK = Blank(z_front=0.0, z_back=-50.0, radius=20.0, assumed=False)   # Ø40 × 50, face at Z 0
TOOL_CHANGE = (50.0, 60.0)                                              # (Z, radius), far outside


def g0(z: float, radius: float) -> Move:
    return Move("rapid", z, 2.0 * radius)


def g1(z: float, radius: float) -> Move:
    return Move("feed", z, 2.0 * radius)


def check(*operations: list[Move], kinds: tuple[str, ...] = ("SLOT", "SLOT")) -> None:
    """Operations 1, 2, … each one pass, run from the tool-change point."""
    passes = {n: [moves] for n, moves in enumerate(operations, start=1)}
    check_rapids_in_air(BLANK, passes, dict(enumerate(kinds, start=1)), TOOL_CHANGE)


def refusal(*operations: list[Move], kinds: tuple[str, ...] = ("SLOT", "SLOT")) -> str:
    with pytest.raises(EngineError) as refused:
        check(*operations, kinds=kinds)
    return str(refused.value)


def test_a_rapid_plunge_into_the_uncut_blank_is_refused_with_its_depth():
    """Down at Z-10 from above the blank to R12: 20 − 12 = 8 mm through the blank."""
    message = refusal([g0(-10, 60), g0(-10, 12), g1(-10, 9)])
    assert message.startswith("operation 1 SLOT: G00 X24.000 Z-10.000 runs 8.00 mm through uncut blank")
    assert "Ø40" in message


def test_the_approach_above_the_blank_then_a_plunge_fed_and_its_retract_are_in_the_air():
    """Rapid to 2 mm above the blank, feed the plunge, rapid back up the line just fed."""
    check([g0(-10, 60), g0(-10, 22), g1(-10, 9), g0(-10, 22), g0(-10, 60)])


def test_a_rapid_off_the_line_a_plunge_fed_is_in_material():
    """A plunge removes its own line only (no tool width): leaving it 1 mm to the side at R12 →
    R22 runs through the blank from R12 to R20 along a line of slope 1/10 (Z over R)."""
    message = refusal([g0(-10, 60), g0(-10, 22), g1(-10, 12), g0(-11, 22)])
    expected = (20 - 12) * math.hypot(1, 10) / 10
    assert f"runs {expected:.2f} mm" in message and "G00 X44.000 Z-11.000" in message


def test_a_longitudinal_feed_clears_what_lies_radially_outside_it():
    """After a feed at R15 from in front of the face to Z-30, a rapid from in front of the face
    along Z at R16 is in the air; at R14 (below the cut) it runs the whole 30 mm from the face to
    Z-30 through material."""
    cut = [g0(1, 60), g0(1, 15), g1(-30, 15), g0(-30, 60), g0(1, 60)]
    check(cut + [g0(1, 16), g0(-30, 16)], kinds=("ROUGH",))
    message = refusal(cut + [g0(1, 14), g0(-30, 14)], kinds=("ROUGH",))
    assert "operation 1 ROUGH: G00 X28.000 Z-30.000 runs 30.00 mm through material no earlier feed removed" in message


def test_a_diagonal_rapid_across_the_corner_of_the_blank_is_refused_by_its_length_inside():
    """From (Z2, R10) to (Z-8, R30): inside the blank while Z < 0 and R < 20, i.e. for the part
    of the move from t = 0.2 to t = 0.5 of its length √(10² + 20²)."""
    message = refusal([g0(2, 60), g0(2, 10), g0(-8, 30)])
    assert f"runs {0.3 * math.hypot(10, 20):.2f} mm" in message


def test_an_earlier_operation_clears_the_way_for_a_later_one_not_the_other_way_round():
    """A rough pass to R15 (operation 1) lets the slot (operation 2) rapid down to R17; numbered
    the other way round, the slot's rapid runs 20 − 17 = 3 mm through the uncut blank."""
    rough = [g0(1, 60), g0(1, 15), g1(-30, 15), g0(-30, 60)]
    slot = [g0(-20, 60), g0(-20, 17), g1(-20, 12), g0(-20, 17), g0(-20, 60)]
    check(rough, slot, kinds=("ROUGH", "SLOT"))
    assert refusal(slot, rough, kinds=("SLOT", "ROUGH")).startswith(
        "operation 1 SLOT: G00 X34.000 Z-20.000 runs 3.00 mm through uncut blank")


def test_the_tool_change_between_operations_is_a_rapid_too():
    """Operation 1 roughs from behind the blank to Z-30 and stops 1 mm above its cut; operation 2's
    tool-change block (G00 X120 Z50) runs from there straight to the tool-change point, through the
    uncut blank in front of Z-30 until it rises above R20: 4/44 of its way √(80² + 44²)."""
    from_behind = [g0(-51, 60), g0(-51, 15), g1(-30, 15), g0(-30, 16)]
    message = refusal(from_behind, [g0(-20, 60)], kinds=("ROUGH", "ROUGH"))
    assert message.startswith(f"operation 2 ROUGH: G00 X120.000 Z50.000 runs {4 / 44 * math.hypot(80, 44):.2f} mm "
                              "through uncut blank")


def test_without_a_stored_blank_the_largest_the_job_suggests_is_assumed():
    """No stock: the profile's largest radius plus the 2 mm on the diameter import-dxf puts on a
    profile-only blank (1 mm on the radius), or the largest radius a feed cuts at, whichever is larger;
    in Z the profile's extent (stretched only by a FACE operation's cut: see the attack tests of issue 17)."""
    profile = (0.0, -40.0, 10.0)      # (Z front, Z back, largest radius)
    feeds_low = {1: [[g0(1, 30), g1(1, 9), g1(-40, 9)]]}
    feeds_high = {1: [[g0(1, 30), g1(1, 13), g1(-40, 13)]]}
    assert job_blank(None, profile, feeds_low) == Blank(0.0, -40.0, 10.0 + 2.0 / 2, assumed=True)
    assert job_blank(None, profile, feeds_low, {1: "FACE"}) == Blank(1.0, -40.0, 10.0 + 2.0 / 2, assumed=True)
    assert job_blank(None, profile, feeds_high).radius == 13.0
    assert job_blank((2.0, -45.0, 25.0), profile, feeds_high) == Blank(2.0, -45.0, 25.0, assumed=False)


# --- import-dxf and instantiate --job ------------------------------------------------------------

SHAFT_R, GROOVE_R, GROOVE_Z = 10.0, 8.0, -20.0      # Ø20 × 40 with a Ø16 groove at Z-19…-21
STOCK_DIAMETER = 30.0


def grooved_shaft(path, rough: bool) -> None:
    """Seed-000 convention: profile on layer 0, a SLOT plunge on the groove, with or without a
    ROUGH pass at R10.5 over the whole length before it."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (0, SHAFT_R), (-19, SHAFT_R), (-19, GROOVE_R), (-21, GROOVE_R), (-21, SHAFT_R),
                        (-40, SHAFT_R), (-40, 0)])
    layers = (["1"] if rough else []) + ["2"]
    for layer in layers:
        doc.layers.add(layer)
    if rough:
        msp.add_text("@GROUGH @S500 @F200 @T01", dxfattribs={"layer": "1"})
        msp.add_line((1, SHAFT_R + 0.5), (-41, SHAFT_R + 0.5), dxfattribs={"layer": "1"})
    msp.add_text("@GSLOT @S300 @F20 @T02", dxfattribs={"layer": "2"})
    msp.add_line((GROOVE_Z, SHAFT_R), (GROOVE_Z, GROOVE_R), dxfattribs={"layer": "2"})
    doc.saveas(path)


def counts(url) -> tuple[int, int]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone()


def test_import_dxf_refuses_a_slot_whose_approach_rapids_through_the_blank(run, tmp_path):
    """The slot's approach stops the clearance above the groove's top (R10 + 2) at Z-20, inside the
    Ø30 blank nothing roughed: refused in one line, nothing stored."""
    grooved_shaft(tmp_path / "slot_only.dxf", rough=False)
    before = counts(run.url)
    made = run("import-dxf", tmp_path / "slot_only.dxf", "--stock-diameter", STOCK_DIAMETER, "--program-name", "SLOT")
    assert made.exit_code == 1, made.output
    approach = SHAFT_R + CLEARANCE
    assert made.stderr.count("\n") == 1 and counts(run.url) == before
    assert (f"operation 2 SLOT: G00 X{2 * approach:.3f} Z{GROOVE_Z:.3f} runs "
            f"{STOCK_DIAMETER / 2 - approach:.2f} mm through uncut blank") in made.stderr


def test_a_stored_job_remade_without_its_rough_operation_is_refused(run, tmp_path):
    """Roughed first, the slot's approach is in the air and the job is stored; the rough operation
    switched off in SQL, `instantiate --job` makes the same rapid through the blank: refused, no
    program stored."""
    grooved_shaft(tmp_path / "roughed.dxf", rough=True)
    made = run("import-dxf", tmp_path / "roughed.dxf", "--stock-diameter", STOCK_DIAMETER, "--program-name", "ROUGHED",
               "--json")
    assert made.exit_code == 0, made.output
    job_id = json.loads(made.stdout)["job_id"]
    assert run("instantiate", "--job", job_id, "--dry-run").exit_code == 0
    with psycopg.connect(run.url) as conn:
        module_params = conn.execute("SELECT module_params FROM job WHERE id = %s", (job_id,)).fetchone()[0]
        for name in ("prep:1", "cutcond:1", "cutmotion:1"):
            module_params[name]["op_present"] = False
        conn.execute("UPDATE job SET module_params = %s WHERE id = %s", (Jsonb(module_params), job_id))
    before = counts(run.url)
    remade = run("instantiate", "--job", job_id)
    assert remade.exit_code == 1, remade.output
    assert "operation 2 SLOT" in remade.stderr and counts(run.url) == before


BLANK_DIAMETER = 44.0          # the sample's blank, as its NOTES layer says: Ø44 × 70, face at Z 0
BLANK_Z = (-70.0, 0.0)


def without_layer(source, layer: str, path):
    doc = ezdxf.readfile(source)
    for entity in [e for e in doc.modelspace() if e.dxf.layer == layer]:
        doc.modelspace().delete_entity(entity)
    doc.saveas(path)
    return path


def inside_the_blank(point) -> bool:
    z, radius = point
    return (BLANK_Z[0] + INSIDE_MM < z < BLANK_Z[1] - INSIDE_MM
            and radius < BLANK_DIAMETER / 2 - INSIDE_MM)


def rapids_before_the_first_cut(lines: list[str]):
    """The G0 moves before the program's first feed move: the blank is still whole then."""
    found = []
    for g, start, end in motions(lines):
        if g != 0:
            break
        found.append((start, end))
    return found


def test_no_rapid_runs_into_the_uncut_blank_when_the_rough_layer_is_left_out(run, tmp_path):
    """The sample drawing without its ROUGH layer (a shop that roughs on another machine draws
    only SLOT, FINISH, THREAD) imported with its blank Ø44 given: the first operation's approach
    is a rapid from outside the blank straight down to the slot's start, through 9.5 mm of
    uncut steel. With the blank known the engine must keep rapids out of it or refuse."""
    drawing_path = without_layer(SAMPLE_DRAWING, "1", tmp_path / "no_rough.dxf")
    before = counts(run.url)
    made = run("import-dxf", drawing_path, "--stock-diameter", BLANK_DIAMETER, "--json")
    if made.exit_code == 1:
        assert made.stderr.count("\n") == 1 and counts(run.url) == before, made.output
        return
    assert made.exit_code == 0, made.output
    program = run("instantiate", "--job", json.loads(made.stdout)["job_id"], "--dry-run")
    assert program.exit_code == 0, program.output
    through = [(start, end) for start, end in rapids_before_the_first_cut(program.stdout.splitlines())
               if any(inside_the_blank((start[0] + (end[0] - start[0]) * k / SAMPLES_PER_MOVE,
                                        start[1] + (end[1] - start[1]) * k / SAMPLES_PER_MOVE))
                      for k in range(SAMPLES_PER_MOVE + 1))]
    assert through == []


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
