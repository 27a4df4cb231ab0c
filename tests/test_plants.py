"""Several plants, one template authority (issue 33; docs/design.md §12): two PostgreSQL servers,
a head office and plant 7, each an embedded server of its own with wal_level = logical (the local
test server runs with replica, and only a restart changes that), set up only through the engine's
commands (`engine db start --wal-level logical`, `engine plant publish`, `engine plant subscribe`).

What a user relies on: a release at the head office reaches the plant; a draft never does;
retiring a version does not delete it at the plant; a program made at the plant while the head
office is down carries its lineage and reaches the head office's history when it is back; the ids
two databases make never collide; a plant refuses drafts and releases in one line. Every wait is
for a state PostgreSQL reports (a slot's confirmed position, a row arriving), bounded so a broken
setup fails instead of hanging; no duration is asserted. The servers, their subscriptions and
slots are removed afterwards."""
from __future__ import annotations

import json

import psycopg
import pytest
from helpers.plant_servers import (
    FIRST_ID,
    HISTORY_SLOT,
    LAST_ID,
    LOOPBACK,
    PLANT,
    TEMPLATES_SLOT,
    caught_up,
    edit_spur,
    engine,
    instantiate,
    new_database,
    ok,
    program_lines,
    released,
    rows,
    start,
    versions,
    wait_until,
)


@pytest.mark.slow
def test_a_release_reaches_the_plant_a_draft_never_and_retiring_deletes_nothing(group):
    head, plant = group.head_url, group.plant_url
    caught_up(head, TEMPLATES_SLOT)
    assert rows(plant, "SELECT gear_class, version, hash FROM template_release ORDER BY 1, 2") == \
        rows(head, "SELECT gear_class, version, hash FROM template_release ORDER BY 1, 2")

    draft = edit_spur(head, "REVISION A")
    caught_up(head, TEMPLATES_SLOT)
    assert draft in versions(head, "spur") and draft not in versions(plant, "spur")

    ok(engine(group.head, "template", "release", "--class", "spur", "--yes", "--without-golden-tests", url=head))
    caught_up(head, TEMPLATES_SLOT)
    assert released(plant, "spur") == released(head, "spur") == (draft, released(head, "spur")[1])
    program = instantiate(group.plant, plant)
    assert "; REVISION A" in program_lines(plant, program["program_id"])

    retiring = edit_spur(head, "REVISION B")
    caught_up(plant, HISTORY_SLOT)   # the plant's job is in the head office's job table now
    own_jobs = rows(head, "SELECT count(*) FROM job WHERE gear_class = 'spur' AND id < %s", (10**10,))[0][0]
    report = json.loads(ok(engine(group.head, "template", "release", "--class", "spur", "--yes", "--json",
                                  "--without-golden-tests", url=head)))
    # the gate makes again the head office's own jobs only: a plant's are proved at the plant, on its gears
    assert rows(head, "SELECT count(*) FROM job WHERE id = %s", (program["job_id"],)) == [(1,)]
    assert report["impact"]["jobs"] == own_jobs
    caught_up(head, TEMPLATES_SLOT)
    assert rows(plant, "SELECT version, state FROM template_version_state WHERE gear_class = 'spur' "
                       "AND version IN (%s, %s) ORDER BY version", (draft, retiring)) == \
        [(draft, "retired"), (retiring, "released")]
    assert rows(plant, "SELECT count(*) FROM program WHERE id = %s", (program["program_id"],)) == [(1,)]


@pytest.mark.slow
def test_a_program_made_while_the_head_office_is_down_reaches_it_with_its_lineage(group):
    version, template_hash = released(group.head_url, "spur")
    caught_up(group.head_url, TEMPLATES_SLOT)
    ok(engine(group.head, "db", "stop"))
    try:
        program = instantiate(group.plant, group.plant_url)
        status = ok(engine(group.plant, "plant", "status", url=group.plant_url))
    finally:
        start(group.head)
    program_id = program["program_id"]
    assert FIRST_ID <= program_id <= LAST_ID
    lines = program_lines(group.plant_url, program_id)
    lineage = [line for line in lines if line.startswith("; PROGRAM ")]
    assert lineage and lineage[0].startswith(f"; PROGRAM {program_id} TEMPLATE spur v{version} {template_hash[:8]} ")
    assert f"warning: slot {HISTORY_SLOT} is inactive" in status
    arrived = wait_until(lambda: rows(group.head_url, "SELECT lines, draft FROM program WHERE id = %s", (program_id,)),
                         "the plant's program reaches the head office")
    assert arrived == [(lines, False)]


@pytest.mark.slow
def test_plant_ids_never_collide(group):
    at_head, at_plant = instantiate(group.head, group.head_url), instantiate(group.plant, group.plant_url)
    assert 1 <= at_head["program_id"] < 10**10 and FIRST_ID <= at_plant["program_id"] <= LAST_ID
    caught_up(group.plant_url, HISTORY_SLOT)
    assert rows(group.head_url, "SELECT count(*) FROM program WHERE id IN (%s, %s)",
                (at_head["program_id"], at_plant["program_id"])) == [(2,)]
    with pytest.raises(psycopg.errors.CheckViolation, match=f"plant {PLANT} makes ids {FIRST_ID} to {LAST_ID}"):
        rows(group.plant_url, "INSERT INTO drawing (id, file_name, profile) VALUES (5, 'x.dxf', '[]')")
    second = new_database(group.plant.url, "plant")
    ok(engine(group.plant, "db", "migrate", url=second))
    taken = engine(group.plant, "plant", "subscribe", "--head", group.head_url, "--number", PLANT, url=second)
    assert taken.exit_code == 1 and taken.stderr.count("\n") == 1
    assert f"the head office has a plant {PLANT} already" in taken.stderr


@pytest.mark.slow
def test_subscribing_again_changes_nothing_and_a_plant_keeps_its_number(group):
    slots = "SELECT slot_name FROM pg_replication_slots ORDER BY 1"
    before = rows(group.head.url, slots), rows(group.plant.url, slots)
    again = ok(engine(group.plant, "plant", "subscribe", "--head", group.head_url, "--number", PLANT,
                      url=group.plant_url))
    assert again.startswith(f"plant {PLANT}: ids {FIRST_ID} to {LAST_ID};")
    assert (rows(group.head.url, slots), rows(group.plant.url, slots)) == before
    other = engine(group.plant, "plant", "subscribe", "--head", group.head_url, "--number", PLANT + 1,
                   url=group.plant_url)
    assert other.exit_code == 1 and f"this database is plant {PLANT}, not {PLANT + 1}" in other.stderr


@pytest.mark.slow
def test_a_plant_refuses_drafts_and_releases_in_one_line(group, tmp_path):
    release = engine(group.plant, "template", "release", "--class", "spur", "--yes", url=group.plant_url)
    assert release.exit_code == 1 and release.stderr.count("\n") == 1
    assert f"this database is plant {PLANT}" in release.stderr and "head office" in release.stderr
    csv = tmp_path / "spur.csv"
    csv.write_text(ok(engine(group.head, "template", "export", "--class", "spur", url=group.head_url)))
    imported = engine(group.plant, "template", "import", "--class", "spur", csv, url=group.plant_url)
    assert imported.exit_code == 1 and imported.stderr.count("\n") == 1
    assert "is the head office's" in imported.stderr
    with pytest.raises(psycopg.errors.ReadOnlySqlTransaction):
        rows(group.plant_url, "UPDATE machine SET name = name")


@pytest.mark.slow
def test_at_a_plant_the_proof_the_simulation_and_the_web_view_work_unchanged(group):
    from starlette.testclient import TestClient

    from engine.service.web.app import create_app

    program_id = instantiate(group.plant, group.plant_url)["program_id"]
    shown = json.loads(ok(engine(group.plant, "programs", "show", program_id, "--json", url=group.plant_url)))
    assert shown["programs"][0]["rendering"]["status"] == "MATCH"   # rendered again from the received version, proved
    ok(engine(group.plant, "simulate", "--program", program_id, url=group.plant_url))
    with TestClient(create_app(group.plant_url), base_url=LOOPBACK) as client:
        page = client.get(f"/programs/{program_id}", headers={"Accept": "application/json"})
    assert page.status_code == 200 and page.json() == shown


@pytest.mark.slow
def test_at_a_plant_the_delivery_sends_and_records_and_the_head_office_sees_it(group):
    from engine.programs.config import Config
    from engine.service.delivery import deliver

    job_id = instantiate(group.plant, group.plant_url)["job_id"]
    with psycopg.connect(group.plant_url, autocommit=True) as conn:
        sent = deliver(conn, "hobber-840d", f"JOB {job_id}", via="web", client="test", config=Config())
    assert sent.job_id == job_id and FIRST_ID <= sent.program_id <= LAST_ID
    request = rows(group.plant_url, "SELECT id, program_id FROM program_request WHERE job_id = %s", (job_id,))
    assert len(request) == 1 and FIRST_ID <= request[0][0] <= LAST_ID
    caught_up(group.plant_url, HISTORY_SLOT)
    assert rows(group.head_url, "SELECT id, program_id FROM program_request WHERE job_id = %s", (job_id,)) == request


@pytest.mark.slow
def test_status_as_text_and_json(group):
    head = json.loads(ok(engine(group.head, "plant", "status", "--json", url=group.head_url)))
    plant = json.loads(ok(engine(group.plant, "plant", "status", "--json", url=group.plant_url)))
    assert (head["role"], plant["role"], plant["number"]) == ("head office", f"plant {PLANT}", PLANT)
    assert {"template_version_rows": "released"}.items() <= \
        {t["table"]: t["row_filter"] for t in head["published"]}.items()
    assert [s["name"] for s in plant["subscriptions"]] == [TEMPLATES_SLOT]
    assert [s["name"] for s in head["subscriptions"]] == [HISTORY_SLOT]
    assert [s["name"] for s in head["slots"]] == [TEMPLATES_SLOT]
    assert all(isinstance(s["retained_bytes"], int) for s in head["slots"] + plant["slots"])
    text = ok(engine(group.plant, "plant", "status", url=group.plant_url))
    assert text.startswith(f"plant {PLANT}; wal_level logical") and f"receives {TEMPLATES_SLOT}" in text


def test_a_single_database_is_neither_head_office_nor_plant(read_only_run):
    status = json.loads(ok(read_only_run("plant", "status", "--json")))
    assert (status["role"], status["number"], status["subscriptions"], status["warnings"]) == \
        ("single (no replication)", 0, [], [])


def test_publishing_needs_wal_level_logical(read_only_run):
    level = rows(read_only_run.url, "SHOW wal_level")[0][0]
    if level == "logical":
        pytest.skip("the test server runs with wal_level = logical")
    refused = read_only_run("plant", "publish")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert f"wal_level is {level}, a publisher needs logical" in refused.stderr


def test_db_start_is_the_embedded_servers_only(read_only_run):
    refused = read_only_run("db", "start", "--wal-level", "logical")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert "name another server" in refused.stderr
