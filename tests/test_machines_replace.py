"""`engine machines import --replace` and `engine machines show` (issue 31: every list exports what
its import reads): the machines `list --csv` writes come back unchanged by `import --replace`; a
machine no job was made on is replaced whole, each changed field said old → new; one a stored job
was made on is changed in no field (its programs were proved on it), one line, nothing stored."""
from __future__ import annotations

import json
from decimal import Decimal

import psycopg
from helpers.class_jobs import ok, refused
from helpers.machine_files import exported, machines, written


def test_the_exported_machines_imported_with_replace_are_unchanged(run, tmp_path):
    before = machines(run.url)
    result = ok(run("machines", "import", written(tmp_path, exported(run)), "--replace", "--json"))
    assert json.loads(result.stdout) == {"added": [], "replaced": [m["name"] for m in before], "changes": []}
    assert machines(run.url) == before


def test_a_machine_no_job_was_made_on_is_replaced_field_by_field(run, tmp_path):
    rows = exported(run)
    lathe = next(row for row in rows if row["kind"] == "lathe")
    old_spindle = Decimal(lathe["spindle_max"])
    new_spindle = old_spindle - 500   # r/min
    lathe["spindle_max"] = str(new_spindle)
    result = ok(run("machines", "import", written(tmp_path, [lathe]), "--replace"))
    assert f"machine {lathe['name']}: spindle_max {old_spindle.normalize():f} → {new_spindle.normalize():f}" \
        in result.stdout
    stored = next(m for m in machines(run.url) if m["name"] == lathe["name"])
    assert stored["spindle_max"] == new_spindle


def test_a_machine_a_stored_job_was_made_on_is_changed_in_no_field(run, tmp_path):
    ok(run("instantiate", "--gear", 42))
    before = machines(run.url)
    rows = exported(run)
    hobber = next(row for row in rows if row["name"] == "hobber-840d")
    hobber["z_max"] = str(Decimal(hobber["z_max"]) + 1)   # mm
    message = refused(run("machines", "import", written(tmp_path, [hobber]), "--replace"))
    assert "machine hobber-840d: the file changes its z_max" in message and "made on it" in message
    assert machines(run.url) == before


def test_without_replace_a_stored_machine_is_still_refused(run, tmp_path):
    before = machines(run.url)
    message = refused(run("machines", "import", written(tmp_path, exported(run)[:1])))
    assert "exist already" in message and "--replace" in message
    assert machines(run.url) == before


def test_show_gives_every_field_of_the_record_and_its_jobs(run):
    ok(run("instantiate", "--gear", 42))
    shown = json.loads(ok(run("machines", "show", "hobber-840d", "--json")).stdout)["machine"]
    stored = next(m for m in machines(run.url) if m["name"] == "hobber-840d")
    with psycopg.connect(run.url) as conn:
        jobs = conn.execute("SELECT count(*) FROM job WHERE machine = 'hobber-840d'").fetchone()[0]
    assert shown == {**{key: plain(value) for key, value in stored.items()}, "job_count": jobs}
    assert "z_max" in ok(run("machines", "show", "hobber-840d")).stdout


def test_show_of_an_unknown_machine_names_the_known_ones(read_only_run):
    message = refused(read_only_run("machines", "show", "no-such-machine"))
    assert "machine 'no-such-machine' does not exist" in message and "hobber-840d" in message


def plain(value):
    """A stored value as the JSON record gives it (a numeric as its number)."""
    if isinstance(value, Decimal):
        return int(value) if value == value.to_integral_value() else float(value)
    return value
