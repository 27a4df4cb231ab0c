"""The lineage line read back (engine.nc.lineage.read_lineage): what the writer writes, in every
dialect's comment form, reads as the values it was written from; a line that is not a whole lineage
line is refused. Both readers go through it: the web view's look-up (a pasted line, lenient) and the
simulation's header rule (a stored line, exactly as written)."""
from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.nc.lineage import DRY_RUN_ID, lineage_line, lineage_words, read_lineage
from engine.service.web.answers import BadRequest
from engine.service.web.programs import pasted_lineage
from engine.simulation.hobbing.headers import CLAIM, line_comment_problem
from engine.verifier.grammar import DIALECTS

BIGINT_MAX = 2**63 - 1         # a program id is a PostgreSQL bigint
INTEGER_MAX = 2**31 - 1        # a template version an integer
# The controls whose comments are in parentheses (ISO, Fanuc); the others' follow `;`.
PARENTHESES = {"iso", "fanuc", "fanuc-g81.4"}
ALL_DIALECTS = sorted({dialect for _, dialect in DIALECTS} | {"unknown"})   # an unknown one: the 840D form
HEXES = st.text("0123456789abcdef", min_size=8, max_size=64)
CLASSES = st.from_regex(r"[a-z][a-z0-9_]{0,30}", fullmatch=True)   # gear_class.name's CHECK
IDS = st.one_of(st.integers(1, BIGINT_MAX), st.just(DRY_RUN_ID))
# What the line is written from: program id, class, version, template and input hash, draft, unverified.
REST = (CLASSES, st.integers(0, INTEGER_MAX), HEXES, HEXES, st.booleans(), st.booleans())
VALUES = st.tuples(IDS, *REST)
STORED_VALUES = st.tuples(st.integers(1, BIGINT_MAX), *REST)   # a stored program's: an id, no DRY-RUN
SPACES = st.text(" \t\u00a0", min_size=1, max_size=3)
NOT_WHOLE = "reads as a lineage line but not a whole one"
LINE = "; PROGRAM 812 TEMPLATE spur v14 176b5437 INPUT bdf26401"
# A line each reader refuses (stored: exact; pasted: lenient) → whether the pasted reader takes it.
REFUSED_STORED = {
    LINE + " GEAR 44": False,                                # a header claim added
    LINE + " UNVERIFIED DRAFT": False,                       # the words out of order
    LINE.replace(" v14 ", " 14 "): False,                    # no `v`
    LINE.replace("176b5437", "176b543"): False,              # a hash cut short
    LINE.replace("176b5437", "176b54370"): False,            # a hash too long
    LINE.replace("812", "8" * 20): False,                    # more digits than a bigint has
    LINE.replace("v14", "v" + "1" * 11): False,              # more digits than an integer has
    LINE.rsplit(" INPUT", 1)[0]: False,                      # the INPUT word left out
    LINE.replace("TEMPLATE spur ", "TEMPLATE "): False,      # no class
    LINE.replace("; ", ";; "): False,                        # the comment opened twice
    "; PROGRAM 812 TEMPLATE spur v14 176b5437 INPUT": True,  # the INPUT hash left out
    LINE.replace(" TEMPLATE", "  TEMPLATE"): True,           # two spaces
    LINE.lower(): True, LINE.upper(): True,
    "N10 " + LINE: True, LINE + " ": True, " " + LINE: False,   # the look-up strips it first
    LINE + ")": True,                                        # closed as the other form is
    "(" + LINE[2:]: True,                                    # opened, not closed
    LINE.replace(";", "(", 1) + " )": True,
}


def written(values: tuple, dialect: str) -> str:
    return lineage_line(lineage_words(*values), dialect)


def expected(values: tuple) -> tuple:
    """What the line says: id, class, version, DRAFT and UNVERIFIED as given, each hash's first 8 digits."""
    program_id, gear_class, version, template, given_input, draft, unverified = values
    return (program_id, gear_class, version, template[:8], given_input[:8], draft, unverified)


@settings(max_examples=300, deadline=None)
@given(VALUES, st.sampled_from(ALL_DIALECTS))
def test_what_the_writer_writes_reads_back_in_every_dialects_comment_form(values, dialect):
    line = written(values, dialect)
    opening, closing = ("(", ")") if dialect in PARENTHESES else ("; ", "")
    assert line.startswith(opening) and line.endswith(closing), line
    assert tuple(read_lineage(line)) == expected(values)
    assert tuple(read_lineage(line, pasted=True)) == expected(values)


@settings(max_examples=200, deadline=None)
@given(VALUES, st.sampled_from(ALL_DIALECTS), st.integers(1, 99999), SPACES, st.sampled_from([str.upper, str.lower]))
def test_a_pasted_line_reads_back_after_a_block_number_in_any_case_and_spacing(values, dialect, block, spaces, case):
    """What a control's screen or a copy does to the line: a block number before it, other spaces,
    another case (the class as the case makes it, the hashes in lower case, DRY-RUN in any)."""
    pasted = case(f"N{block}{spaces}" + written(values, dialect).replace(" ", spaces))
    program_id, gear_class, *rest = expected(values)
    assert tuple(read_lineage(pasted, pasted=True)) == (program_id, case(gear_class), *rest)
    assert read_lineage(pasted) is None


@settings(max_examples=100, deadline=None)
@given(VALUES, st.sampled_from(ALL_DIALECTS))
def test_no_cut_of_a_written_line_reads_as_stored_unless_the_writer_writes_it(values, dialect):
    """Every beginning of the line, cut anywhere: whole only where it is the line the writer writes
    with fewer of the trailing words (DRAFT, UNVERIFIED)."""
    line = written(values, dialect)
    shorter = {written((*values[:5], draft, unverified), dialect)
               for draft in {False, values[5]} for unverified in {False, values[6]}}
    for end in range(len(line)):
        assert (read_lineage(line[:end]) is not None) == (line[:end] in shorter), line[:end]


@pytest.mark.parametrize("text, pasted_reads", REFUSED_STORED.items())
def test_a_line_that_is_not_exactly_the_writers_is_refused_as_stored(text, pasted_reads):
    assert read_lineage(text) is None
    found = read_lineage(text, pasted=True)
    assert (found is not None) == pasted_reads, found
    if found is not None:
        assert (found.program_id, found.gear_class.lower(), found.version) == (812, "spur", 14)


@pytest.mark.parametrize("text", ["", "; PROGRAM", "; program from template of spur", "PROGRAM 812 TEMPLATE spur "
                                  "v14 176b5437 INPUT bdf26401", "; TEMPLATE spur v14", "176b5437", "812"])
def test_text_that_is_no_lineage_line_is_refused_by_both_readings(text):
    assert read_lineage(text) is None and read_lineage(text, pasted=True) is None


# --- the web view's look-up reads a pasted line through it ------------------------------------------


@settings(max_examples=100, deadline=None)
@given(STORED_VALUES, st.sampled_from(ALL_DIALECTS))
def test_the_lookup_takes_a_written_line_for_its_program(values, dialect):
    said = pasted_lineage(f"  N20 {written(values, dialect)} ")
    assert said is not None and tuple(said) == expected(values)


@pytest.mark.parametrize("text", [LINE.rsplit(" INPUT", 1)[0], LINE + " GEAR 44", LINE.replace("v14", "v" + "1" * 11)])
def test_the_lookup_refuses_a_line_that_is_no_stored_programs_whole_line(text):
    with pytest.raises(BadRequest, match=NOT_WHOLE):
        pasted_lineage(text)


def test_the_lookup_says_a_dry_runs_line_names_no_stored_program():
    with pytest.raises(BadRequest, match="is a dry run's lineage line: a dry run stores no program") as refused:
        pasted_lineage(f"N30 {LINE.replace('812', DRY_RUN_ID.lower())}")
    assert NOT_WHOLE not in str(refused.value)


def test_the_lookup_passes_over_what_is_no_lineage_line_and_checks_the_id_range():
    assert pasted_lineage("; program from template of spur") is None and pasted_lineage("bdf26401") is None
    with pytest.raises(BadRequest, match="give a program id, a whole number from 1 to"):
        pasted_lineage(LINE.replace("812", str(BIGINT_MAX + 1)))


# --- the simulation's header rule reads a stored line through it -------------------------------------


@settings(max_examples=100, deadline=None)
@given(STORED_VALUES, st.sampled_from(["gear_", "hob_", "hobbed_", "machine_", "fixture_"]))
def test_a_stored_lineage_line_whose_class_holds_a_header_word_is_no_header_claim(values, word):
    """The 840D's line of a class named `gear_…` (hobbing programs are never UNVERIFIED)."""
    line = written((values[0], word + values[1], *values[2:6], False), "840d")
    assert CLAIM.search(line)                                           # the rule reads it
    assert line_comment_problem(line, "comment") is None
    assert line_comment_problem(line + " GEAR 44", "comment") is not None            # a claim added
    assert line_comment_problem(line.replace(" v", "  v", 1), "comment") is not None  # respelt
