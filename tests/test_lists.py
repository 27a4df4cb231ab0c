"""Looking into what exists (issue 16): `engine gears|jobs|programs|hobs list|show|delete`, the
list forms (table, one JSON line, CSV) and their filters, against records each test stores itself."""
from __future__ import annotations

import csv
import io
import json
import subprocess
import sys
from pathlib import Path

import psycopg
import pytest
from psycopg import sql

# Gears of this test, stored on days of their own (the seeded gears are stored today).
GEARS = (  # id, class, module, teeth, face width, material, day stored
    (91001, "spur", 2.5, 31, 22, "C45", "2020-03-01"),
    (91002, "helical", 3, 27, 30, "42CrMo4", "2020-03-15"),
    (91003, "spur", 1.25, 60, 10, "16MnCr5", "2020-04-02"),
)
JOB_PARAMS = {"mn": 2.5, "z2": 31, "program_name": "LISTS_TEST"}


def execute(url, statement, params=()) -> None:
    with psycopg.connect(url) as conn:
        conn.execute(statement, params)


def rows_of(url, table: str) -> list[tuple]:
    with psycopg.connect(url) as conn:
        return conn.execute(sql.SQL("SELECT * FROM {} ORDER BY 1, 2").format(sql.Identifier(table))).fetchall()


def store_gears(url) -> None:
    for gear_id, gear_class, module, teeth, width, material, day in GEARS:
        helix = (15, "R") if gear_class == "helical" else (0, None)
        execute(url, "INSERT INTO gear (id, gear_class, module, teeth, helix_angle, hand, face_width, material, "
                     "created_at) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s::date + time '10:00')",
                (gear_id, gear_class, module, teeth, *helix, width, material, day))


def store_job(url, gear_id: int, day: str, gear_class: str = "spur", hob_id: str | None = None) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("INSERT INTO job (gear_id, gear_class, machine, hob_id, params, created_at) "
                            "VALUES (%s, %s, 'hobber-840d', %s, %s, %s::date + time '11:00') RETURNING id",
                            (gear_id, gear_class, hob_id, json.dumps(JOB_PARAMS), day)).fetchone()[0]


def listed(run, *args) -> list[dict]:
    """The records of a list command's --json: exactly one line, one key."""
    result = run(*args, "--json")
    assert result.exit_code == 0, result.output
    assert result.stdout.count("\n") == 1, result.stdout
    payload = json.loads(result.stdout)
    assert len(payload) == 1
    return next(iter(payload.values()))


def ours(records: list[dict]) -> dict[int, dict]:
    mine = {gear_id for gear_id, *_ in GEARS}
    return {record["gear_id"]: record for record in records if record["gear_id"] in mine}


def refused(result, *words) -> str:
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert message.startswith("error: ") and "\n" not in message, message
    for word in words:
        assert word in message, message
    return message


# --- gears ------------------------------------------------------------------------------------------------

def test_gears_list_json_gives_each_stored_gear_with_its_class(run):
    store_gears(run.url)
    found = ours(listed(run, "gears", "list"))
    assert sorted(found) == [91001, 91002, 91003]
    for gear_id, gear_class, module, teeth, width, material, day in GEARS:
        record = found[gear_id]
        assert (record["class"], record["module"], record["teeth"], record["face_width"], record["material"]) == \
            (gear_class, module, teeth, width, material)
        assert record["created_at"].startswith(day) and record["unit_count"] == 1 and record["job_count"] == 0


@pytest.mark.parametrize("filters, expected", [
    (("--class", "spur"), [91001, 91003]),
    (("--class", "helical"), [91002]),
    (("--since", "2020-03-15"), [91002, 91003]),
    (("--until", "2020-03-15"), [91001, 91002]),
    (("--since", "2020-03-02", "--until", "2020-04-01"), [91002]),
    (("--class", "spur", "--since", "2020-03-02"), [91003]),
])
def test_gears_list_filters_select_the_right_gears(run, filters, expected):
    store_gears(run.url)
    assert sorted(ours(listed(run, "gears", "list", *filters))) == expected


def test_gears_list_days_exclude_the_gears_stored_today(run):
    store_gears(run.url)
    found = listed(run, "gears", "list", "--until", "2020-12-31")
    assert sorted(record["gear_id"] for record in found) == [91001, 91002, 91003]


def test_gears_list_csv_and_table(run):
    store_gears(run.url)
    result = run("gears", "list", "--class", "helical", "--until", "2020-12-31", "--csv")
    assert result.exit_code == 0, result.output
    rows = list(csv.DictReader(io.StringIO(result.stdout)))   # the columns `gears import` reads (issue 31)
    assert [(row["gear_id"], row["gear_class"], row["teeth"], row["material"]) for row in rows] == \
        [("91002", "helical", "27", "42CrMo4")]
    table = run("gears", "list", "--until", "2020-12-31")
    assert table.exit_code == 0 and table.stderr.strip() == "3 gears"
    lines = table.stdout.splitlines()
    assert lines[0].split()[:4] == ["gear", "class", "m", "z"]
    assert [line.split()[:4] for line in lines[1:]] == [["91001", "spur", "2.5", "31"], ["91002", "helical", "3", "27"],
                                                        ["91003", "spur", "1.25", "60"]]


def test_gears_show_gives_the_gear_its_units_and_its_jobs(run):
    store_gears(run.url)
    execute(run.url, "INSERT INTO gear_unit (gear_id, unit, teeth, face_width, z_top) VALUES (91001, 2, 17, 12, -30)")
    job_id = store_job(run.url, 91001, "2020-05-05", hob_id="H-M2-AA-R1")
    result = run("gears", "show", 91001, "--json")
    assert result.exit_code == 0 and result.stdout.count("\n") == 1
    gear = json.loads(result.stdout)["gear"]
    assert (gear["gear_id"], gear["class"], gear["module"], gear["teeth"], gear["material"]) == \
        (91001, "spur", 2.5, 31, "C45")
    assert [(unit["unit"], unit["teeth"], unit["z_top"]) for unit in gear["units"]] == [(2, 17, -30)]
    assert [(job["job_id"], job["hob_id"], job["program_count"]) for job in gear["jobs"]] == \
        [(job_id, "H-M2-AA-R1", 0)]
    text = run("gears", "show", 91001)
    assert text.exit_code == 0 and "C45" in text.stdout and "H-M2-AA-R1" in text.stdout


# --- jobs -------------------------------------------------------------------------------------------------

def test_jobs_list_and_its_filters(run):
    store_gears(run.url)
    first, second = store_job(run.url, 91001, "2020-05-05"), store_job(run.url, 91002, "2020-06-06", "helical")
    assert [job["job_id"] for job in listed(run, "jobs", "list", "--until", "2020-12-31")] == [first, second]
    by_gear = listed(run, "jobs", "list", "--gear", 91002)
    assert [(job["job_id"], job["gear_id"], job["class"], job["machine"]) for job in by_gear] == \
        [(second, 91002, "helical", "hobber-840d")]
    assert [job["job_id"] for job in listed(run, "jobs", "list", "--class", "spur", "--until", "2020-12-31")] == \
        [first]
    assert [job["job_id"] for job in listed(run, "jobs", "list", "--since", "2020-06-01", "--until", "2020-06-06")] \
        == [second]
    rows = list(csv.DictReader(io.StringIO(run("jobs", "list", "--gear", 91001, "--csv").stdout)))
    assert [(row["job_id"], row["gear_id"], row["class"]) for row in rows] == [(str(first), "91001", "spur")]


def test_jobs_show_gives_the_parameters_and_the_programs(run):
    made = json.loads(run("instantiate", "--gear", 42, "--json").stdout)
    result = run("jobs", "show", made["job_id"], "--json")
    assert result.exit_code == 0 and result.stdout.count("\n") == 1
    job = json.loads(result.stdout)["job"]
    assert (job["job_id"], job["gear_id"], job["class"]) == (made["job_id"], 42, "spur")
    assert job["params"]["program_name"] == made["name"] and job["params"]["z2"] == 19
    assert [(p["program_id"], p["template_version"], p["draft"]) for p in job["programs"]] == \
        [(made["program_id"], made["template_version"], False)]
    text = run("jobs", "show", made["job_id"])
    assert text.exit_code == 0 and made["name"] in text.stdout


# --- programs ---------------------------------------------------------------------------------------------

@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_programs_list_filters_by_gear_job_class_and_release(run):
    made = json.loads(run("instantiate", "--gear", 42, "--json").stdout)
    other = json.loads(run("instantiate", "--gear", 43, "--json").stdout)
    for filters, expected in ((("--gear", 42), [made]), (("--job", other["job_id"]), [other]),
                              (("--class", "helical"), [other]), (("--released",), [made, other]),
                              (("--draft",), []), (("--until", "2020-12-31"), [])):
        found = listed(run, "programs", "list", *filters)
        assert [p["program_id"] for p in found] == [m["program_id"] for m in expected], filters
    record = listed(run, "programs", "list", "--gear", 42)[0]
    assert (record["job_id"], record["gear_id"], record["class"], record["name"], record["line_count"]) == \
        (made["job_id"], 42, "spur", made["name"], made["lines"])
    rows = list(csv.DictReader(io.StringIO(run("programs", "list", "--job", made["job_id"], "--csv").stdout)))
    assert [(row["program_id"], row["draft"]) for row in rows] == [(str(made["program_id"]), "False")]


def test_programs_show_prints_the_record_and_the_stored_text(run):
    made = json.loads(run("instantiate", "--gear", 42, "--json").stdout)
    with psycopg.connect(run.url) as conn:
        lines = conn.execute("SELECT lines FROM program WHERE id = %s", (made["program_id"],)).fetchone()[0]
    text = run("programs", "show", made["program_id"])
    assert text.exit_code == 0
    assert text.stdout.splitlines()[-len(lines):] == lines
    assert "job:" in text.stdout and "spur" in text.stdout and "(released)" in text.stdout


# --- hobs -------------------------------------------------------------------------------------------------

def test_hobs_show_and_csv(run):
    execute(run.url, "INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class, tool_number) "
                     "VALUES ('H-LIST-1', 4.5, 2, 90, 140, 'L', 'B', 7)")
    job_id = store_job(run.url, 42, "2020-05-05", hob_id="H-LIST-1")
    result = run("hobs", "show", "h-list-1", "--json")
    assert result.exit_code == 0 and result.stdout.count("\n") == 1
    hob = json.loads(result.stdout)["hob"]
    assert (hob["hob_id"], hob["module"], hob["starts"], hob["hand"], hob["tool_number"]) == \
        ("H-LIST-1", 4.5, 2, "L", 7)
    assert [job["job_id"] for job in hob["jobs"]] == [job_id]
    rows = {row["id"]: row for row in csv.DictReader(io.StringIO(run("hobs", "list", "--csv").stdout))}
    assert (rows["H-LIST-1"]["module"], rows["H-LIST-1"]["accuracy_class"]) == ("4.5", "B")


def test_cases_and_classes_lists_take_json_and_csv(read_only_run):
    cases = listed(read_only_run, "cases", "list")
    rows = list(csv.DictReader(io.StringIO(read_only_run("cases", "list", "--csv").stdout)))
    assert [int(row["id"]) for row in rows] == [case["case_id"] for case in cases] and cases   # as import reads
    with psycopg.connect(read_only_run.url) as conn:
        names = [name for (name,) in conn.execute("SELECT name FROM gear_class ORDER BY name")]
    assert [record["class"] for record in listed(read_only_run, "template", "list")] == names
    rows = list(csv.DictReader(io.StringIO(read_only_run("template", "list", "--csv").stdout)))
    assert [row["class"] for row in rows] == names


# --- delete -----------------------------------------------------------------------------------------------

def snapshot(url) -> dict:
    return {table: rows_of(url, table) for table in ("gear", "gear_unit", "job", "hob", "program")}


def test_delete_without_yes_says_what_and_deletes_nothing(run):
    store_gears(run.url)
    before = snapshot(run.url)
    refused(run("gears", "delete", 91003), "would delete gear 91003", "--yes")
    refused(run("hobs", "delete", "H-M2-A-L1"), "would delete hob H-M2-A-L1", "--yes")
    assert snapshot(run.url) == before


def test_a_referenced_row_is_refused_naming_what_refers_to_it(run):
    store_gears(run.url)
    store_job(run.url, 91001, "2020-05-05", hob_id="H-M2-A-L1")
    made = json.loads(run("instantiate", "--gear", 42, "--json").stdout)
    before = snapshot(run.url)
    refused(run("gears", "delete", 91001, "--yes"), "gear 91001 has 1 job")
    refused(run("hobs", "delete", "H-M2-A-L1", "--yes"), "hob H-M2-A-L1 has 1 job")
    refused(run("jobs", "delete", made["job_id"], "--yes"), f"job {made['job_id']} has 1 program")
    refused(run("gears", "delete", 42, "--yes"), "gear 42 has", "golden test")
    assert snapshot(run.url) == before


def test_delete_with_yes_removes_the_row_and_only_it(run):
    store_gears(run.url)
    execute(run.url, "INSERT INTO gear_unit (gear_id, unit, teeth, face_width, z_top) VALUES (91003, 2, 17, 8, -20)")
    job_id = store_job(run.url, 91002, "2020-05-05", "helical")
    before = snapshot(run.url)
    for args, words in (((("gears", "delete", 91003, "--yes")), "deleted gear 91003"),
                        ((("jobs", "delete", job_id, "--yes")), f"deleted job {job_id}"),
                        ((("hobs", "delete", "h-m2-a-l1", "--yes")), "deleted hob H-M2-A-L1")):
        result = run(*args)
        assert result.exit_code == 0 and words in result.stdout, result.output
    after = snapshot(run.url)
    assert after["gear"] == [row for row in before["gear"] if row[0] != 91003]
    assert after["gear_unit"] == [row for row in before["gear_unit"] if row[0] != 91003]
    assert after["job"] == [row for row in before["job"] if row[0] != job_id]
    assert after["hob"] == [row for row in before["hob"] if row[0] != "H-M2-A-L1"]
    assert ours(listed(run, "gears", "list")).keys() == {91001, 91002}


# --- bad input --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("args, words", [
    (("gears", "show", 999999), ["gear 999999 does not exist"]),
    (("jobs", "show", 999999), ["job 999999 does not exist"]),
    (("hobs", "show", "H-NONE"), ["hob H-NONE does not exist"]),
    (("programs", "show", 999999), ["program 999999 does not exist"]),
    (("gears", "delete", 999999, "--yes"), ["gear 999999 does not exist"]),
    (("jobs", "delete", 999999), ["job 999999 does not exist"]),
    (("hobs", "delete", "H-NONE", "--yes"), ["hob H-NONE does not exist"]),
    (("gears", "list", "--since", "2020-02-30"), ["--since", "2020-02-30"]),
    (("jobs", "list", "--until", "yesterday"), ["--until", "yesterday"]),
    (("programs", "list", "--since", "2020-05-01", "--until", "2020-04-01"), ["--since 2020-05-01 is after"]),
    (("gears", "list", "--class", "no_such_class"), ["class 'no_such_class' does not exist"]),
])
def test_bad_input_is_one_line_and_exit_1(run, args, words):
    refused(run(*args), *words)


def test_json_and_csv_together_are_refused_as_one_json_line(read_only_run):
    """Given --json, the refusal itself is the JSON error line (issue 16: errors in --json mode)."""
    result = read_only_run("jobs", "list", "--json", "--csv")
    assert result.exit_code == 1 and result.stdout == ""
    assert result.stderr.count("\n") == 1
    error = json.loads(result.stderr)
    assert error["exit"] == 1 and "--json and --csv" in error["error"]


NEW_COMMANDS = (("gears", "list"), ("gears", "show"), ("gears", "delete"), ("jobs", "list"), ("jobs", "show"),
                ("jobs", "delete"), ("programs", "list"), ("programs", "show"), ("hobs", "list"), ("hobs", "show"),
                ("hobs", "delete"), ("cases", "list"), ("template", "list"))


@pytest.mark.parametrize("command", NEW_COMMANDS, ids=" ".join)
def test_every_list_and_show_command_gives_an_example(command):
    from click.testing import CliRunner

    from engine.cli.app import main

    result = CliRunner().invoke(main, [*command, "--help"])
    assert result.exit_code == 0
    assert any(line.strip().startswith(f"Example: engine {command[0]} ") for line in result.stdout.splitlines())


def test_migrations_and_shared_rows_list_as_json_and_csv(read_only_run):
    """db status and template shared are lists too: one JSON line, or CSV with a header."""
    migrations = listed(read_only_run, "db", "status")
    names = sorted(path.name for path in (Path(__file__).resolve().parent.parent / "migrations").glob("*.sql"))
    assert [record["migration"] for record in migrations] == names
    assert {record["state"] for record in migrations} == {"applied"}
    rows = listed(read_only_run, "template", "shared", "--class", "helical")
    assert rows and all(record["class"] == "helical" for record in rows)
    assert any("spur" in record["shared_with"] for record in rows)   # the refactor stores common lines once
    table = list(csv.DictReader(io.StringIO(read_only_run("template", "shared", "--class", "helical", "--csv").stdout)))
    assert [int(record["row_id"]) for record in table] == [record["row_id"] for record in rows]
    assert [record["shared_with"] for record in table] == [" ".join(record["shared_with"]) for record in rows]


def test_a_reader_that_leaves_early_gets_no_error_message(read_only_run):
    """`engine gears list | head`: the pipe closes before the list is written; the command ends
    quietly (exit 1, as Python's own tools do on EPIPE), not with 'unexpected error', exit 2."""
    command = [sys.executable, "-m", "engine", "--database-url", read_only_run.url, "db", "status"]
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    child.stdout.close()   # the reader is gone before the engine writes
    stderr = child.stderr.read().decode()
    assert child.wait(timeout=120) == 1
    assert stderr == ""
