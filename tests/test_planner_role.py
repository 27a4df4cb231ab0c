"""The planner role (issue 31, docs/design.md §10): a login person in engine_planner imports gears,
units, hobs, cases, work-holdings, machines and materials, each through the engine's own import,
new records and the file `list --csv` wrote taken back; the same person may not edit or release a
template, and a runner may not import: each refusal is one line naming the role that may, exit 1,
nothing stored."""
from __future__ import annotations

import csv
import io

import psycopg
import pytest
from helpers.class_jobs import ok, refused
from helpers.roles import logins

# (kind, table, its list as CSV, its import, the key column, the new records' keys)
KINDS = [
    ("gears", "gear", ("gears", "list", "--csv"), ("gears", "import", "--replace"), "gear_id", ("9001",)),
    ("units", "gear_unit", ("gears", "list", "--units", "--csv"), ("gears", "units"), "gear_id", ()),
    ("hobs", "hob", ("hobs", "list", "--csv"), ("hobs", "import", "--replace"), "id", ("PLAN-HOB-1",)),
    ("cases", "cutting_case", ("cases", "list", "--csv"), ("cases", "import", "--replace"), "id", ("", "900001")),
    ("work-holdings", "work_holding", ("fixtures", "list", "--csv"), ("fixtures", "import", "--replace"), "id",
     ("PLAN-ARBOR-1",)),
    ("machines", "machine", ("machines", "list", "--csv"), ("machines", "import", "--replace"), "name",
     ("plan-machine-1",)),
    ("materials", "material", ("materials", "list", "--csv"), ("materials", "import", "--replace"), "name",
     ("PlanSteel1",)),
]


@pytest.fixture
def login_in(server_url):
    with logins(server_url) as create:
        yield create


def as_login(run, login):
    """The CLI as that login person (its own URL, not the owner's)."""
    return lambda *args: run("--database-url", login.url(run.url), *args, url=False)


def exported(run, listing, tmp_path, key, new_keys) -> str:
    """The file the list writes (as the owner), with a copy of its first record under each of
    `new_keys` (a case without an id draws one from the sequence; 900001 moves it past)."""
    rows = list(csv.DictReader(io.StringIO(ok(run(*listing)).stdout)))
    assert rows, listing
    rows += [{**rows[0], key: new_key} for new_key in new_keys]
    path = tmp_path / f"{listing[0]}.csv"
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return str(path)


def table(url, name) -> list[tuple]:
    with psycopg.connect(url) as conn:
        return sorted(map(repr, conn.execute(f"SELECT * FROM {name}").fetchall()))   # noqa: S608 (a test's table name)


@pytest.mark.parametrize("kind, name, listing, importing, key, new_keys", KINDS, ids=[kind[0] for kind in KINDS])
def test_a_planner_imports_each_kind(run, login_in, tmp_path, kind, name, listing, importing, key, new_keys):
    path = exported(run, listing, tmp_path, key, new_keys)
    before = table(run.url, name)
    ok(as_login(run, login_in("engine_planner"))(*importing, path))
    after = table(run.url, name)
    assert len(after) == len(before) + len(new_keys)
    assert set(before) <= set(after)   # the rows exported came back unchanged


@pytest.mark.parametrize("kind, name, listing, importing, key, new_keys", KINDS, ids=[kind[0] for kind in KINDS])
def test_a_runner_importing_is_told_to_ask_for_engine_planner(run, login_in, tmp_path, kind, name, listing,
                                                               importing, key, new_keys):
    path = exported(run, listing, tmp_path, key, new_keys)
    before = table(run.url, name)
    message = refused(as_login(run, login_in("engine_runner"))(*importing, path))
    assert "refused this for your role" in message and "engine_planner imports gears" in message
    assert table(run.url, name) == before


def test_a_planner_editing_a_template_is_told_to_ask_for_engine_editor(run, login_in, tmp_path):
    path = tmp_path / "spur.csv"
    ok(run("template", "export", "--class", "spur", "--out", path))
    before = table(run.url, "template_version_rows")
    message = refused(as_login(run, login_in("engine_planner"))("template", "import", "--class", "spur", path))
    assert "engine_editor edits templates" in message and "engine_planner" not in message
    assert table(run.url, "template_version_rows") == before


DRAFT = """UPDATE template_view SET o = o || ' ' WHERE gear_class = 'spur'
           AND id = (SELECT min(id) FROM template_view WHERE gear_class = 'spur' AND o <> '')"""


def test_a_planner_releasing_a_template_is_told_it_needs_engine_releaser(run, login_in):
    with psycopg.connect(run.url) as conn:   # the owner makes a draft of spur
        conn.execute(DRAFT)
    before = table(run.url, "template_release")
    message = refused(as_login(run, login_in("engine_planner"))("template", "release", "--class", "spur", "--yes"))
    assert "needs the role engine_releaser" in message
    assert table(run.url, "template_release") == before


def test_a_planner_may_not_make_a_program(run, login_in):
    before = table(run.url, "job")
    message = refused(as_login(run, login_in("engine_planner"))("instantiate", "--gear", 42))
    assert "engine_runner makes programs" in message
    assert table(run.url, "job") == before


def test_a_planner_deletes_a_gear_and_a_hob_it_imported(run, login_in, tmp_path):
    planner = as_login(run, login_in("engine_planner"))
    for listing, importing, key, new_key in ((("gears", "list", "--csv"), ("gears", "import"), "gear_id", "9002"),
                                            (("hobs", "list", "--csv"), ("hobs", "import"), "id", "PLAN-HOB-2")):
        rows = list(csv.DictReader(io.StringIO(ok(run(*listing)).stdout)))
        path = tmp_path / f"{listing[0]}-new.csv"
        with path.open("w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerow({**rows[0], key: new_key})
        ok(planner(*importing, path))
    ok(planner("gears", "delete", "9002", "--yes"))
    ok(planner("hobs", "delete", "PLAN-HOB-2", "--yes"))
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT count(*) FROM gear WHERE id = 9002").fetchone()[0] == 0
        assert conn.execute("SELECT count(*) FROM hob WHERE id = 'PLAN-HOB-2'").fetchone()[0] == 0


@pytest.mark.parametrize("statement", [
    "UPDATE cutting_case SET job_id = NULL",                 # which job a case records: the database's own
    "UPDATE cutting_case SET created_at = now()",
    "DELETE FROM cutting_case",
    "UPDATE template_view SET o = '\"X\"' WHERE gear_class = 'spur' AND id = 800",
    "UPDATE gear_class SET description = 'x'",
    "UPDATE job SET params = '{}'",
    "DELETE FROM template_release",
])
def test_a_planner_may_not_write_what_is_not_the_shops_data(conn, statement):
    from helpers.roles import as_role

    with pytest.raises(psycopg.errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_planner"):
        conn.execute(statement)
    assert conn.execute("SELECT current_user").fetchone()[0] != "engine_planner"
