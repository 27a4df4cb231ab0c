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


def test_the_json_list_holds_every_machine_with_its_dialect_and_limits(read_only_run):
    listed = json.loads(ok(read_only_run("machines", "list", "--json")).stdout)["machines"]
    assert [(m["name"], m["kind"], m["dialect"], m["spindle_max"]) for m in listed] == seeded(read_only_run.url)
    fanuc = next(m for m in listed if m["name"] == "lathe-fanuc-0t")
    assert (fanuc["gcode_system"], fanuc["decimal_point_input"]) == ("A", "calculator")


def test_the_csv_list_has_a_header_of_keys_and_one_line_per_machine(read_only_run):
    rows = list(csv.DictReader(io.StringIO(ok(read_only_run("machines", "list", "--csv")).stdout)))
    expected = [(name, dialect) for name, _, dialect, _ in seeded(read_only_run.url)]
    assert [(row["name"], row["dialect"]) for row in rows] == expected


def test_the_table_names_each_machine_and_counts_them_on_stderr(read_only_run):
    result = ok(read_only_run("machines", "list"))
    names = [name for name, *_ in seeded(read_only_run.url)]
    assert all(name in result.stdout for name in names)
    assert result.stderr.strip() == f"{len(names)} machines"


def test_the_table_says_which_machines_print_floor_to_floor(run, tmp_path):
    """A hobber stating every floor-to-floor time says yes, one stating some names the missing
    ones (also at its import), a lathe says -: the table shows what --json gives field by field."""
    from engine.machines.records import FLOOR_TIMES

    listed = json.loads(ok(run("machines", "list", "--json")).stdout)["machines"]
    hobber = next(m for m in listed if m["kind"] == "hobber")
    rows = list(csv.DictReader(io.StringIO(ok(run("machines", "list", "--csv")).stdout)))
    row = next(r for r in rows if r["name"] == hobber["name"])
    full = {**row, "name": "shop-full", **{name: "1" for name in FLOOR_TIMES}}
    partial = {**full, "name": "shop-partial", "door_time": "", "tool_change_time": ""}
    path = tmp_path / "machines.csv"
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(row))
        writer.writeheader()
        writer.writerows([full, partial])
    imported = ok(run("machines", "import", str(path)))
    assert "note: machine shop-partial" in imported.stderr and "door_time, tool_change_time" in imported.stderr
    assert "shop-full" not in imported.stderr
    table = ok(run("machines", "list")).stdout.splitlines()
    assert "floor-to-floor" in table[0]
    line = {name: next(line for line in table if line.startswith(name + " ")) for name in ("shop-full", "shop-partial")}
    assert line["shop-full"].rstrip().endswith(" yes")
    assert line["shop-partial"].rstrip().endswith("missing door_time, tool_change_time")
    lathe = next(m["name"] for m in listed if m["kind"] == "lathe")
    assert next(line for line in table if line.startswith(lathe + " ")).rstrip().endswith(" -")


def test_the_import_help_names_every_required_column(read_only_run):
    from engine.machines.importing import REQUIRED

    text = " ".join(ok(read_only_run("machines", "import", "--help")).stdout.split())
    assert all(column in text for column in REQUIRED), text
