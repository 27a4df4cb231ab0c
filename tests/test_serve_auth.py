"""Who may do what on the web view (issue 32; design notes §10): on loopback the pages are open; on
any other address (create_app(require_login=True)) every page but the login asks for a login, and
the login is PostgreSQL's, checked by connecting to the service's own database with the password.
The logins are real roles made by the test (roles are cluster-wide: unique names, dropped after)
on a server of the test's own that checks passwords (tests/helpers/password_server.py): the
suite's servers trust local connections, where no password is ever checked, and a login there is
refused."""
import os
import socket
import subprocess
import sys
import uuid
from contextlib import contextmanager
from pathlib import Path

import psycopg
import pytest
from helpers.password_server import database_url, migrated_database, password_server
from helpers.roles import logins
from markupsafe import escape
from psycopg import sql
from psycopg.conninfo import conninfo_to_dict, make_conninfo
from starlette.responses import JSONResponse
from starlette.routing import Route
from starlette.testclient import TestClient

from engine.service.web.app import create_app
from engine.service.web.auth import NO_ROLE, REFUSED, SESSION_COOKIE, may_request, unchecked_logins

JSON = {"Accept": "application/json"}
LOOPBACK = "http://127.0.0.1"   # the open web view answers a loopback Host only
TRUSTED = f"trusted_{uuid.uuid4().hex[:12]}"   # a login pg_hba.conf trusts: no password asked
PAGES = ("/", "/classes", "/machines")
REPOSITORY = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def server():
    """(admin URL of a migrated database on a password-checking server, a login factory)."""
    with password_server(trusted=(TRUSTED,)) as admin_url:
        url = migrated_database(admin_url, f"engine_login_{uuid.uuid4().hex[:10]}")
        with logins(admin_url) as create:
            yield url, create


@pytest.fixture(scope="module")
def service(server):
    """The service's own URL: a login of engine_runner with a password, as design notes §10 says."""
    url, create = server
    login = create("engine_runner")
    return database_url(url, conninfo_to_dict(url)["dbname"], login.name, login.password), login


@contextmanager
def web(url, require_login=True):
    app = create_app(url, require_login=require_login, session_secret="test secret")
    app.router.routes.append(Route("/may-request", lambda request: JSONResponse({"may": may_request(request)})))
    with TestClient(app, base_url=LOOPBACK, follow_redirects=False) as client:
        yield client


def logged_in(client, login, password=None):
    return client.post("/login", data={"user": login.name, "password": password or login.password, "next": "/classes"})


def test_without_a_login_every_page_sends_to_the_login(service):
    url, _ = service
    with web(url) as client:
        for path in (*PAGES, "/classes/spur", "/machines/hobber-840d"):
            answer = client.get(path)
            assert answer.status_code == 303 and answer.headers["location"] == f"/login?next={path}", path
            assert client.get(path, headers=JSON).status_code == 401
        form = client.get("/login")
    assert form.status_code == 200 and 'name="password" type="password"' in form.text


def test_a_reader_logs_in_sees_every_page_and_may_not_request(server, service):
    url, create = server
    reader = create("engine_reader")
    with web(service[0]) as client:
        answer = logged_in(client, reader)
        assert answer.status_code == 303 and answer.headers["location"] == "/classes"
        pages = {path: client.get(path) for path in PAGES}
        listed = client.get("/classes", headers=JSON)
        may = client.get("/may-request").json()["may"]
    assert all(page.status_code == 200 for page in pages.values())
    assert reader.name in pages["/classes"].text and "Log out" in pages["/classes"].text
    assert listed.json() == {"classes": []} and may is False


def test_a_runner_may_request_a_program(server, service):
    runner = server[1]("engine_runner")
    with web(service[0]) as client:
        assert logged_in(client, runner).status_code == 303
        assert client.get("/may-request").json()["may"] is True


@pytest.mark.parametrize("kind", ["wrong password", "unknown user"])
def test_a_failed_login_is_one_line_that_does_not_say_whether_the_user_exists(server, service, kind):
    reader = server[1]("engine_reader")
    typed = "not-the-password-" + uuid.uuid4().hex
    with web(service[0]) as client:
        if kind == "unknown user":
            answer = client.post("/login", data={"user": f"nobody_{uuid.uuid4().hex[:8]}", "password": typed})
        else:
            answer = logged_in(client, reader, typed)
        as_json = client.post("/login", data={"user": reader.name, "password": typed}, headers=JSON)
        after = client.get("/classes")
    assert answer.status_code == 401 and REFUSED in answer.text and typed not in answer.text
    assert as_json.status_code == 401 and as_json.json() == {"error": REFUSED}
    assert after.status_code == 303   # no session was given


def test_a_login_without_an_engine_role_or_with_an_empty_password_is_refused(server, service):
    url, _ = server
    with psycopg.connect(url, autocommit=True) as admin:
        name, password = f"nobody_{uuid.uuid4().hex[:10]}", uuid.uuid4().hex
        admin.execute(sql.SQL("CREATE ROLE {} LOGIN PASSWORD {}").format(sql.Identifier(name), sql.Literal(password)))
    try:
        with web(service[0]) as client:
            no_role = client.post("/login", data={"user": name, "password": password})
            empty = client.post("/login", data={"user": service[1].name, "password": ""})
    finally:
        with psycopg.connect(url, autocommit=True) as admin:
            admin.execute(sql.SQL("DROP ROLE {}").format(sql.Identifier(name)))
    assert no_role.status_code == 401 and str(escape(NO_ROLE)) in no_role.text
    assert empty.status_code == 401 and REFUSED in empty.text


def test_a_login_the_server_trusts_without_a_password_is_refused(server, service):
    """pg_hba.conf trusts TRUSTED: PostgreSQL lets it in whatever password is typed, so that
    connection proves nothing about the person."""
    url, _ = server
    with psycopg.connect(url, autocommit=True) as admin:
        admin.execute(sql.SQL("CREATE ROLE {} LOGIN IN ROLE engine_reader").format(sql.Identifier(TRUSTED)))
    try:
        with web(service[0]) as client:
            answer = client.post("/login", data={"user": TRUSTED, "password": "anything"})
    finally:
        with psycopg.connect(url, autocommit=True) as admin:
            admin.execute(sql.SQL("DROP ROLE {}").format(sql.Identifier(TRUSTED)))
    assert answer.status_code == 401 and REFUSED in answer.text


def test_logout_a_revoked_role_and_a_forged_cookie_end_the_session(server, service):
    url, create = server
    reader, other = create("engine_reader"), create("engine_reader")
    with web(service[0]) as client:
        assert logged_in(client, reader).status_code == 303 and client.get("/classes").status_code == 200
        assert client.post("/logout", headers={"Origin": LOOPBACK}).status_code == 303
        assert client.get("/classes").status_code == 303
        assert logged_in(client, other).status_code == 303 and client.get("/classes").status_code == 200
        with psycopg.connect(url, autocommit=True) as admin:
            admin.execute(sql.SQL("REVOKE engine_reader FROM {}").format(sql.Identifier(other.name)))
        assert client.get("/classes").status_code == 303   # asked of PostgreSQL again on every page
    with web(service[0]) as client:
        client.cookies.set(SESSION_COOKIE, 'eyJsb2dpbiI6ICJwb3N0Z3JlcyJ9')   # {"login": "postgres"}, unsigned
        assert client.get("/classes").status_code == 303


def test_a_logout_from_another_site_is_refused_and_the_session_kept(server, service):
    """Another site's page may not log a user out (its form's POST carries its own Origin, or none
    when the browser hides it): 403 naming the check, and the session goes on."""
    reader = server[1]("engine_reader")
    with web(service[0]) as client:
        assert logged_in(client, reader).status_code == 303
        refused = [client.post("/logout", headers=headers) for headers in
                   ({"Origin": "https://evil.example"}, {"Referer": "https://evil.example/page"}, {})]
        as_json = client.post("/logout", headers={"Origin": "https://evil.example", **JSON})
        still = client.get("/classes")
        own = client.post("/logout", headers={"Referer": f"{LOOPBACK}/classes"})
        after = client.get("/classes")
    assert all(answer.status_code == 403 and "logout is taken only from this service's own page"
               in answer.text.replace("&#39;", "'") for answer in refused)
    assert as_json.status_code == 403 and "evil.example" in as_json.json()["error"]
    assert still.status_code == 200 and own.status_code == 303 and after.status_code == 303


def test_no_page_shows_a_password(server, service):
    """The service's own password (in its database URL) and the login's appear in no page and no
    JSON answer."""
    url, create = server
    reader = create("engine_reader")
    with web(service[0]) as client:
        logged_in(client, reader)
        answers = [client.get(path, headers=headers) for path in (*PAGES, "/login", "/nosuch")
                   for headers in ({}, JSON)]
    assert all(service[1].password not in answer.text and reader.password not in answer.text for answer in answers)
    assert SESSION_COOKIE in client.cookies and reader.password not in client.cookies[SESSION_COOKIE]


def test_a_server_that_checks_passwords_is_not_said_to_refuse_logins(server, service):
    """The password server asks every role but its administrator for a password: the service's
    login is not said to refuse logins; its administrator's URL (trusted) is."""
    assert unchecked_logins(service[0]) is None
    said = unchecked_logins(server[0])
    assert said is not None and said.startswith("web logins will be refused") and "scram-sha-256" in said


def test_a_trusting_server_is_found_by_a_made_up_login_too(read_only_database_url):
    """A service whose own role the server does not know (its URL's login refused): the made-up
    role told "does not exist" without a password asked is the trusting server's answer."""
    url = make_conninfo(read_only_database_url, user=f"nobody_{uuid.uuid4().hex[:10]}")
    said = unchecked_logins(url)
    assert said is not None and "a made-up login was told, no password asked: role \"engine_probe_" in said


def test_engine_serve_off_loopback_says_at_start_up_that_a_trusting_server_refuses_every_login(
        read_only_database_url, tmp_path):
    """The review of issue 32: on the embedded server (initdb --auth=trust) every web login was
    refused "wrong user name or password", the reason only on stderr at each try. `engine serve
    --host` off loopback says it once at start-up, then serves (FTP and request folders still work)."""
    with socket.socket() as probe:
        probe.bind(("0.0.0.0", 0))
        port = probe.getsockname()[1]
    environment = {**os.environ, "ENGINE_RUNTIME_DIR": str(tmp_path), "ENGINE_CONFIG": "",
                   "PYTHONPATH": str(REPOSITORY)}
    service = subprocess.Popen([sys.executable, "-m", "engine", "--database-url", read_only_database_url, "serve",
                                "--host", "0.0.0.0", "--port", str(port)], env=environment, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        first, second = service.stdout.readline(), service.stdout.readline()
    finally:
        service.terminate()   # as engine serve stop asks
        out, err = service.communicate(timeout=60)
    assert first.startswith("web logins will be refused: the database server lets logins in without a password "
                            "(pg_hba.conf `trust`: the service's own role got in with a made-up password)"), first + err
    assert "set scram-sha-256" in first and second.startswith(f"serving the web view at http://0.0.0.0:{port}/")
    assert service.returncode == 0 and "stopped" in out


def test_on_loopback_the_pages_are_open(read_only_database_url):
    """The app bound to 127.0.0.1 (engine serve's default): the local user sees every page without
    a login, and acts as the service's own role (the suite's superuser here) for requests."""
    with web(read_only_database_url, require_login=False) as client:
        answers = {path: client.get(path) for path in (*PAGES, "/classes/spur", "/machines/hobber-840d")}
        may = client.get("/may-request").json()["may"]
    assert all(answer.status_code == 200 for answer in answers.values())
    assert "Log out" not in answers["/classes"].text and may is True
