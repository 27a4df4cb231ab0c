"""`engine machines import` (issue 27's new-user review: a shop's own lathe could be added only in
SQL): the CSV `engine machines list --csv` writes is what it reads, so every seeded machine exported
and imported under another name comes back field for field; a machine that exists, a kind and
dialect no grammar reads, a repeated name and a value the database refuses are one line each, exit
1, and nothing is stored."""
from __future__ import annotations

import json

import psycopg
import pytest
from helpers.class_jobs import ok, refused
from helpers.machine_files import exported, machines, written


def test_every_machine_exported_and_imported_under_a_new_name_comes_back_field_for_field(run, tmp_path):
    before = machines(run.url)
    renamed = [{**row, "name": "shop-" + row["name"]} for row in exported(run)]
    result = ok(run("machines", "import", written(tmp_path, renamed), "--json"))
    assert json.loads(result.stdout) == {"added": [row["name"] for row in renamed], "replaced": [], "changes": []}
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
    ("exists", [{**LATHE, "name": "lathe-fanuc-0t"}], "machine(s) lathe-fanuc-0t exist already"),
    ("exists in another case", [{**LATHE, "name": "Lathe-Fanuc-0T"}], "machine(s) lathe-fanuc-0t exist already"),
    ("no grammar", [{**LATHE, "dialect": "haas"}], "dialect 'haas', which no grammar of the verifier reads"),
    ("twice", [LATHE, LATHE], "machine 'new-lathe' is given twice"),
    ("twice in two cases", [LATHE, {**LATHE, "name": "NEW-lathe"}], "is given twice (names that differ only in case"),
    ("refused value", [{**LATHE, "spindle_max": "-1"}], "machine 'new-lathe': spindle_max must be above 0 (r/min)"),
    ("a choice misspelt", [{**LATHE, "decimal_point_input": "calculater"}],
     "machine 'new-lathe': decimal_point_input must be increment or calculator"),
    ("travel backwards", [{**LATHE, "x_min": "400"}], "machine 'new-lathe': x_min must be below x_max"),
    ("not a number", [{**LATHE, "x_max": "350,5"}], "line 3 column x_max: '350,5' is not a number"),
    ("no kind", [{**LATHE, "kind": ""}], "line 3 gives no kind"),
    ("no travel", [{**LATHE, "z_min": ""}], "line 3 gives no z_min"),
    ("power-on G90 on system A", [{**LATHE, "gcode_system": "A", "power_on": "G18 G40 G90 G97 G99"}],
     "power_on lists G90, which on G-code system A is the turning cycle"),
    ("power-on one group twice", [{**LATHE, "power_on": "G18 G98 G99"}], "power_on lists G98 and G99, one modal group"),
    ("helix sign not a sign", [{**LATHE, "egb_helix_sign": "2"}], "egb_helix_sign must be 1 or -1"),
    ("reference outside the travel", [{**LATHE, "reference_x": "420", "reference_z": "100"}],
     "reference_x 420 lies outside its travel (X 0…300)"),
]


@pytest.mark.parametrize("rows, words", [case[1:] for case in REFUSED], ids=[case[0] for case in REFUSED])
def test_a_bad_file_is_refused_in_one_line_and_nothing_is_stored(run, tmp_path, rows, words):
    before = machines(run.url)
    message = refused(run("machines", "import", written(tmp_path, [{**LATHE, "name": "good-lathe"}, *rows])))
    assert words in message and "machines.csv" in message, message
    assert machines(run.url) == before


def test_every_check_of_the_machine_table_is_said_in_the_words_of_its_columns(conn):
    """A value the table refuses is named by what its check asks (engine.machines.importing.CHECKS),
    not by the constraint's name: a check added to the table without its words fails here."""
    from engine.machines.importing import CHECKS

    names = {name for (name,) in conn.execute(
        "SELECT conname FROM pg_constraint WHERE conrelid = 'machine'::regclass AND contype = 'c'")}
    assert names == set(CHECKS)


def test_a_header_without_rows_is_refused(read_only_run, tmp_path):
    path = tmp_path / "machines.csv"
    path.write_text(",".join(LATHE) + "\n")
    assert "holds no machine" in refused(read_only_run("machines", "import", path))


def test_a_fanuc_hobbers_stated_helix_sign_is_stored_listed_and_loaded(run, tmp_path):
    """egb_helix_sign (migration 0037, fanuc-egb.md §F5): a column of the CSV like any other; the
    seeded records leave it empty (not stated), a shop's Fanuc hobber states it after its dry run."""
    from engine.machines.records import load_machine

    hobber = next(row for row in exported(run) if row["kind"] == "hobber")
    assert hobber["egb_helix_sign"] == ""
    ok(run("machines", "import", written(tmp_path, [{**hobber, "name": "shop-fanuc", "dialect": "fanuc",
                                                     "egb_helix_sign": "-1"}])))
    assert next(row for row in exported(run) if row["name"] == "shop-fanuc")["egb_helix_sign"] == "-1"
    listed = json.loads(ok(run("machines", "list", "--json")).stdout)["machines"]
    assert next(m for m in listed if m["name"] == "shop-fanuc")["egb_helix_sign"] == -1
    with psycopg.connect(run.url) as conn:
        assert load_machine(conn, "shop-fanuc").egb_helix_sign == -1
