"""What the environment and the config file may not do (issue 16, adversary review): confirm what
cannot be undone, break an invocation a default does not apply to, or turn an error into two
lines; and what a spreadsheet must not run from `--csv`."""
import csv
import io
import json

import psycopg
import pytest

from engine.cli.app import main
from engine.cli.conventions import COMMAND_LINE_ONLY, envvar_name, option_name, options, walk


def one_error_line(result) -> str:
    assert result.exit_code == 1, result.output
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1, result.stderr
    return result.stderr


def one_json_error(result) -> str:
    assert result.exit_code == 1, result.output
    assert result.stderr.count("\n") == 1, result.stderr
    return json.loads(result.stderr)["error"]


def count(url: str, sql: str) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute(sql).fetchone()[0]


# options that confirm what cannot be undone: typed on the command line only ---------------------

def test_every_command_line_only_option_exists_and_has_no_variable():
    commands = dict(walk(main))
    for (path, name), reason in COMMAND_LINE_ONLY.items():
        found = [option for option in options(commands[path]) if option_name(option) == name]
        assert len(found) == 1 and reason, (path, name)
        assert envvar_name(path, found[0]) not in (found[0].envvar or []), (path, name)


def test_a_variable_does_not_confirm_a_hob_delete(run):
    added = run("hobs", "add", "--id", "H-M5-B-L9", "--module", 5, "--tip-diameter", 100, "--length", 120,
                "--hand", "L", "--accuracy-class", "B")
    assert added.exit_code == 0, added.output
    result = run("hobs", "delete", "H-M5-B-L9", env={"ENGINE_HOBS_DELETE_YES": "1"})
    assert result.exit_code == 1
    assert count(run.url, "SELECT count(*) FROM hob WHERE id = 'H-M5-B-L9'") == 1
    assert run("hobs", "delete", "H-M5-B-L9", "--yes").exit_code == 0
    assert count(run.url, "SELECT count(*) FROM hob WHERE id = 'H-M5-B-L9'") == 0


def test_a_variable_does_not_make_a_program_from_the_draft(run):
    result = run("instantiate", "--gear", 42, "--json", env={"ENGINE_INSTANTIATE_DRAFT": "1"})
    assert result.exit_code == 0, result.output
    program_id = json.loads(result.stdout)["program_id"]
    assert count(run.url, f"SELECT count(*) FROM program WHERE id = {int(program_id)} AND NOT draft") == 1


@pytest.mark.parametrize("table, key, option", [
    ("gears.delete", "yes", "--yes"),
    ("jobs.delete", "yes", "--yes"),
    ("template.release", "yes", "--yes"),
    ("gears.import", "replace", "--replace"),
    ("instantiate", "force", "--force"),
    ("instantiate", "skip_bad", "--skip-bad"),
    ("instantiate", "skip-bad", "--skip-bad"),
])
def test_a_confirming_option_in_the_config_file_is_refused_naming_it(read_only_run, table, key, option):
    read_only_run.config.write_text(f"[{table}]\n{key} = true\n")
    said = one_error_line(read_only_run("gears", "delete", 42))
    assert str(read_only_run.config) in said and option in said and "command line only" in said and "line 2" in said
    assert count(read_only_run.url, "SELECT count(*) FROM gear WHERE id = 42") == 1


# a default that does not apply to the invocation is ignored; typed, it is refused ---------------

def test_the_config_files_batch_habits_leave_one_gear_alone(run):
    run.config.write_text("[instantiate]\nworkers = 4\nexplain = true\n")
    one = run("instantiate", "--gear", 42)
    assert one.exit_code == 0, one.output
    assert one.stdout.rstrip().endswith("M30")
    assert " emitted" in one.stderr   # the config file's explain applies to one program: it is explained


def test_explain_from_the_environment_does_not_refuse_a_batch(read_only_run):
    result = read_only_run("instantiate", "--gears", "42-43", "--dry-run", "--json",
                           env={"ENGINE_INSTANTIATE_EXPLAIN": "1"})
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["dry_run"] is True


@pytest.mark.parametrize("args, option", [
    (("--gear", 42, "--workers", 2), "--workers"),
    (("--gears", "42-43", "--explain"), "--explain"),
])
def test_a_batch_option_typed_where_it_does_not_apply_is_still_refused(read_only_run, args, option):
    assert option in one_error_line(read_only_run("instantiate", *args))


# exclusive flag pairs -----------------------------------------------------------------------------

def test_released_and_draft_together_are_one_usage_error(read_only_run):
    said = one_error_line(read_only_run("programs", "list", "--released", "--draft"))
    assert "--draft" in said and "--released" in said


def test_a_flag_typed_wins_over_its_partner_from_the_environment(run):
    made = run("instantiate", "--gear", 42, "--json")
    program_id = json.loads(made.stdout)["program_id"]
    listed = run("programs", "list", "--released", "--json", env={"ENGINE_PROGRAMS_LIST_DRAFT": "1"})
    assert listed.exit_code == 0, listed.output
    assert [record["program_id"] for record in json.loads(listed.stdout)["programs"]] == [program_id]
    table = run("gears", "list", "--csv", env={"ENGINE_GEARS_LIST_JSON": "1"})
    assert table.exit_code == 0 and table.stdout.startswith("gear_id,")


# errors: JSON when --json comes from the environment or the file; always one line ---------------

def test_a_usage_error_is_json_when_the_environment_asks_for_json(read_only_run):
    said = one_json_error(read_only_run("gears", "list", "--bogus", env={"ENGINE_GEARS_LIST_JSON": "1"}))
    assert "--bogus" in said


def test_a_usage_error_is_json_when_the_config_file_asks_for_json(read_only_run):
    read_only_run.config.write_text("[jobs.list]\njson = true\n")
    said = one_json_error(read_only_run("jobs", "list", "--gear", "forty-two"))
    assert "forty-two" in said


@pytest.mark.parametrize("typed, shown", [("X\n", "X\\n"), ("A\rB", "A\\rB"), ("H\x1b[31m", "H\\x1b[31m"),
                                          ("L\u2028M", "L\\u2028M")])
def test_an_error_naming_a_value_with_a_line_break_is_one_line(read_only_run, typed, shown):
    assert shown in one_error_line(read_only_run("hobs", "show", typed))
    assert shown in one_json_error(read_only_run("hobs", "show", typed, "--json"))


# CSV a spreadsheet opens as text ------------------------------------------------------------------

FORMULAS = {  # material as stored -> the cell a spreadsheet reads (OWASP: a leading ')
    "=cmd|'/c calc'!A1": "'=cmd|'/c calc'!A1",
    "+1+1": "'+1+1",
    "@SUM(A1:A2)": "'@SUM(A1:A2)",
    "\tC45": "'\tC45",
    "\r=1": "'\r=1",
    "-x": "'-x",
    "-5+cmd|' /C calc'!A0": "'-5+cmd|' /C calc'!A0",
    "-2.5": "-2.5",
    "-.5": "-.5",
    "C45-=1": "C45-=1",
}


def test_a_text_cell_that_a_spreadsheet_would_run_is_quoted(run):
    with psycopg.connect(run.url) as conn:
        for number, material in enumerate(FORMULAS):
            conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material) "
                         "VALUES (%s, 'spur', 2, 33, 0, 20, %s)", (93001 + number, material))
    result = run("gears", "list", "--csv")
    assert result.exit_code == 0, result.output
    rows = {row["gear_id"]: row for row in csv.DictReader(io.StringIO(result.stdout, newline=""))}
    assert [rows[str(93001 + number)]["material"] for number in range(len(FORMULAS))] == list(FORMULAS.values())
    assert float(rows["93001"]["module"]) == 2 and rows["93001"]["teeth"] == "33"   # numbers: no quote


def test_numbers_are_written_as_they_are():
    from engine.cli.output import Column, csv_text

    text = csv_text((Column("a", "a"), Column("b", "b")), [{"a": -5, "b": -0.25}])
    assert text == "a,b\n-5,-0.25\n"


@pytest.mark.parametrize("variable", ["ENGINE_INSTANTIATE_SKIP_BAD", "ENGINE_INSTANTIATE_WORKERS"])
def test_a_batch_default_from_the_environment_does_not_refuse_one_gear(run, variable):
    """A shop sets its batches' habit once (docs/guide/configuration.md); `instantiate --gear 42`, on
    which the user gave no batch option, must still make the program."""
    value = "4" if variable.endswith("WORKERS") else "1"
    result = run("instantiate", "--gear", 42, env={variable: value})
    assert result.exit_code == 0, result.output
    assert result.stdout.rstrip().endswith("M30")


def test_a_delete_is_confirmed_on_the_command_line_only(run):
    """The guide (records): a delete without --yes says what it would delete and exits 1. An environment
    variable (or a config file's [gears.delete] yes = true) must not confirm every delete."""
    with psycopg.connect(run.url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width) "
                     "VALUES (91502, 'spur', 2, 33, 0, 20)")
    result = run("gears", "delete", 91502, env={"ENGINE_GEARS_DELETE_YES": "1"})
    assert result.exit_code == 1, result.output
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT count(*) FROM gear WHERE id = 91502").fetchone()[0] == 1
