"""Issue 14 items 3, 4, 6, 7, 8: the signs of every hobbing program follow the machine record, and
every program sets the machine up the way the record says.

Expected values come from the reference (§A7, DIN 66217 frame; h = +1 right hand, −1 left hand),
computed here: k_B = −h_hob·z0/z2, k_Z = −h_gear·360·sin β/(π·m_n·z2), A = h_hob·γ − h_gear·β with
sin γ = z0·m_n/(d_a0 − 2.5·m_n), k_Y = +360·cos γ/(π·m_n·z2) for either hand; on a machine with
other senses the program value is the DIN value times the senses involved (k_B·c·b, k_Z·c·z,
k_Y·c·y, A·a, Z·z, Y·y)."""
from __future__ import annotations

import math

import pytest
from helpers.nc_reader import read_program
from helpers.verifier_programs import accepted, refusal

from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear

# Seeded gears (seed_templates/gears.csv), one per class, and the helix given to classes whose
# seeded gear is straight, so that the gear's hand matters to the Z term.
CLASS_GEARS = {"spur": 42, "helical": 43, "taper": 50, "crowned": 51, "worm_wheel": 53, "duplex": 54}
HELIX_FOR_TEST = {50: 10.0, 51: 12.0}
FLIPPED = "hobber-flip"      # every sense opposite to DIN 66217, its own setup
FLIPPED_SETUP = {"work_offset": "G55", "door_close_m": 60, "door_open_m": 61, "orient_before_coupling": True,
                 "load_x": None, "load_z": None}
SENSES = ("a_direction", "b_direction", "c_direction", "y_direction", "z_direction")
ANGLE_TOLERANCE = 0.0006     # A is written with 3 decimals
FACTOR_TOLERANCE = 6e-7      # factors with 6 decimals


def hand(letter) -> int:
    return -1 if letter == "L" else 1


def add_flipped_machine(conn) -> None:
    conn.execute("CREATE TEMP TABLE flipped AS SELECT * FROM machine WHERE name = 'hobber-840d'")
    conn.execute("UPDATE flipped SET name = %s, a_direction = -1, b_direction = -1, c_direction = -1, "
                 "y_direction = -1, z_direction = -1, work_offset = %s, door_close_m = %s, door_open_m = %s, "
                 "orient_before_coupling = %s, load_x = %s, load_z = %s",
                 (FLIPPED, *FLIPPED_SETUP.values()))
    conn.execute("INSERT INTO machine SELECT * FROM flipped")


def set_hands(conn, gear_id: int, gear_hand: str | None, hob_hand: str) -> None:
    """Every hob of the library gets `hob_hand` (so the match must take one of it); the gear its
    hand (a worm wheel the hob's: the hob copies its worm)."""
    conn.execute("UPDATE hob SET hand = %s", (hob_hand,))
    if gear_id in HELIX_FOR_TEST:
        conn.execute("UPDATE gear SET helix_angle = %s, hand = %s WHERE id = %s",
                     (HELIX_FOR_TEST[gear_id], gear_hand, gear_id))
    elif gear_hand is not None:
        conn.execute("UPDATE gear SET hand = %s WHERE id = %s", (gear_hand, gear_id))


def gear_row(conn, gear_id):
    mn, z2, beta, hand_ = conn.execute("SELECT module, teeth, helix_angle, hand FROM gear WHERE id = %s",
                                       (gear_id,)).fetchone()
    return float(mn), z2, float(beta), hand_


def hob_row(conn, text):
    hob_id = next(line.split()[2] for line in text.splitlines() if line.startswith("; HOB "))
    z0, da0, hand_, tool = conn.execute("SELECT starts, tip_diameter, hand, tool_number FROM hob WHERE id = %s",
                                        (hob_id,)).fetchone()
    return z0, float(da0), hand_, tool


def din_values(conn, gear_id, text) -> dict:
    """A, the B numerator, k_Z and k_Y in the DIN frame, from the reference formulas."""
    mn, z2, beta, gear_hand = gear_row(conn, gear_id)
    z0, da0, hob_hand, _ = hob_row(conn, text)
    gamma = math.degrees(math.asin(z0 * mn / (da0 - 2.5 * mn)))
    worm = gear_id == CLASS_GEARS["worm_wheel"]
    # A worm wheel's A is the same formula (§A7); it is 0 when the hob's lead is the wheel's helix (§B10)
    return {"A": hand(hob_hand) * gamma - hand(gear_hand) * beta,
            "B": -hand(hob_hand) * z0,
            "Z": 0.0 if worm else -hand(gear_hand) * 360 * math.sin(math.radians(beta)) / (math.pi * mn * z2),
            "Y": 360 * math.cos(math.radians(gamma)) / (math.pi * mn * z2)}


def program_values(text) -> dict:
    nc = read_program(text)
    egon = nc.block_with("EGON").call("EGON").args
    terms = dict(zip(egon[5::3], map(float, egon[6::3])))
    return {"A": nc.block_with("A").words["A"], "B": int(egon[3]), "Z": terms.get("Z"), "Y": terms.get("Y")}


def instantiate(conn, gear_id, machine=None, **choices):
    return instantiate_gear(conn, gear_id, machine=machine, choices=Choices(**choices)).text


def check_signs(conn, gear_id, text, senses) -> None:
    a, b, c, y, z = senses
    expected, found = din_values(conn, gear_id, text), program_values(text)
    assert found["A"] == pytest.approx(a * expected["A"], abs=ANGLE_TOLERANCE), text
    assert found["B"] == c * b * expected["B"]
    if expected["Z"]:
        assert found["Z"] == pytest.approx(c * z * expected["Z"], abs=FACTOR_TOLERANCE)
    else:
        assert found["Z"] is None, "no differential without a helix and an axial pass"
    if found["Y"] is not None:
        assert found["Y"] == pytest.approx(c * y * expected["Y"], abs=FACTOR_TOLERANCE)


CASES = [(cls, gear_hand, hob_hand, machine)
         for cls, gear_id in CLASS_GEARS.items()
         for gear_hand in ((None,) if cls in ("spur", "duplex") else ("R", "L") if cls != "worm_wheel" else ("",))
         for hob_hand in ("R", "L")
         for machine in ("hobber-840d", FLIPPED)]


@pytest.mark.parametrize("cls, gear_hand, hob_hand, machine", CASES)
def test_signs_of_a_b_z_and_y_follow_the_hands_and_the_machine(conn, cls, gear_hand, hob_hand, machine):
    gear_id = CLASS_GEARS[cls]
    add_flipped_machine(conn)
    set_hands(conn, gear_id, hob_hand if gear_hand == "" else gear_hand, hob_hand)
    choices = {"worm_feed": "tangential"} if cls == "worm_wheel" else {}
    text = instantiate(conn, gear_id, machine, **choices)
    senses = (1,) * 5 if machine == "hobber-840d" else (-1,) * 5
    check_signs(conn, gear_id, text, senses)


def test_gear_43_has_the_issues_numbers_on_the_din_hobber(conn):
    """Issue 14 item 4: A = γ − β = 2.3715° − 15° and k_Z = −360·sin 15°/(π·3·41)."""
    nc = read_program(instantiate(conn, 43))
    assert nc.block_with("A").raw["A"] == "-12.628"
    assert nc.block_with("EGON").call("EGON").args[3:] == ("-1", "41", "Z", "-0.241126", "1")


@pytest.mark.parametrize("hob_hand", ["R", "L"])
def test_tangential_worm_wheels_of_both_hands_keep_the_y_factor_positive(conn, hob_hand):
    """§A7: k_B carries the hob's hand, k_Y does not (the old program had −k_Y for a left hand)."""
    set_hands(conn, 53, hob_hand, hob_hand)
    egon = read_program(instantiate(conn, 53, worm_feed="tangential")).block_with("EGON").call("EGON").args
    assert int(egon[3]) == -hand(hob_hand) and egon[5] == "Y" and float(egon[6]) > 0


@pytest.mark.parametrize("gear_id", [43, 50, 51, 53, 54])
def test_z_and_y_positions_mirror_on_a_machine_whose_z_and_y_point_the_other_way(conn, gear_id):
    add_flipped_machine(conn)
    choices = {"worm_feed": "tangential"} if gear_id == 53 else {"shift_y": 3.0}
    din, flipped = (read_program(instantiate(conn, gear_id, machine, **choices))
                    for machine in ("hobber-840d", FLIPPED))

    def positions(nc, axis):
        return [m.end[axis] for m in nc.moves if m.block < nc.index("EGOFS") and axis in m.changed]
    for axis in ("Z", "Y", "X"):
        mirror = -1 if axis != "X" else 1
        assert positions(flipped, axis) == [mirror * v for v in positions(din, axis)], axis
    low, high = (flipped.block_with(code) for code in ("G25", "G26"))
    assert low.words["Z"] < min(positions(flipped, "Z")) and high.words["Z"] > max(positions(flipped, "Z"))


@pytest.mark.parametrize("machine", ["hobber-840d", FLIPPED])
@pytest.mark.parametrize("cls", sorted(CLASS_GEARS))
def test_every_program_sets_the_machine_up_as_its_record_says(conn, cls, machine):
    """Design notes §7: work offset, tool call, Y, (spindle orientation), coupling; at the end
    M9, EGOFS(C), EGDEL(C), M5, the load position and the doors where the record has them."""
    add_flipped_machine(conn)
    conn.execute("UPDATE hob SET tool_number = 7")
    text = instantiate(conn, CLASS_GEARS[cls], machine)
    nc = read_program(text)
    lines = text.splitlines()
    offset = "G54" if machine == "hobber-840d" else FLIPPED_SETUP["work_offset"]
    first_move, last_g1 = nc.indexes("motion")[0], nc.indexes("move G1")[-1]
    assert nc.index(offset) < first_move
    tool = nc.block_with("T")
    assert (tool.words["T"], tool.words["D"]) == (7, 1) and tool.index < first_move
    egon, egdef = nc.index("EGON"), nc.index("EGDEF")
    assert any("Y" in nc.blocks[i].axes or "Y" in nc.blocks[i].params for i in range(egdef))
    ends = [nc.indexes(event)[-1] for event in ("M9", "EGOFS", "EGDEL", "M5", "M30")]   # the last (duplex: 2 units)
    assert last_g1 < ends[0] and ends == sorted(ends) and ends[-1] == len(nc.blocks) - 1
    cycle_time = header_cycle_time_line(lines)
    assert cycle_time.startswith("; CYCLE TIME ") and cycle_time.endswith(" MIN")
    if machine == FLIPPED:
        assert nc.index("SPOS") < egdef < egon
        assert nc.index("M60") < first_move and last_g1 < nc.index("M61") < ends[-1]
        assert nc.moves[-1].block < ends[0], "no load position: the program stays at the retract"
    else:
        assert nc.index("SPOS") is None and nc.index("M60") is None
        last = nc.moves[-1]
        assert (last.mode, last.end["X"], last.end["Z"]) == ("G0", 300.0, 100.0) and last.block > ends[3]


def header_cycle_time_line(lines: list[str]) -> str:
    """The header line after the template's version and the engine's lineage line (`; PROGRAM …`)."""
    assert lines[5].startswith("; TEMPLATE ") and lines[6].startswith("; PROGRAM "), lines[:8]
    return lines[7]


def brief_cycle_time(text, rapid_rate, load) -> float:
    """The BRIEF's definition, from the text: G1 path length / F, G0 the largest axis travel at
    the rapid rate, G4 F seconds; the program starts at the load position."""
    nc, minutes, position, feed = read_program(text), 0.0, dict(load), None
    for block in nc.blocks:
        feed = block.words.get("F", feed) if 4 not in block.g else feed
        if 4 in block.g:
            minutes += block.words["F"] / 60
            continue
        if 25 in block.g or 26 in block.g:
            continue
        axes = {a: v for a, v in block.axes.items() if a in "XYZ"}
        deltas = [abs(v - position.get(a, v)) for a, v in axes.items()]
        position.update(axes)
        mode = {0, 1} & set(block.g)
        if deltas and 1 in mode:
            minutes += math.sqrt(sum(d * d for d in deltas)) / feed
        elif deltas and 0 in mode:
            minutes += max(deltas) / rapid_rate
    return minutes


@pytest.mark.parametrize("cls", sorted(CLASS_GEARS))
@pytest.mark.parametrize("choices", [{}, {"cuts": 2, "feed_mode": "conventional-climb"}, {"worm_feed": "tangential"}])
def test_the_header_cycle_time_is_the_programs(conn, cls, choices):
    if cls == "worm_wheel":   # no axial pass: a feed mode given for a worm wheel is refused
        choices = {name: value for name, value in choices.items() if name != "feed_mode"}
    text = instantiate(conn, CLASS_GEARS[cls], **choices)
    header = float(header_cycle_time_line(text.splitlines()).split()[3])
    expected = brief_cycle_time(text, 8000.0, {"X": 300.0, "Z": 100.0})
    assert abs(header - expected) <= 0.051, (header, expected)


# ---------------------------------------------------------------- the verifier's new rules

EGDEF, EGON = "EGDEF(C,B,1)", 'EGON(C,"FINE",B,-1,19)'
AREA = ["G25 X50.000 Y-30.000 Z-25.000", "G26 X62.000 Y30.000 Z20.000", "WALIMON"]


def hobbing_lines(body: list[str], offset: str | None = "G54") -> list[str]:
    """A program named TEST: header, modes, the work offset (unless None), the working area, the body, M30."""
    return ["%_N_TEST_MPF", ";$PATH=/_N_MPF_DIR", "; GEAR 42", "G90 G71 G94", *([offset] if offset else []),
            *AREA, *body, "M30"]


def test_a_program_with_offset_tool_y_orientation_and_doors_is_accepted(conn):
    add_flipped_machine(conn)
    body = ["M60", "T1 D1", "G0 Y0.000", "SPOS=0", EGDEF, EGON, "M3 S246", "G64", "G1 Z5.000 F100.0", "G60",
            "M9", "EGOFS(C)", "EGDEL(C)", "M5", "M61"]
    assert accepted(conn, FLIPPED, hobbing_lines(body, "G55"))


@pytest.mark.parametrize("body, reason", [
    (["G0 Y0.000", EGDEF, EGDEF], "EGDEL(C) first"),
    (["G0 Y0.000", EGDEF, EGON, "EGOFS(C)", EGDEF], "EGDEL(C) first"),
    (["G0 Y0.000", EGDEF, EGON, "EGOFS(C)"], "M30 with C's coupling still defined"),
    (["G0 Y0.000", EGDEF], "M30 with C's coupling still defined"),
    ([EGDEF, EGON], "EGON before Y"),
])
def test_coupling_rules_are_refused(conn, body, reason):
    assert reason in refusal(conn, "hobber-840d", hobbing_lines(body))


def test_a_coupling_deleted_before_m30_and_redefined_after_egdel_is_accepted(conn):
    body = ["G0 Y0.000", EGDEF, EGON, "EGOFS(C)", "EGDEL(C)", EGDEF, EGON, "EGOFS(C)", "EGDEL(C)"]
    assert accepted(conn, "hobber-840d", hobbing_lines(body))


def test_a_hob_move_before_the_work_offset_is_refused(conn):
    assert "before a work offset" in refusal(conn, "hobber-840d", hobbing_lines(["G0 X55.000"], offset=None))
    assert accepted(conn, "hobber-840d", hobbing_lines(["G0 X55.000"]))


def test_door_m_codes_are_the_machine_records_only(conn):
    assert "M60 is not an M code" in refusal(conn, "hobber-840d", hobbing_lines(["M60"]))
    add_flipped_machine(conn)
    assert accepted(conn, FLIPPED, hobbing_lines(["M60", "M61"]))


def test_the_lathes_refuse_a_work_offset_other_than_the_record_s(conn):
    """Issue 27: an 840D lathe program as stored on the control selects its work offset; the
    record's (machine.work_offset, G54 as seeded) is the frame its travel is stated in, any
    other is refused naming both."""
    lathe = ["%_N_TEST_MPF", ";$PATH=/_N_MPF_DIR", "; DRAWING part.dxf", "G18 G71 G90 G40 DIAMON"]
    assert accepted(conn, "lathe-840d", [*lathe, "G54", "M30"])
    message = refusal(conn, "lathe-840d", [*lathe, "G55", "M30"])
    assert "G55 is not the work offset of machine lathe-840d (G54)" in message
