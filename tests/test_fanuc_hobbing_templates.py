"""The class templates make Fanuc hobbing programs (issue 30): `instantiate --machine hobber-fanuc`
stores a program the Fanuc grammar reads and the simulation proves, its coupling rendered as
`G81 T L [Q P]` … `G80` from the same model values as the 840D's EGON, and its moves the 840D
program's moves.

Expected words come from the reference (docs/reference/fanuc-egb.md §F5; h = +1 right hand, −1
left hand; c, b, z the record's senses; s its egb_helix_sign), computed here:
T = z2, L = −h_hob·c·b·z0, and for a helical gear Q = m_n, P = −h_gear·c·z·s·β; a spur gear has
neither Q nor P, and no program has an explicit differential (no EGON, no C word).

The seeded Fanuc hobber's programs are made without the tailstock here (the agreed M20/M21 blocks
came to the Fanuc grammar in a change of their own; a test below shows the rows render them).
Taper, crowned and the worm wheel's radial plunge need G64/G61 and the dwell G04: strict xfail
while the grammar of this tree does not read them (PENDING_GRAMMAR)."""
from __future__ import annotations

import math
import re

import pytest
from helpers.machines import add_machine_like

from engine.errors import EngineError
from engine.gears.records import load_gear, load_hobs
from engine.hobbing import dialects
from engine.hobbing.choices import Choices
from engine.machines.records import load_machine
from engine.programs import verified_run
from engine.programs.instantiate import instantiate_gear
from engine.programs.remake import instantiate_job
from engine.simulation import simulate_program
from engine.verifier import verify_program
from engine.verifier.grammar import HOBBING_FANUC

FANUC, SIEMENS = "hobber-fanuc", "hobber-840d"
NO_TAILSTOCK = Choices(tailstock=False)
# The Fanuc grammar of this tree reads G64/G61 and G04 or not yet (a grammar change of issue 30):
# until it does, taper, crowned and the worm wheel are refused at those blocks (strict xfail).
PENDING_GRAMMAR = pytest.mark.xfail(not {61, 64, 4} <= HOBBING_FANUC.g_codes.keys(), strict=True,
                                    reason="Fanuc grammar: G64/G61/G04 not read yet (issue 30)")
# Seeded gears (seed_templates/gears.csv) by class; both hands come from 43 (R) and 44 (L).
GEARS = [pytest.param(42, id="spur"), pytest.param(43, id="helical R"), pytest.param(44, id="helical L"),
         pytest.param(45, id="spur 2 cuts"), pytest.param(46, id="spur 2-start hob"),
         pytest.param(47, id="helical beta 20"), pytest.param(54, id="duplex"),
         pytest.param(50, id="taper", marks=PENDING_GRAMMAR), pytest.param(51, id="crowned", marks=PENDING_GRAMMAR),
         pytest.param(53, id="worm wheel radial", marks=PENDING_GRAMMAR)]
G81 = re.compile(r"G81 T(?P<t>\d+) L(?P<l>-?\d+)(?: Q(?P<q>\d+\.\d*) P(?P<p>-?\d+\.\d{4}))?")
MOVE = re.compile(r"G[01] ")
C_WORD = re.compile(r"(^| )C[-+.\d]")
PROGRAMS = "SELECT count(*) FROM program"


def hand(letter) -> int:
    return -1 if letter == "L" else 1


def job_hob(conn, program):
    hob_id = conn.execute("SELECT hob_id FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    return next(hob for hob in load_hobs(conn) if hob.id == hob_id)


def expected_g81(gear, teeth: int, hob, machine) -> dict:
    """The words of §F5 for one toothing of `teeth` on the record's senses."""
    words = {"t": teeth, "l": -hand(hob.hand) * machine.c_direction * machine.b_direction * hob.starts}
    if gear.helix_angle and gear.gear_class != "worm_wheel":
        words["q"] = gear.module
        words["p"] = (-hand(gear.hand) * machine.c_direction * machine.z_direction * machine.egb_helix_sign
                      * gear.helix_angle)
    return words


def read_g81(line: str) -> dict:
    found = G81.fullmatch(line)
    assert found, line
    return {key: (float(value) if key in "qp" else int(value)) for key, value in found.groupdict().items()
            if value is not None}


def moves(lines: list[str]) -> list[str]:
    """The motion blocks, 840D's `A=` written as Fanuc's `A`."""
    return [line.replace("A=", "A") for line in lines if MOVE.match(line)]


@pytest.mark.parametrize("gear_id", GEARS)
def test_the_seeded_gear_on_the_fanuc_hobber_is_stored_verified_and_simulated(conn, gear_id):
    program = instantiate_gear(conn, gear_id, machine=FANUC, choices=NO_TAILSTOCK)
    machine, gear, hob = load_machine(conn, FANUC), load_gear(conn, gear_id), job_hob(conn, program)
    stored = conn.execute("SELECT lines FROM program WHERE id = %s", (program.program_id,)).fetchone()[0]
    assert stored == program.lines
    verify_program(program.lines, machine, program.name)
    assert simulate_program(program.lines, gear, hob, machine, program.name).refusals == []
    lines = program.lines
    assert lines[0] == lines[-1] == "%" and lines[1] == f"O{machine.program_number_base + gear_id:04d} (GEAR{gear_id})"
    assert lines[-2] == "M30" and "G21 G90 G94" in lines and not any(";" in line for line in lines)
    teeth = [gear.teeth, *(unit.teeth for unit in gear.units)]
    assert [read_g81(line) for line in lines if line.startswith("G81")] == [expected_g81(gear, t, hob, machine)
                                                                           for t in teeth]
    assert lines.count("G80") == len(teeth) and lines.index("G80") < lines.index("M30")
    assert not any(word in line for line in lines for word in ("EGON", "EGDEF", "G25", "G26", "WALIMON"))
    assert not any(C_WORD.search(line) for line in lines)   # the control's Q/P is the differential, once


@pytest.mark.parametrize("gear_id", [42, 43, 44, 47, 54])
def test_the_fanuc_program_makes_the_840d_programs_moves_and_the_840d_program_is_unchanged(conn, gear_id):
    fanuc = instantiate_gear(conn, gear_id, machine=FANUC, choices=NO_TAILSTOCK)
    siemens = instantiate_gear(conn, gear_id, machine=SIEMENS, choices=NO_TAILSTOCK)
    assert moves(fanuc.lines) == moves(siemens.lines) and moves(fanuc.lines)
    assert siemens.lines[0] == f"%_N_GEAR{gear_id}_MPF" and any(line.startswith("EGON(") for line in siemens.lines)
    assert not any(line.startswith(("%", "O", "G81", "G80", "(")) for line in siemens.lines[1:])


@pytest.mark.parametrize("gear_hand", ["R", "L"])
@pytest.mark.parametrize("hob_hand", ["R", "L"])
@pytest.mark.parametrize("senses", [{}, {"c_direction": -1}, {"b_direction": -1, "z_direction": -1},
                                    {"egb_helix_sign": -1}])
def test_l_and_p_follow_both_hands_the_senses_and_the_records_helix_sign(conn, gear_hand, hob_hand, senses):
    conn.execute("UPDATE hob SET hand = %s", (hob_hand,))
    conn.execute("UPDATE gear SET hand = %s WHERE id = 43", (gear_hand,))
    name = add_machine_like(conn, FANUC, "hobber-fanuc-senses", **senses)
    program = instantiate_gear(conn, 43, machine=name, choices=NO_TAILSTOCK)
    machine, gear, hob = load_machine(conn, name), load_gear(conn, 43), job_hob(conn, program)
    [line] = [line for line in program.lines if line.startswith("G81")]
    words, expected = read_g81(line), expected_g81(gear, gear.teeth, hob, machine)
    assert {key: words[key] for key in "tlq"} == {key: expected[key] for key in "tlq"}
    assert math.isclose(words["p"], expected["p"], abs_tol=5e-5)
    assert simulate_program(program.lines, gear, hob, machine, program.name).refusals == []


def test_the_tailstock_rows_render_the_agreed_fanuc_blocks(conn, monkeypatch):
    """M20/M21 with their comment in parentheses (the grammar's reading of them is pending)."""
    monkeypatch.setattr(verified_run, "verify_program", lambda *args: None)
    monkeypatch.setattr(verified_run, "prove", lambda *args: None)
    lines = instantiate_gear(conn, 42, machine=FANUC).lines
    assert "M20 (TAILSTOCK CLAMP)" in lines and "M21 (TAILSTOCK RELEASE)" in lines


REFUSALS = [   # (record changes, choices, words of the one-line reason)
    ({"egb_helix_sign": None}, NO_TAILSTOCK, "egb_helix_sign"),
    ({"program_number_base": 8960}, NO_TAILSTOCK, "O9003"),
    ({"program_number_base": None}, NO_TAILSTOCK, "program_number_base"),
    ({"orient_before_coupling": True}, NO_TAILSTOCK, "orient"),
]


@pytest.mark.parametrize("changes, choices, words", REFUSALS, ids=[case[2] for case in REFUSALS])
def test_what_the_fanuc_form_cannot_write_is_refused_in_one_line_nothing_stored(conn, changes, choices, words):
    name = add_machine_like(conn, FANUC, "hobber-fanuc-refuses", **changes)
    before = conn.execute(PROGRAMS).fetchone()[0]
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, 43, machine=name, choices=choices)
    message = str(refused.value)
    assert words in message and "nothing stored" in message and "\n" not in message
    assert conn.execute(PROGRAMS).fetchone()[0] == before


def test_a_tangential_worm_wheel_feed_is_refused_on_fanuc(conn):
    with pytest.raises(EngineError, match="G81 has no Y term"):
        instantiate_gear(conn, 53, machine=FANUC, choices=Choices(tailstock=False, worm_feed="tangential"))


def test_a_hobber_of_a_dialect_no_template_writes_is_refused_by_name(conn):
    name = add_machine_like(conn, FANUC, "hobber-linuxcnc", dialect="linuxcnc")
    with pytest.raises(EngineError, match="runs dialect linuxcnc"):
        instantiate_gear(conn, 42, machine=name, choices=NO_TAILSTOCK)


@pytest.mark.parametrize("machine", [SIEMENS, FANUC])
def test_a_job_stored_before_the_dialect_parameters_is_made_again_in_its_machines_dialect(conn, machine):
    made = instantiate_gear(conn, 42, machine=machine, choices=NO_TAILSTOCK)
    conn.execute("UPDATE job SET params = params - 'dialect' - 'fanuc' - 'program_number' - 'egb_helix_sign' "
                 "- 'egb_start' - 'egb_teeth' - 'egb_stop' WHERE id = %s",
                 (made.job_id,))
    again = instantiate_job(conn, made.job_id)
    assert again.lines[:6] == made.lines[:6] and again.lines[7:] == made.lines[7:]   # the lineage aside


def test_a_class_without_fanuc_rows_is_refused_by_name_nothing_stored(conn, monkeypatch):
    """A class whose template has no Fanuc rows (here spur, taken out of the table) is named, not
    read line by line as 840D code by the Fanuc grammar."""
    monkeypatch.setattr(dialects, "FANUC_CLASSES", dialects.FANUC_CLASSES - {"spur"})
    before = conn.execute(PROGRAMS).fetchone()[0]
    with pytest.raises(EngineError, match=r"^gear 42 on hobber-fanuc \(Fanuc\): class spur has no Fanuc rows"):
        instantiate_gear(conn, 42, machine=FANUC, choices=NO_TAILSTOCK)
    assert conn.execute(PROGRAMS).fetchone()[0] == before
