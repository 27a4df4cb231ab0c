"""`engine machines import` (issue 27's new-user review: a shop's own lathe could be added only in
SQL): the CSV `engine machines list --csv` writes is what it reads, so every seeded machine exported
and imported under another name comes back field for field; a machine that exists, a kind and
dialect no grammar reads, a repeated name and a value the database refuses are one line each, exit
1, and nothing is stored."""
from __future__ import annotations

import csv
import io
import json

import psycopg
import pytest
from helpers.class_jobs import ok, refused


def machines(url) -> list[dict]:
    with psycopg.connect(url) as conn:
        cursor = conn.execute("SELECT * FROM machine ORDER BY name")
        names = [column.name for column in cursor.description]
        return [dict(zip(names, row)) for row in cursor]


def exported(run) -> list[dict]:
    return list(csv.DictReader(io.StringIO(ok(run("machines", "list", "--csv")).stdout)))


def written(tmp_path, rows: list[dict]) -> str:
    path = tmp_path / "machines.csv"
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return str(path)


def test_every_machine_exported_and_imported_under_a_new_name_comes_back_field_for_field(run, tmp_path):
    before = machines(run.url)
    renamed = [{**row, "name": "shop-" + row["name"]} for row in exported(run)]
    result = ok(run("machines", "import", written(tmp_path, renamed), "--json"))
    assert json.loads(result.stdout) == {"added": [row["name"] for row in renamed]}
    after = {machine["name"]: machine for machine in machines(run.url)}
    for machine in before:
        assert after["shop-" + machine["name"]] == {**machine, "name": "shop-" + machine["name"]}


def test_a_lathe_given_by_its_required_columns_takes_the_defaults(run, tmp_path):
    lathe = {"name": "my-lathe", "kind": "lathe", "dialect": "iso", "x_min": "0", "x_max": "300", "z_min": "-500",
             "z_max": "200", "spindle_max": "4000", "gcode_system": "A", "decimal_point_input": "calculator",
             "power_on": "G18 G40 G97 G99"}
    assert "added 1 machine(s): my-lathe" in ok(run("machines", "import", written(tmp_path, [lathe]))).stdout
    stored = next(m for m in machines(run.url) if m["name"] == "my-lathe")
    assert (stored["y_min"], stored["y_max"], stored["work_offset"], stored["z_direction"]) == (0, 0, "G54", 1)
    assert (stored["power_on"], float(stored["spindle_max"])) == ("G18 G40 G97 G99", 4000.0)


LATHE = {"name": "new-lathe", "kind": "lathe", "dialect": "iso", "x_min": "0", "x_max": "300", "z_min": "-500",
         "z_max": "200", "spindle_max": "4000"}
REFUSED = [
    ("exists", [{**LATHE, "name": "lathe-fanuc-0t"}], "machine 'lathe-fanuc-0t' exists"),
    ("no grammar", [{**LATHE, "dialect": "haas"}], "dialect 'haas', which no grammar of the verifier reads"),
    ("twice", [LATHE, LATHE], "machine 'new-lathe' is given twice"),
    ("refused value", [{**LATHE, "spindle_max": "-1"}], "the database refused machine 'new-lathe' ("),
    ("not a number", [{**LATHE, "x_max": "lots"}], "the database refused machine 'new-lathe' ("),
    ("no kind", [{**LATHE, "kind": ""}], "line 3 gives no kind"),
]


@pytest.mark.parametrize("rows, words", [case[1:] for case in REFUSED], ids=[case[0] for case in REFUSED])
def test_a_bad_file_is_refused_in_one_line_and_nothing_is_stored(run, tmp_path, rows, words):
    before = machines(run.url)
    message = refused(run("machines", "import", written(tmp_path, [{**LATHE, "name": "good-lathe"}, *rows])))
    assert words in message and "machines.csv" in message, message
    assert machines(run.url) == before
