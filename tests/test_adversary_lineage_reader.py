"""Adversary against the one lineage-line reader (engine.nc.lineage.read_lineage) and the two rules
that read through it: the simulation's header-claim rule, whose exemption lets the template-version
line and the lineage line name a class (engine.simulation.hobbing.headers._names_a_class), and the
web view's look-up box (engine.service.web.programs).

What broke:

* The template-version line's exemption took any text without spaces for the class
  (`; TEMPLATE \\S+ v[0-9]+`): a template row writing `; TEMPLATE GEAR=45 v14`, or
  `; TEMPLATE spur;CYCLE_TIME=0.2MIN v14`, states a header fact no rule held (Fanuc's
  `(TEMPLATE GEAR=45 v14)` too, read in the `;` form). A template writes its version line from
  its class, whose name is `[a-z][a-z0-9_]{0,62}` (engine.names, gear_class's CHECK).
* The lineage line's reader took the same `\\S+` for the class; no stored program can carry such
  a line (check_program_lines, check_program_release), but the reader said more than the writer
  can write.

What held (kept as a regression test): every line the pasted reading takes, whatever Unicode
space parts its words, reads as lineage-shaped to refuse_lineage_shaped and to the database's
lineage_shaped, so no template row writes a line the stored reading exempts or the look-up reads.
"""
from __future__ import annotations

import pytest
from helpers.collision_truth import messages

from engine.gears.records import load_gear, load_hobs
from engine.machines.records import load_machine
from engine.nc.lineage import lineage_shaped, read_lineage
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program
from engine.simulation.hobbing.headers import line_comment_problem
from engine.simulation.hobbing.reading import semicolon_form

GEAR = 42                       # the seeded spur gear, on the seeded hobber-840d
# Template-version lines a template row can write, each with a header fact no rule holds.
DRESSED_VERSION_LINES = ["; TEMPLATE GEAR=45 v1", "; TEMPLATE spur;GEAR=45 v1", "; TEMPLATE spur;CYCLE_TIME=0.2MIN v1",
                         "; TEMPLATE HOB_H-M9 v1", "; TEMPLATE x)(GEAR=45 v1"]
HASHES = "176b5437 INPUT bdf26401"
# Every character Python's str reads as a space (the pasted reading's \s), from Unicode itself.
UNICODE_SPACES = [chr(code) for code in range(0x110000) if chr(code).isspace()]


# --- the simulation's header rule ---------------------------------------------------------------------


@pytest.mark.parametrize("line", DRESSED_VERSION_LINES)
def test_a_header_claim_dressed_as_the_template_version_line_is_refused(line):
    assert line_comment_problem(line, "comment") is not None


def test_a_fanucs_template_version_line_dressed_so_is_refused_in_the_form_the_rule_reads():
    """Fanuc/ISO `(…)` comments are read in the `;` form (engine.simulation.hobbing.reading)."""
    assert line_comment_problem(semicolon_form("(TEMPLATE GEAR=45 v14)"), "comment") is not None
    assert line_comment_problem(semicolon_form("(TEMPLATE spur v14)"), "comment") is None


@pytest.mark.parametrize("line", ["; TEMPLATE spur v14", "; TEMPLATE gear_x v3", "; TEMPLATE hobbed_cycle v1",
                                  "; TEMPLATE " + "a" * 63 + " v1"])
def test_a_template_version_line_of_a_class_name_stays_exempt(line):
    assert line_comment_problem(line, "comment") is None


@pytest.mark.parametrize("gear_class", ["x;GEAR=45", "GEAR=45", "spur)(GEAR=45", "Spur"])
def test_the_stored_reading_takes_only_a_class_name_the_writer_can_write(gear_class):
    line = f"; PROGRAM 812 TEMPLATE {gear_class} v14 {HASHES}"
    assert read_lineage(line) is None
    if "GEAR" in gear_class:
        assert line_comment_problem(line, "comment") is not None


def simulated(conn, lines: list[str]):
    hob_id = next(line.split()[2] for line in lines if line.startswith("; HOB "))
    hob = next(hob for hob in load_hobs(conn) if hob.id == hob_id)
    return simulate_program(lines, load_gear(conn, GEAR), hob, load_machine(conn, "hobber-840d"), "GEAR42")


def test_a_programs_template_version_line_dressed_with_a_gear_is_refused_by_the_simulation(conn):
    """The made program passes; a second version line (the first still names the class, so the
    GEAR line's CLASS agrees with it) stating another gear is refused."""
    lines = instantiate_gear(conn, GEAR).lines
    at = next(number for number, line in enumerate(lines) if line.startswith("; TEMPLATE spur v"))
    assert not messages(simulated(conn, lines))
    assert messages(simulated(conn, lines[:at + 1] + ["; TEMPLATE GEAR=45 v1"] + lines[at + 1:]))


# --- what reads as a lineage line is refused as a template's line --------------------------------------


@pytest.mark.parametrize("space", UNICODE_SPACES, ids=lambda space: f"U+{ord(space):04X}")
def test_every_line_either_reading_takes_is_lineage_shaped_in_python_and_the_database(conn, space):
    """A line the look-up reads as a lineage line (an operator reads it so at the control) must be
    one that no template row may write: refuse_lineage_shaped and check_program_lines read it so
    whatever space separates its words (a regression test: adversary of the one reader)."""
    words = f"PROGRAM 812 TEMPLATE spur v14 {HASHES}".replace(" ", space)
    for line in (f";{space}{words}", f"({words})", f"N10{space};{words}".lower()):
        assert read_lineage(line, pasted=True) is not None, repr(line)
        assert lineage_shaped(line), repr(line)
        assert conn.execute("SELECT lineage_shaped(%s)", (line,)).fetchone()[0], repr(line)
