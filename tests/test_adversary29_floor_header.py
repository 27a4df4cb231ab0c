"""Adversary 29 against 4f10afc's `; FLOOR TO FLOOR <m> MIN` header (engine.simulation.hobbing.headers
and floor_facts). The commit refuses "a loose spelling" and "a second line"; a comment is held to the
canonical form only when it holds one of headers.CLAIM's words (`\\bFLOOR`), so a misspelling that
drops the word is an unchecked comment a reader still takes as the figure:

* `; FL00R TO FL00R 9.9 MIN` (zeros for the O's: the same line to the eye on a control's screen);
* `; FLOR TO FLOR 9.9 MIN` (a typo in an edited template row);

each was accepted with the program's own line removed, 9.9 min where the program takes 1.9 (now
refused: a comment with a time in minutes is held to a header's canonical form). And the line was
not held to the header block (now it is): `; CYCLE TIME` after the first motion is refused
(header_place_problem: "one the machine has already passed"), `; FLOOR TO FLOOR` there is accepted.
The program is gear 42's stored spur program on the seeded hobber-840d."""
from __future__ import annotations

import pytest
from helpers.collision_truth import messages

from engine.gears.records import load_gear, load_hobs
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program


def simulated(conn, lines: list[str]):
    hob_id = next(line.split()[2] for line in lines if line.startswith("; HOB "))
    hob = next(hob for hob in load_hobs(conn) if hob.id == hob_id)
    return simulate_program(lines, load_gear(conn, 42), hob, load_machine(conn, "hobber-840d"), "GEAR42")


def without_floor_line(conn) -> tuple[list[str], str]:
    lines = instantiate_gear(conn, 42).lines
    floor = next(line for line in lines if line.startswith("; FLOOR TO FLOOR "))
    return [line for line in lines if line != floor], floor


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("line", ["; FL00R TO FL00R 9.9 MIN", "; FLOR TO FLOR 9.9 MIN"])
def test_a_misspelt_floor_to_floor_line_is_refused(conn, line):
    lines, floor = without_floor_line(conn)
    at = lines.index(next(text for text in lines if text.startswith("; CYCLE TIME "))) + 1
    assert floor != "; FLOOR TO FLOOR 9.9 MIN"            # the program's own figure is another
    assert messages(simulated(conn, lines[:at] + [line] + lines[at:])), line


def test_a_floor_to_floor_line_after_the_motion_is_refused_as_the_cycle_time_is(conn):
    lines, floor = without_floor_line(conn)
    cycle = next(text for text in lines if text.startswith("; CYCLE TIME "))
    late = [text for text in lines if text != cycle]
    assert any("after the first motion" in m for m in messages(simulated(conn, late[:-2] + [cycle] + late[-2:])))
    assert any("after the first motion" in m for m in messages(simulated(conn, lines[:-2] + [floor] + lines[-2:])))
