"""A rapid (G0) of a turning job runs through air only (engine.turning.material): the blank less
what the job's feeds before it have cut. A rapid into uncut material breaks the tool or the
machine, so the job is refused, naming the operation, the move and how far it runs through the
material. Every expected length is computed here from the blank and the move drawn in the test."""
from __future__ import annotations

import json
import math

import ezdxf
import psycopg
import pytest
from psycopg.types.json import Jsonb

from engine.errors import EngineError
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
