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
* The look-up: a superscript digit (`²`: str.isdigit() is true, int() refuses it) answered a
  stack trace (500) instead of a refusal, in the box and in /programs/<id>; other Unicode digits
  (`８１２`) led to program 812, though no control shows an id so; and a query of 5000 digits
  (int() refuses more than 4300) answered a stack trace in the box, /programs/<id> and ?gear=.
* The look-up took a pasted line whose DRAFT or UNVERIFIED word is not its program's (a line
  changed: no stored program has it) to that program; and refused a line pasted in upper case
  (the class compared case-sensitively, though the pasted reading takes any case).
* The look-up read `00000812`, eight digits that can only be a hash's first digits (no id is
  written with a leading zero), as program 812 when that program exists: the program whose INPUT
  or template hash starts `00000812` could not be found by it, and 812 was shown instead.

* A Fanuc program's number header `O1234 (NAME)` was never read by the header rule (it has no
  `;`): `O1234 (GEAR 45)` or `O1234 (CYCLE TIME 0.1 MIN)` simulated without a finding. Its name is
  now held to be a program name (engine.names) when it states a header fact.

What held (kept as a regression test): every line the pasted reading takes, whatever Unicode
space parts its words, reads as lineage-shaped to refuse_lineage_shaped and to the database's
lineage_shaped, so no template row writes a line the stored reading exempts or the look-up reads.
"""
from __future__ import annotations

import json

import pytest
from helpers.collision_truth import messages
from helpers.fanuc_cases import twin
from helpers.fanuc_programs import fanuc_program
from starlette.testclient import TestClient

from engine.gears.records import load_gear, load_hobs
from engine.machines.records import load_machine
from engine.nc.lineage import lineage_shaped, read_lineage
from engine.programs.instantiate import instantiate_gear
from engine.service.web.app import create_app
from engine.simulation import simulate_program
from engine.simulation.hobbing.headers import header_name_problem, line_comment_problem
from engine.simulation.hobbing.reading import semicolon_form

LOOPBACK = "http://127.0.0.1"   # the web view answers a loopback Host only
JSON = {"Accept": "application/json"}
MIN_HASH_DIGITS = 8             # the hash digits the lineage line shows, and the look-up reads as a hash
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


# --- the look-up box ----------------------------------------------------------------------------------


@pytest.mark.parametrize("path", ["/lookup?q=²", "/lookup?q=²²²²²²²²²", "/programs/²", "/lookup?q=８１２",
                                  "/programs/٨١٢", "/programs?gear=４２"])
def test_a_query_in_digits_no_control_shows_is_refused_in_one_line(read_only_database_url, path):
    refused_in_one_line(read_only_database_url, path, 400)


# Python's int() refuses a text of more than 4300 digits (sys.int_info.str_digits_check_threshold's
# default limit): such a query is no id, and is answered as one line.
LONG = "1" * 5000


@pytest.mark.parametrize("path, status", [(f"/lookup?q={LONG}", 400), (f"/programs/{LONG}", 400),
                                          (f"/programs?gear={LONG}", 400), (f"/lookup?q=0000{LONG}", 400)])
def test_a_query_of_thousands_of_digits_is_answered_in_one_line(read_only_database_url, path, status):
    refused_in_one_line(read_only_database_url, path, status)


def refused_in_one_line(url: str, path: str, status: int) -> None:
    with TestClient(create_app(url), base_url=LOOPBACK, raise_server_exceptions=False) as client:
        answer = client.get(path, headers=JSON)
    assert answer.status_code == status, answer.text
    assert len(answer.json()["error"].splitlines()) == 1


@pytest.fixture
def made(run):
    """(status of a look-up, program id, its lineage line) of gear 42's program made by the CLI,
    released and verified, and the web view on the same database."""
    result = run("instantiate", "--gear", GEAR, "--json")
    assert result.exit_code == 0, result.output
    program_id = json.loads(result.stdout)["program_id"]
    shown = json.loads(run("programs", "show", program_id, "--json").stdout)["programs"][0]
    assert not shown["draft"] and not shown["unverified"]
    line = next(text for text in shown["lines"] if text.startswith(f"; PROGRAM {program_id} TEMPLATE "))
    with TestClient(create_app(run.url), base_url=LOOPBACK) as client:
        def status(typed: str) -> int:
            return client.get("/lookup", params={"q": typed}, follow_redirects=False).status_code
        yield status, program_id, line


def test_a_pasted_line_in_upper_case_leads_to_its_program(made):
    """A control's screen in capitals: the pasted reading takes any case, the class too."""
    status, program_id, line = made
    assert status(line) == 303 and status(line.upper()) == 303


@pytest.mark.parametrize("words", [" DRAFT", " UNVERIFIED", " DRAFT UNVERIFIED"])
def test_a_pasted_line_whose_draft_or_unverified_word_is_not_its_programs_leads_nowhere(made, words):
    """No stored program has the line (the program is released and verified): it was changed."""
    status, program_id, line = made
    assert status(line + words) == 400


def test_eight_digits_with_a_leading_zero_are_a_hash_not_a_program_id(made):
    """No id is written so; no program's hash starts so here: none is found, not the program."""
    status, program_id, line = made
    zero_led = str(program_id).rjust(MIN_HASH_DIGITS, "0")
    assert zero_led.startswith("0") and status(zero_led) == 404
    assert status(str(program_id)) == 303


# --- a Fanuc program's number header ------------------------------------------------------------------


@pytest.mark.parametrize("name, refused", [("GEAR 45", True), ("CYCLE TIME 0.1 MIN", True), ("HOB H-M9", True),
                                          ("GEAR42", False), ("PART 7", False)])
def test_a_header_fact_in_the_program_number_headers_name_is_refused(name, refused):
    """`O1042 (<program name>)`: the control shows the name beside the number."""
    assert (header_name_problem(name) is not None) == refused


def test_a_fanuc_program_whose_number_header_states_a_gear_is_refused_by_the_simulation(conn, monkeypatch):
    lines, gear, hob, siemens, fanuc = twin(conn, monkeypatch, GEAR)
    program = fanuc_program(lines, gear, hob, fanuc)
    at = next(number for number, line in enumerate(program) if line.startswith("O") and line.endswith(")"))
    assert simulate_program(program, gear, hob, fanuc).refusals == []
    stated = program[:at] + [program[at].split(" ")[0] + " (GEAR 45)"] + program[at + 1:]
    assert simulate_program(stated, gear, hob, fanuc).refusals
