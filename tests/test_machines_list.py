"""`engine machines list` (issue 27's new-user review: there was no way to see which machines
exist and which dialect each runs, but an error message): every record of the seeded database,
as a table, --json with every field and --csv, the rows read back from the database itself."""
from __future__ import annotations

import csv
import io
import json

import psycopg
from helpers.class_jobs import ok


def seeded(url) -> list[tuple[str, str, str, float]]:
    with psycopg.connect(url) as conn:
        rows = conn.execute("SELECT name, kind, dialect, spindle_max FROM machine ORDER BY name").fetchall()
    return [(name, kind, dialect, float(spindle)) for name, kind, dialect, spindle in rows]


def test_the_json_list_holds_every_machine_with_its_dialect_and_limits(run):
    listed = json.loads(ok(run("machines", "list", "--json")).stdout)["machines"]
    assert [(m["name"], m["kind"], m["dialect"], m["spindle_max"]) for m in listed] == seeded(run.url)
    fanuc = next(m for m in listed if m["name"] == "lathe-fanuc-0t")
    assert (fanuc["gcode_system"], fanuc["decimal_point_input"]) == ("A", "calculator")


def test_the_csv_list_has_a_header_of_keys_and_one_line_per_machine(run):
    rows = list(csv.DictReader(io.StringIO(ok(run("machines", "list", "--csv")).stdout)))
    expected = [(name, dialect) for name, _, dialect, _ in seeded(run.url)]
    assert [(row["name"], row["dialect"]) for row in rows] == expected


def test_the_table_names_each_machine_and_counts_them_on_stderr(run):
    result = ok(run("machines", "list"))
    names = [name for name, *_ in seeded(run.url)]
    assert all(name in result.stdout for name in names)
    assert result.stderr.strip() == f"{len(names)} machines"
