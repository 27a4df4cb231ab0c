"""An id beyond what its column holds (gear ids are PostgreSQL integers, job and program ids
bigints) is bad input: one line naming the option and the value, exit 1 (issue 16), never a
database error (exit 2)."""
from __future__ import annotations

import pytest

INTEGER_BEYOND, BIGINT_BEYOND = "2147483648", "9223372036854775808"
COMMANDS = (
    ("jobs", "list", "--gear", INTEGER_BEYOND),
    ("jobs", "show", BIGINT_BEYOND),
    ("jobs", "delete", BIGINT_BEYOND),
    ("programs", "list", "--gear", INTEGER_BEYOND),
    ("programs", "list", "--job", BIGINT_BEYOND),
    ("programs", "show", BIGINT_BEYOND),
    ("gears", "show", INTEGER_BEYOND),
    ("gears", "delete", INTEGER_BEYOND),
    ("cases", "confirm", "--job", BIGINT_BEYOND),
    ("suggest", "--gear", INTEGER_BEYOND),
    ("classify", "--gear", INTEGER_BEYOND),
    ("hobs", "match", "--gear", INTEGER_BEYOND),
    ("explain", "--program", BIGINT_BEYOND),
    ("simulate", "--program", BIGINT_BEYOND),
    ("template", "diff", "--class", "spur", "--from", "1", "--to", INTEGER_BEYOND),
)


@pytest.mark.parametrize("args", COMMANDS, ids=" ".join)
def test_an_id_beyond_its_column_is_bad_input(read_only_run, args):
    result = read_only_run(*args)
    assert result.exit_code == 1, result.output
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1
    assert args[-1] in result.stderr


LARGEST = (("jobs", "list", "--gear", "2147483647"), ("programs", "list", "--job", "9223372036854775807"))


@pytest.mark.parametrize("args", LARGEST, ids=" ".join)
def test_the_largest_id_a_column_holds_is_a_filter_that_finds_nothing(read_only_run, args):
    result = read_only_run(*args, "--json")
    assert result.exit_code == 0, result.output


OUT_OF_RANGE_FILTERS = (   # a filter id beyond PostgreSQL's integer/bigint: bad input, not a bug
    ("jobs", "list", "--gear", "99999999999"),
    ("programs", "list", "--gear", "99999999999"),
    ("programs", "list", "--job", "99999999999999999999"),
)


@pytest.mark.parametrize("args", OUT_OF_RANGE_FILTERS, ids=" ".join)
def test_a_filter_id_out_of_range_is_bad_input_not_a_bug(read_only_run, args):
    result = read_only_run(*args)
    assert result.exit_code == 1, result.output
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1
    assert args[-1] in result.stderr


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_instantiate_gear_0_names_the_gear(read_only_run):
    """--gear 0 was given: the message must not say none was."""
    result = read_only_run("instantiate", "--gear", 0, "--dry-run")
    assert result.exit_code == 1
    assert "give exactly one of" not in result.stderr and "0" in result.stderr, result.stderr
