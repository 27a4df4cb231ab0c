"""The class templates make the Fanuc M-series form (issue 30, docs/reference/fanuc-egb.md §F3): on a
hobber of dialect `fanuc-g81.4` the coupling is `G81.4 R<teeth> L<threads>` … `G80.4`, from the
same rows and model values as the `fanuc` form's `G81 T L` … `G80`. R is the number of teeth
(1…500), L the hob threads (1…30) with a sign, "the sign giving the C axis's direction" [16i-HB]
p. 116, so L carries the direction as G81's L does (§F5). Expected words are computed here from
the reference (h = +1 right hand, −1 left hand; c, b the record's senses): R = z2,
L = −h_hob·c·b·z0. Q and P in G81.4 have no confirmed units or compensation (§F3): a gear that
needs them (β ≠ 0, not a worm wheel) is refused in one line, nothing stored.

The record is the seeded `hobber-fanuc` copied with its dialect changed, so its programs are the
`fanuc` programs' twins: the same moves, and every line but the coupling, the header's machine
name and the lineage line the same."""
from __future__ import annotations

import re

import pytest
from helpers.machines import add_machine_like

from engine.errors import EngineError
from engine.gears.records import load_gear, load_hobs
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program
from engine.verifier import verify_program

FANUC, M_SERIES = "hobber-fanuc", "hobber-fanuc-m"
PROGRAMS = "SELECT count(*) FROM program"
HELICAL = "UPDATE gear SET helix_angle = %s, hand = 'R' WHERE id = %s"
# Seeded gears (seed_templates/gears.csv) a G81.4 program is made for: every class without Q/P.
GEARS = [pytest.param(42, id="spur"), pytest.param(46, id="spur 2-start hob"), pytest.param(54, id="duplex"),
         pytest.param(50, id="taper beta 0"), pytest.param(51, id="crowned beta 0"),
         pytest.param(53, id="worm wheel radial")]
G81_4 = re.compile(r"G81\.4 R(?P<r>\d+) L(?P<l>-?\d+)")
MOVE = re.compile(r"G[01] ")


@pytest.fixture
def m_series(conn) -> str:
    return add_machine_like(conn, FANUC, M_SERIES, dialect="fanuc-g81.4")


def hand(letter) -> int:
    return -1 if letter == "L" else 1


def job_hob(conn, program):
    hob_id = conn.execute("SELECT hob_id FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    return next(hob for hob in load_hobs(conn) if hob.id == hob_id)


def expected_words(teeth: int, hob, machine) -> dict:
    """§F3 with §F5's direction: R = z2, L = −h_hob·c·b·z0."""
    return {"r": teeth, "l": -hand(hob.hand) * machine.c_direction * machine.b_direction * hob.starts}


def read_words(line: str) -> dict:
    found = G81_4.fullmatch(line)
    assert found, line
    return {key: int(value) for key, value in found.groupdict().items()}


def moves(lines: list[str]) -> list[str]:
    return [line for line in lines if MOVE.match(line)]


def as_g81(line: str, machine: str) -> str:
    """A G81.4 program's line as the G81 twin writes it: the coupling's words and the machine's name
    (the lineage line, which names the program, is compared without)."""
    line = re.sub(r"^G81\.4 R", "G81 T", line).replace("G80.4", "G80")
    return line.replace(f"(MACHINE {M_SERIES})", f"(MACHINE {machine})")


@pytest.mark.parametrize("gear_id", GEARS)
def test_the_g81_4_program_is_verified_simulated_and_the_g81_programs_twin(conn, m_series, gear_id):
    program = instantiate_gear(conn, gear_id, machine=m_series)
    twin = instantiate_gear(conn, gear_id, machine=FANUC)
    machine, gear, hob = load_machine(conn, m_series), load_gear(conn, gear_id), job_hob(conn, program)
    verify_program(program.lines, machine, program.name)
    assert simulate_program(program.lines, gear, hob, machine, program.name).refusals == []
    teeth = [gear.teeth, *(unit.teeth for unit in gear.units)]
    assert [read_words(line) for line in program.lines if line.startswith("G81")] == [
        expected_words(t, hob, machine) for t in teeth]
    assert program.lines.count("G80.4") == len(teeth) and "G80" not in program.lines
    assert program.lines.index("G80.4") < program.lines.index("M30")
    assert moves(program.lines) == moves(twin.lines) and moves(program.lines)
    lineage = [i for i, line in enumerate(twin.lines) if line.startswith("(PROGRAM ")]
    assert [as_g81(line, FANUC) for i, line in enumerate(program.lines) if i not in lineage] == [
        line for i, line in enumerate(twin.lines) if i not in lineage]


@pytest.mark.parametrize("gear_id, helix", [(43, None), (47, None), (50, 10)],
                         ids=["helical R", "helical beta 20", "taper beta 10"])
def test_a_gear_needing_q_and_p_is_refused_in_one_line_nothing_stored(conn, m_series, gear_id, helix):
    if helix is not None:   # the seeded taper gear made helical, right hand
        conn.execute(HELICAL, (helix, gear_id))
    before = conn.execute(PROGRAMS).fetchone()[0]
    with pytest.raises(EngineError) as refused:
        instantiate_gear(conn, gear_id, machine=m_series)
    message = str(refused.value)
    assert message.startswith(f"gear {gear_id} on {M_SERIES} (Fanuc G81.4): a helical gear")
    assert "Q/P" in message and "§F3" in message and "nothing stored" in message and "\n" not in message
    assert conn.execute(PROGRAMS).fetchone()[0] == before
