"""A runner's request on the web view (issue 32): the job page's button "Make and send to <machine>"
has the job's program made by the delivery path every control's request takes, proved, stored and
recorded in program_request (via 'web', the login, or 'local' on loopback), and leads to the
program's page; the program is the one `engine instantiate --job J --out DIR/` writes (the CLI on the
same database is the reference). A refusal (a draft-only class, a machine's travel edited down) is
the job's page again with its one-line reason, recorded. A reader is refused, naming engine_runner;
a POST from another site's page is refused and changes nothing. The login tests run on a server of
their own that checks passwords (tests/helpers/password_server.py), as tests/test_serve_auth.py."""
from __future__ import annotations

import html
import json
import uuid
from contextlib import contextmanager

import psycopg
import pytest
from helpers.lineage_text import id_masked
from helpers.password_server import database_url, migrated_database, password_server
from helpers.roles import logins
from psycopg.conninfo import conninfo_to_dict
from starlette.testclient import TestClient

from engine.library.seed import seed
from engine.programs.instantiate import instantiate_gear
from engine.service.web.app import create_app

HERE = "http://127.0.0.1:8080"      # where the loopback view is opened
SAME_SITE = {"Origin": HERE}        # what a browser sends with the form of the service's own page
JSON = {"Accept": "application/json"}
MACHINE = "hobber-840d"
ENDINGS = {"lf": "\n", "crlf": "\r\n"}
NC_PART = "%_N_NC_PART_MPF\n;$PATH=/_N_MPF_DIR\nG90 G71 G94\nM30\n"


def requests(url: str) -> list[tuple]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT machine, via, client, asked_for, job_id, program_id, refusal FROM program_request "
                            "ORDER BY id").fetchall()


def program_count(url: str) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM program").fetchone()[0]


@pytest.fixture
def made(run):
    """(run, client, job id, program id): gear 42's job made by the CLI on a private copy of the seeded
    database, and the open (loopback) web view on it."""
    result = run("instantiate", "--gear", 42, "--machine", MACHINE, "--json")
    assert result.exit_code == 0, result.output
    program = json.loads(result.stdout)
    with TestClient(create_app(run.url), base_url=HERE, follow_redirects=False) as client:
        yield run, client, program["job_id"], program["program_id"]


def stored_text(client, program_id: int) -> str:
    """The program's text as its record says it is written: its lines, its line ending, its final newline."""
    answer = client.get(f"/programs/{program_id}", headers=JSON)
    assert answer.status_code == 200, answer.text
    [record] = answer.json()["programs"]
    ending = ENDINGS[record["line_ending"]]
    assert record["rendering"]["status"] == "MATCH" and not record["draft"] and not record["unverified"]
    return ending.join(record["lines"]) + (ending if record["final_newline"] else "")


def test_a_runners_request_proves_stores_records_and_leads_to_the_program(made, tmp_path):
    run, client, job, program = made
    page = client.get(f"/jobs/{job}")
    assert f'<form method="post" action="/jobs/{job}/request"><button>Make and send to {MACHINE}</button>' in page.text
    again = client.post(f"/jobs/{job}/request", headers=SAME_SITE)   # the stored program, proved again
    assert again.status_code == 303 and again.headers["location"] == f"/programs/{program}"
    with psycopg.connect(run.url) as conn:   # the job edited since: its program is made again
        conn.execute("UPDATE job SET params = params || '{\"program_name\": \"WHEEL_42\"}' WHERE id = %s", (job,))
    remade = client.post(f"/jobs/{job}/request", headers=SAME_SITE)
    assert remade.status_code == 303
    new = int(remade.headers["location"].removeprefix("/programs/"))
    assert new != program and program_count(run.url) == 2
    assert requests(run.url) == [(MACHINE, "web", "local", f"JOB {job}", job, program, None),
                                 (MACHINE, "web", "local", f"JOB {job}", job, new, None)]
    out = tmp_path / "out"
    out.mkdir()
    assert run("instantiate", "--job", job, "--out", f"{out}/").exit_code == 0   # the reference: a program of its own
    reference = (out / "WHEEL_42.MPF").read_bytes().decode("ascii")
    assert id_masked(stored_text(client, new).split("\n")) == id_masked(reference.split("\n"))
    assert f"; PROGRAM {new} TEMPLATE spur" in stored_text(client, new)
    listed = client.get(f"/machines/{MACHINE}", headers=JSON).json()["requests"]
    assert [(r["via"], r["client"], r["program_id"]) for r in listed] == [("web", "local", new),
                                                                          ("web", "local", program)]


def test_a_job_whose_proof_fails_now_shows_the_reason_and_is_recorded(made):
    run, client, job, program = made
    with psycopg.connect(run.url) as conn:   # the machine's record changed since: X now ends at 30 mm
        conn.execute("UPDATE machine SET x_max = 30 WHERE name = %s", (MACHINE,))
    page = client.post(f"/jobs/{job}/request", headers=SAME_SITE)
    as_json = client.post(f"/jobs/{job}/request", headers={**SAME_SITE, **JSON})
    assert page.status_code == 400 and f"exceeds the travel of {MACHINE}" in page.text
    assert f"<h1>Job {job}</h1>" in page.text and 'id="refusal">refused: ' in page.text   # the job's page again
    assert as_json.status_code == 400 and f"exceeds the travel of {MACHINE}" in as_json.json()["error"]
    rows = requests(run.url)
    assert [row[:6] for row in rows] == [(MACHINE, "web", "local", f"JOB {job}", job, None)] * 2
    assert rows[1][6] == as_json.json()["error"] and program_count(run.url) == 1   # nothing stored


def test_a_draft_only_class_is_refused_with_its_reason(made, tmp_path):
    run, client, _, _ = made
    (tmp_path / "part.mpf").write_text(NC_PART)   # a class import-nc makes: a draft, no release
    assert run("import-nc", tmp_path / "part.mpf", "--class", "nc_part").exit_code == 0
    with psycopg.connect(run.url) as conn:
        job = conn.execute("INSERT INTO job (gear_class, machine, params) VALUES ('nc_part', %s, "
                           "'{\"program_name\": \"NC_PART\"}') RETURNING id", (MACHINE,)).fetchone()[0]
    answer = client.post(f"/jobs/{job}/request", headers={**SAME_SITE, **JSON})
    assert answer.status_code == 400
    assert answer.json()["error"].startswith("class 'nc_part' has no released template version")
    assert requests(run.url) == [(MACHINE, "web", "local", f"JOB {job}", job, None, answer.json()["error"])]


def test_a_post_from_another_site_is_refused_and_changes_nothing(made):
    run, client, job, program = made
    path = f"/jobs/{job}/request"
    refused = [client.post(path, headers=headers) for headers in (
        {"Origin": "http://evil.example"}, {"Origin": "null"}, {"Referer": "http://evil.example/jobs"},
        {"Origin": "http://127.0.0.1:9999"}, {})]
    assert [answer.status_code for answer in refused] == [403] * 5
    assert all("only from this service's own page" in html.unescape(answer.text) for answer in refused)
    # a name of another site resolving to 127.0.0.1 (DNS rebinding): its own origin, but the open view
    # answers only a loopback Host (tests/test_adversary32_web_rebinding.py)
    rebound = client.post(f"http://evil.example:8080{path}", headers={"Origin": "http://evil.example:8080"})
    assert rebound.status_code == 421 and "open only to the local user" in html.unescape(rebound.text)
    assert requests(run.url) == [] and program_count(run.url) == 1
    from_here = client.post(path, headers={"Referer": f"{HERE}/jobs/{job}"})   # the same page's form: taken
    assert from_here.status_code == 303 and from_here.headers["location"] == f"/programs/{program}"


def test_the_action_takes_only_a_post_and_an_unknown_job_is_404(made):
    run, client, job, _ = made
    assert client.get(f"/jobs/{job}/request").status_code == 405
    unknown = client.post("/jobs/999999/request", headers={**SAME_SITE, **JSON})
    assert unknown.status_code == 404 and unknown.json() == {
        "error": "job 999999 does not exist; the jobs page lists the stored ones"}
    assert client.post("/jobs/abc/request", headers=SAME_SITE).status_code == 400
    assert client.get(f"/jobs/{job}", headers=JSON).json() == json.loads(run("jobs", "show", job, "--json").stdout)
    assert requests(run.url) == []


# --- logins: a reader and a runner on a server that checks passwords --------------------------------

@pytest.fixture(scope="module")
def shop():
    """(the service's URL: a login of engine_runner only, as design notes §10 says; a login factory;
    the admin URL; gear 42's job on the 840D) on a seeded database of a password-checking server."""
    with password_server() as admin_url:
        url = migrated_database(admin_url, f"engine_request_{uuid.uuid4().hex[:10]}")
        with psycopg.connect(url) as conn:
            seed(conn)
            job = instantiate_gear(conn, 42, machine=MACHINE).job_id
        with logins(admin_url) as create:
            service = create("engine_runner")
            yield (database_url(url, conninfo_to_dict(url)["dbname"], service.name, service.password), create, url,
                   job)


@contextmanager
def logged_in(shop, role: str):
    """(the web view asking for logins, logged in as a new login of `role`; the login's name)."""
    service_url, create, _, _ = shop
    login = create(role)
    app = create_app(service_url, require_login=True, session_secret="test secret")
    with TestClient(app, follow_redirects=False) as client:
        answer = client.post("/login", data={"user": login.name, "password": login.password, "next": "/"})
        assert answer.status_code == 303, answer.text
        yield client, login.name


def test_a_reader_sees_no_button_and_is_refused_naming_engine_runner(shop):
    _, _, admin, job = shop
    before = requests(admin)
    with logged_in(shop, "engine_reader") as (client, name):
        page = client.get(f"/jobs/{job}")
        refused = client.post(f"/jobs/{job}/request", headers={"Origin": "http://testserver"})
        as_json = client.post(f"/jobs/{job}/request", headers={"Origin": "http://testserver", **JSON})
        fetched = client.get(f"/jobs/{job}/request")
    assert page.status_code == 200 and "Make and send" not in page.text and "/request" not in page.text
    assert refused.status_code == 403 and "only a member of engine_runner may request a program" in refused.text
    assert as_json.status_code == 403 and as_json.json() == {"error": (
        f"job {job}: only a member of engine_runner may request a program; login {name} may only see the pages: "
        "ask the database's owner to GRANT engine_runner to it")}
    assert fetched.status_code == 405
    assert requests(admin) == before


def test_a_runner_logged_in_is_recorded_by_name(shop):
    _, _, admin, job = shop
    with logged_in(shop, "engine_runner") as (client, name):
        assert "Make and send to hobber-840d" in client.get(f"/jobs/{job}").text
        answer = client.post(f"/jobs/{job}/request", headers={"Origin": "http://testserver"})
    assert answer.status_code == 303
    program = int(answer.headers["location"].removeprefix("/programs/"))
    assert requests(admin)[-1] == (MACHINE, "web", name, f"JOB {job}", job, program, None)
    with psycopg.connect(admin) as conn:   # stored by the service's own login, for the person who asked
        stored_by = conn.execute("SELECT requested_by FROM program_request ORDER BY id DESC LIMIT 1").fetchone()[0]
    assert stored_by == conninfo_to_dict(shop[0])["user"]
