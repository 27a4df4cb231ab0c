"""Every screen says only what is true of a record, across plants (issue 33, the new user's review;
docs/design.md §12, docs/guide/plants.md).

At a head office a plant's job and program arrive as history: their gear, hob and machine records
are the plant's (gears are not replicated; gear 44 there is another gear than gear 44 here), so no
screen renders or proves them here: each shows the stored text and lineage, says where it was made
and that it was proved there, and a command that needs a proof here (plot, explain, simulate, cases
confirm, delivery, instantiate --job) refuses in one line naming the plant. At a plant, a release is
the head office's: its golden tests ran there and are never said to fail here.

The fast tests write a plant's job and program into a copy of the seeded database as the
replication's apply worker writes them (session_replication_role = replica: the row checks of a
local insert do not run); the slow ones take tests/test_plants.py's two servers, a head office and
plant 7, set up with the engine's own commands."""
from __future__ import annotations

import json
from html import unescape

import psycopg
import pytest
from helpers.plant_servers import (
    PLANT,
    caught_up,
    edit_spur,
    engine,
    instantiate,
    ok,
    rows,
)
from starlette.testclient import TestClient

from engine.programs.config import Config
from engine.service.delivery import deliver, machine_files
from engine.service.delivery_names import Refused
from engine.service.web.app import create_app

LOOPBACK = "http://127.0.0.1"
JSON = {"Accept": "application/json"}
AT = 3   # the plant the fast tests' job and program come from
PLANT_IDS = 10**10   # docs/design.md §12: plant N makes ids N·10^10 to (N+1)·10^10 - 1
NOT_RE_PROVED = (f"made at plant {AT}: proved there when it was made; not re-proved here "
                 "(its gear, hob and machine records are the plant's)")
# The apply worker's way (session_replication_role = replica): job and program of the head office's
# own, copied under plant 3's ids, the job's gear the plant's own gear id.
ARRIVED = """
SET session_replication_role = replica;
CREATE TEMP TABLE j AS SELECT * FROM job WHERE id = %(job)s;
UPDATE j SET id = %(new_job)s, gear_id = %(gear)s;
INSERT INTO job SELECT * FROM j;
CREATE TEMP TABLE p AS SELECT * FROM program WHERE id = %(program)s;
UPDATE p SET id = %(new_program)s, job_id = %(new_job)s,
             lines = ARRAY(SELECT replace(l, '; PROGRAM ' || %(program)s || ' ', '; PROGRAM ' || %(new_program)s || ' ')
                           FROM unnest(lines) WITH ORDINALITY u (l, o) ORDER BY o);
INSERT INTO program SELECT * FROM p;
RESET session_replication_role"""


def arrived(run, gear: int) -> tuple[int, int]:
    """A plant-3 job of gear `gear` (the plant's gear id) and its program, as replicated here: (job, program)."""
    made = json.loads(ok(run("instantiate", "--gear", 42, "--machine", "hobber-840d", "--json")))
    new_job, new_program = AT * PLANT_IDS + made["job_id"], AT * PLANT_IDS + made["program_id"]
    with psycopg.connect(run.url, autocommit=True) as conn:
        values = {"job": made["job_id"], "program": made["program_id"], "new_job": new_job,
                  "new_program": new_program, "gear": gear}
        for statement in ARRIVED.strip().split(";\n"):
            conn.execute(statement, {key: value for key, value in values.items() if f"%({key})s" in statement})
    return new_job, new_program


def refused(result, *words: str) -> str:
    assert result.exit_code == 1 and result.stderr.count("\n") == 1, result.output
    for word in words:
        assert word in result.stderr
    return result.stderr


# --- 1: a plant's program at the head office -----------------------------------------------------

@pytest.mark.parametrize("gear", [7001, 44], ids=["gear-not-here", "gear-id-of-another-gear-here"])
def test_a_plants_program_is_shown_with_its_text_and_where_it_was_proved(run, gear):
    _, program = arrived(run, gear)
    stored = rows(run.url, "SELECT lines FROM program WHERE id = %s", (program,))[0][0]
    shown = json.loads(ok(run("programs", "show", program, "--json")))["programs"][0]
    assert (shown["program_id"], shown["plant"], shown["lines"]) == (program, AT, stored)
    assert shown["rendering"] == {"status": "PLANT", "reason": NOT_RE_PROVED, "plant": AT}
    text = ok(run("programs", "show", program))
    assert f"rendering:     PLANT: {NOT_RE_PROVED}" in text and f"plant:         plant {AT}" in text
    assert f"gear:          {gear} (plant {AT}'s, not this database's)" in text
    assert "import it" not in text and "REFUSED" not in text and "MATCH" not in text
    assert text.endswith("\n".join(stored) + "\n")
    lineage = next(line for line in stored if line.startswith(f"; PROGRAM {program} TEMPLATE "))
    by_hash = json.loads(ok(run("programs", "show", "--hash", lineage.split()[6], "--json")))["programs"]
    assert {record["program_id"]: record["rendering"]["status"] for record in by_hash}[program] == "PLANT"


def test_commands_that_need_a_proof_here_refuse_a_plants_program_naming_the_plant(run, tmp_path):
    job, program = arrived(run, 44)
    where = f"was made at plant {AT}"
    refused(run("plot", "--program", program, "--out", tmp_path / "p.svg"), where, f"run it at plant {AT}")
    refused(run("plot", "--job", job, "--out", tmp_path / "j.svg"), where, "there")
    refused(run("explain", "--program", program), where, f"run it at plant {AT}")
    refused(run("simulate", "--program", program), where, f"run it at plant {AT}")
    refused(run("cases", "confirm", "--job", job), where, f"run it at plant {AT}")
    assert list(tmp_path.iterdir()) == []


def test_lists_say_the_plant_of_each_and_filter_by_it(run):
    job, program = arrived(run, 44)
    listed = json.loads(ok(run("programs", "list", "--check", "--json")))["programs"]
    plants = {record["program_id"]: (record["plant"], record["rendering"]) for record in listed}
    assert plants[program] == (AT, "PLANT") and {plant for plant, _ in plants.values()} == {0, AT}
    assert [p["program_id"] for p in json.loads(ok(run("programs", "list", "--plant", AT, "--json")))["programs"]] \
        == [program]
    # gear ids of plants collide: --gear names this database's gear unless --plant says whose
    assert program not in [p["program_id"] for p in
                           json.loads(ok(run("programs", "list", "--gear", 44, "--json")))["programs"]]
    assert [p["program_id"] for p in json.loads(ok(run("programs", "list", "--gear", 44, "--plant", AT,
                                                       "--json")))["programs"]] == [program]
    gear = json.loads(ok(run("gears", "show", 44, "--json")))["gear"]   # this database's gear 44: not the plant's
    assert job not in [j["job_id"] for j in gear["jobs"]] and gear["job_count"] == len(gear["jobs"])
    jobs = json.loads(ok(run("jobs", "list", "--plant", AT, "--json")))["jobs"]
    assert [(j["job_id"], j["plant"]) for j in jobs] == [(job, AT)]
    assert " plant " in ok(run("jobs", "list")).splitlines()[0]


def test_the_web_view_shows_a_plants_program_and_job_and_offers_no_sending(run):
    job, program = arrived(run, 7001)
    with TestClient(create_app(run.url), base_url=LOOPBACK + ":8080", follow_redirects=False) as client:
        page = client.get(f"/programs/{program}", headers=JSON)
        found = client.get("/lookup", params={"q": str(program)})
        html = unescape(client.get(f"/programs/{program}").text)
        job_page = unescape(client.get(f"/jobs/{job}").text)
        listed = client.get("/programs", params={"plant": AT}, headers=JSON)
        listed_page = client.get("/programs").text
        sent = client.post(f"/jobs/{job}/request", headers={"Origin": LOOPBACK + ":8080"})   # the page's own form
    assert page.status_code == 200 and page.json()["programs"][0]["rendering"]["status"] == "PLANT"
    assert found.status_code == 303 and found.headers["location"] == f"/programs/{program}"
    assert NOT_RE_PROVED in html and "gear 7001 does not exist" not in html
    assert "Make and send" not in job_page and f"Made at plant {AT}" in job_page
    assert 'href="/gears/7001"' not in job_page + listed_page   # the plant's gear, not one of this database's
    assert 'href="/gears/42"' in listed_page
    assert [p["program_id"] for p in listed.json()["programs"]] == [program]
    assert "Make and send" not in sent.text
    assert f"job {job} was made at plant {AT}: make and send it there" in unescape(sent.text)


# --- 2: a plant's job is made and sent at its plant -----------------------------------------------

def test_delivery_and_instantiate_refuse_a_plants_job_and_record_the_refusal(run):
    job, _ = arrived(run, 44)
    said = f"job {job} was made at plant {AT}: make and send it there"
    refused(run("instantiate", "--job", job), said)
    with psycopg.connect(run.url, autocommit=True) as conn:
        with pytest.raises(Refused, match=said):
            deliver(conn, "hobber-840d", f"JOB {job}", via="web", client="test", config=Config())
        assert job not in [listed.job_id for listed in machine_files(conn, "hobber-840d")]
    recorded = rows(run.url, "SELECT job_id, program_id, refusal FROM program_request ORDER BY id DESC LIMIT 1")
    assert recorded[0][:2] == (job, None) and recorded[0][2].startswith(said)
    with TestClient(create_app(run.url), base_url=LOOPBACK) as client:   # asked here: the head office's request
        machine = client.get("/machines/hobber-840d", headers=JSON).json()
    assert machine["requests"][0]["plant"] == 0 and machine["requests"][0]["job_id"] == job


def test_a_batch_of_jobs_makes_this_databases_own_and_names_a_plants_as_bad(run):
    job, _ = arrived(run, 44)
    programs = rows(run.url, "SELECT count(*) FROM program")[0][0]
    batch = run("instantiate", "--jobs", f"1-{job}", "--dry-run", "--skip-bad")
    assert batch.exit_code == 0, batch.output
    assert f"job {job} was made at plant {AT}: make and send it there" in batch.output
    assert rows(run.url, "SELECT count(*) FROM program")[0][0] == programs


# --- 4: the release impact names the plants' jobs it leaves out ------------------------------------

def test_the_impact_names_the_plants_jobs_it_does_not_make_again(run):
    arrived(run, 44)
    edit_spur(run.url, "A DRAFT")
    report = json.loads(ok(run("template", "release", "--class", "spur", "--dry-run", "--json")))
    assert report["impact"]["plants"] == [{"plant": AT, "jobs": 1}]
    said = (f"1 job(s) of plant(s) {AT} not re-made here (their gears are the plants'); each plant proves "
            "its programs when it makes or sends them")
    assert report["impact"]["plants_said"] == said   # a sentence of its own, not a clause's "and …"
    assert f"proved (machine verifier and simulation); and {said}" in ok(run("template", "release", "--class",
                                                                             "spur", "--dry-run"))


# --- 6: plant status, its lag and --check ---------------------------------------------------------

def test_status_check_exits_1_on_a_warning_and_0_without(run):
    assert ok(run("plant", "status", "--check")).startswith("single (no replication)")
    level = rows(run.url, "SHOW wal_level")[0][0]
    if level == "logical":
        pytest.skip("the test server runs with wal_level = logical: no warning to make here")
    with psycopg.connect(run.url, autocommit=True) as conn:   # published, but nothing is sent at this wal_level
        conn.execute("CREATE PUBLICATION engine_templates FOR TABLE machine")
    try:
        plain = run("plant", "status")
        checked = run("plant", "status", "--check")
    finally:
        with psycopg.connect(run.url, autocommit=True) as conn:
            conn.execute("DROP PUBLICATION engine_templates")
    assert plain.exit_code == 0 and f"warning: wal_level is {level}" in plain.stdout
    refused(checked, "engine plant status --check: 1 warning(s): wal_level is")
    assert checked.stdout == plain.stdout


# --- slow: two servers ----------------------------------------------------------------------------

@pytest.mark.slow
def test_at_the_head_office_a_plants_program_is_shown_never_proved(group):   # noqa: F811 (the fixture imported above)
    made = instantiate(group.plant, group.plant_url)
    caught_up(group.plant_url, f"engine_plant_{PLANT}_history")
    shown = json.loads(ok(engine(group.head, "programs", "show", made["program_id"], "--json",
                                 url=group.head_url)))["programs"][0]
    assert shown["rendering"]["status"] == "PLANT" and shown["plant"] == PLANT
    assert shown["lines"] == rows(group.plant_url, "SELECT lines FROM program WHERE id = %s",
                                  (made["program_id"],))[0][0]
    simulated = engine(group.head, "simulate", "--program", made["program_id"], url=group.head_url)
    refused(simulated, f"was made at plant {PLANT}", f"run it at plant {PLANT}")
    sent = engine(group.head, "instantiate", "--job", made["job_id"], url=group.head_url)
    refused(sent, f"job {made['job_id']} was made at plant {PLANT}: make and send it there")


@pytest.mark.slow
def test_status_names_the_lag_at_the_publisher_and_the_message_age_apart(group):   # noqa: F811
    caught_up(group.head_url, f"engine_plant_{PLANT}_templates")
    head = json.loads(ok(engine(group.head, "plant", "status", "--json", url=group.head_url)))
    plant = json.loads(ok(engine(group.plant, "plant", "status", "--json", url=group.plant_url)))
    slot = head["slots"][0]
    assert slot["name"] == f"engine_plant_{PLANT}_templates" and isinstance(slot["behind_bytes"], int)
    assert isinstance(slot["behind_seconds"], float) and "replay_lag_seconds" not in slot
    subscription = plant["subscriptions"][0]
    assert "lag_seconds" not in subscription and isinstance(subscription["message_age_seconds"], float)
    text = ok(engine(group.plant, "plant", "status", "--check", url=group.plant_url))   # healthy: exit 0
    assert "publisher's last message" in text and "its lag: engine plant status at the publisher" in text
    assert f"slot engine_plant_{PLANT}_history: active" in text and ", lag " in text


@pytest.mark.slow
def test_at_a_plant_releases_say_their_golden_tests_ran_at_the_head_office(group):   # noqa: F811 (the fixture imported above)
    history = json.loads(ok(engine(group.plant, "template", "history", "--class", "spur", "--json",
                                   url=group.plant_url)))
    releases = [version["release"] for version in history["versions"] if version["release"]]
    assert releases and all(release["gate"] == "head office" for release in releases)
    assert all("not re-checked here (their gears are the head office's)" in release["said"] for release in releases)
    text = ok(engine(group.plant, "template", "history", "--class", "spur", url=group.plant_url))
    assert "MISMATCH" not in text and "released at the head office" in text
    tests = engine(group.plant, "test", "--class", "spur", "--released", url=group.plant_url)
    refused(tests, f"this database is plant {PLANT}", "run them there")
    with TestClient(create_app(group.plant_url), base_url=LOOPBACK) as client:
        page = unescape(client.get("/classes/spur").text)
        golden = client.get("/classes/spur/tests", params={"released": 1}, headers=JSON)
    assert "MISMATCH" not in page and "released at the head office" in page
    assert golden.status_code == 400 and f"this database is plant {PLANT}" in golden.json()["error"]


@pytest.mark.slow
def test_at_a_plant_the_template_list_and_export_are_the_released_versions(group, tmp_path):   # noqa: F811 (the fixture imported above)
    version = rows(group.plant_url, "SELECT released_version('spur')")[0][0]
    count = rows(group.plant_url, "SELECT jsonb_array_length(rows) FROM template_version_rows "
                                  "WHERE gear_class = 'spur' AND version = %s", (version,))[0][0]
    classes = json.loads(ok(engine(group.plant, "template", "list", "--json", url=group.plant_url)))["classes"]
    spur = next(c for c in classes if c["class"] == "spur")
    assert (spur["template_version"], spur["rows"], spur["released"]) == (version, count, version) and count > 0
    exported = ok(engine(group.plant, "template", "export", "--class", "spur", url=group.plant_url))
    # the reference: the head office's export of its current rows, which no draft changed since the release
    assert exported == ok(engine(group.head, "template", "export", "--class", "spur", url=group.head_url))
    with psycopg.connect(group.plant_url) as conn:   # docs/guide/plants.md: no editable rows at a plant
        assert conn.execute("UPDATE template_view SET o = o WHERE gear_class = 'spur'").rowcount == 0
    assert rows(group.plant_url, "SELECT count(*) FROM released_template_view WHERE gear_class = 'spur'") == \
        [(count,)]
