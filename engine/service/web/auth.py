"""Who may do what on the web view (issue 32; design notes §10). On 127.0.0.1 the pages are open
to the local user: whoever can reach the loopback address can run psql as the service's role too.
Bound to any other address, every page but the login asks for a login, and the login is
PostgreSQL's: the user name and password open a connection to the service's own database as that
user (a short connect timeout), so the shop keeps one list of people and passwords, its database's,
with its password rules, expiry (VALID UNTIL) and lock-out (NOLOGIN). A server that did not ask for
the password (pg_hba.conf `trust`, `peer`) proves nothing: the login is refused.

A member of engine_reader, engine_runner, engine_editor, engine_releaser or engine_planner (or the
owner, or a superuser) sees every page; a member of engine_runner (or the owner) may also request a
program for a stored job (may_request). The rights are asked of PostgreSQL again on every page,
so a role revoked or a login locked takes effect at the next click. The session is a signed cookie
(Starlette's SessionMiddleware) holding only the user name, never the password; a failed login is
one line that does not say whether the user exists; no password is echoed or logged."""
from __future__ import annotations

import logging
import os
import secrets
from urllib.parse import SplitResult, quote, urlsplit

import msgspec
import psycopg
from psycopg.conninfo import make_conninfo
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import JSONResponse, RedirectResponse, Response
from starlette.routing import Route
from starlette.types import ASGIApp, Receive, Scope, Send

from ...db.connection import scalar
from ..addresses import is_loopback
from .pages import TEMPLATES, refusal, wants_json

LOGIN_PATH = "/login"
OPEN_PATHS = (LOGIN_PATH,)          # what a visitor without a login may open
SESSION_COOKIE = "engine_session"
SESSION_SECONDS = 12 * 3600         # a shift and its overlap; then the login is asked again
CONNECT_TIMEOUT = 5                 # seconds a login waits for the database
SECRET_VARIABLE = "ENGINE_SERVE_SECRET"
SEEING_ROLES = ["engine_reader", "engine_runner", "engine_editor", "engine_releaser", "engine_planner"]
REQUESTING_ROLE = "engine_runner"
REFUSED = "login refused: wrong user name or password, or the database does not accept this login"
NO_ROLE = ("login refused: this login has no role of the engine's (engine_reader sees the pages, engine_runner "
           "also requests programs); ask the database's owner to grant one")
UNCHECKED_LOGINS = ("web logins will be refused: the database server lets logins in without a password "
                    "(pg_hba.conf `trust`: {said}), and the web view takes only logins "
                    "PostgreSQL checks; set scram-sha-256 on the pg_hba.conf lines this service connects by "
                    "(host; local for a socket) "
                    "(docs/guide/web-view-releases-and-logins.md)")
LOCAL_USER = "local"               # program_request.client of a request on the open loopback app
CROSS_SITE = ("refused: a program is requested only from this service's own page ({}); open the job's page "
              "here and use its button")
LOGOUT_CROSS_SITE = ("refused: a logout is taken only from this service's own page ({}); use the Log out button "
                     "of its pages")
MISDIRECTED = ("this view is open only to the local user, at a loopback address: open it as "
               "http://127.0.0.1:{port}/ (it was reached as {host!r})")
LOG = logging.getLogger("engine.serve")

# What a login may do: the owner of the engine's tables (the role that migrates) and superusers
# everything; the engine's roles as granted, inherited (USAGE: usable without SET ROLE). A login
# that may no longer log in (NOLOGIN, VALID UNTIL passed) or no longer exists has no rights.
RIGHTS = """
SELECT coalesce(r.rolsuper OR pg_has_role(r.oid, o.relowner, 'USAGE'), false),
       EXISTS (SELECT 1 FROM pg_roles g WHERE g.rolname = ANY(%(seeing)s) AND pg_has_role(r.oid, g.oid, 'USAGE')),
       EXISTS (SELECT 1 FROM pg_roles g WHERE g.rolname = %(requesting)s AND pg_has_role(r.oid, g.oid, 'USAGE'))
FROM pg_roles r LEFT JOIN pg_class o ON o.oid = to_regclass('program')
WHERE r.rolname = %(login)s AND r.rolcanlogin AND (r.rolvaliduntil IS NULL OR r.rolvaliduntil > now())"""
SERVICE_LOGIN = "SELECT current_user"


class Rights(msgspec.Struct, frozen=True):
    """What a login may do on the web view."""
    login: str
    sees: bool        # every page
    requests: bool    # also a program for a stored job (engine_runner)


def session_secret(given: str | None) -> str:
    """The key the session cookie is signed with: create_app's, else ENGINE_SERVE_SECRET, else a
    random one for this start (sessions then end when the service restarts)."""
    return given or os.environ.get(SECRET_VARIABLE) or secrets.token_urlsafe(32)


def rights_of(conn: psycopg.Connection, login: str) -> Rights:
    found = conn.execute(RIGHTS, {"login": login, "seeing": SEEING_ROLES, "requesting": REQUESTING_ROLE}).fetchone()
    if found is None:
        return Rights(login, False, False)
    owner, sees, requests = found
    return Rights(login, owner or sees, owner or requests)


def check_login(database_url: str, user: str, password: str) -> Rights | None:
    """The rights of `user` if PostgreSQL accepts the password for the service's database, else None.
    An empty password is refused before asking: libpq would take it as none given and use a
    password file or PGPASSWORD of the service's own environment."""
    if not user or not password or "\0" in user + password:
        return None
    conninfo = make_conninfo(database_url, user=user, password=password, passfile=os.devnull,
                             connect_timeout=CONNECT_TIMEOUT)
    try:
        with psycopg.connect(conninfo, autocommit=True) as conn:
            if not conn.pgconn.used_password:
                LOG.warning("login refused: the database server did not ask for a password (pg_hba.conf trusts "
                            "the connection); the web view takes only logins PostgreSQL checks")
                return None
            return rights_of(conn, user)
    except psycopg.Error:
        return None


def unchecked_logins(database_url: str) -> str | None:
    """Why no web login can succeed on this database server, or None: it lets a login in without
    asking for its password (pg_hba.conf `trust`, as the embedded server's initdb --auth=trust),
    and check_login refuses every login PostgreSQL did not check. Asked once at start-up (engine
    serve off loopback): the service's own role with a made-up password let in, or a made-up role
    told it does not exist without a password asked (a server that checks passwords asks one of an
    unknown role too, not to tell who exists). A refusal for any other reason (no pg_hba.conf line
    for a made-up role) is not taken for trust. Each try leaves one FATAL line in the server's log."""
    own = _probe(database_url, None)
    if own is None:
        return UNCHECKED_LOGINS.format(said="the service's own role got in with a made-up password")
    made_up = _probe(database_url, f"engine_probe_{secrets.token_hex(6)}")
    if made_up is not None and "does not exist" in made_up:
        return UNCHECKED_LOGINS.format(said=f"a made-up login was told, no password asked: {made_up[:100]}")
    return None


def _probe(database_url: str, user: str | None) -> str | None:
    """A login with a made-up password (as `user`, else the URL's): None if it was let in without
    one, else why it was refused ("" when the server asked for the password)."""
    conninfo = make_conninfo(database_url, password=secrets.token_urlsafe(18), passfile=os.devnull,
                             connect_timeout=CONNECT_TIMEOUT, **({"user": user} if user else {}))
    probe = psycopg.pq.PGconn.connect(conninfo.encode())
    try:
        if probe.status == psycopg.pq.ConnStatus.OK:
            return None if not probe.used_password else ""
        if probe.used_password:
            return ""
        return (probe.error_message.decode(errors="replace").strip().splitlines() or ["-"])[0].rpartition(
            "FATAL:")[2].strip()
    finally:
        probe.finish()


class LoginRequired:
    """Every page but the login asks for a login whose rights PostgreSQL confirms now (the service
    bound to an address other than loopback); the rights are left in request.state.rights. The
    open (loopback) view answers only a loopback Host: see misdirected."""

    def __init__(self, app: ASGIApp, require_login: bool):
        self.app, self.require_login = app, require_login

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        request = Request(scope, receive)
        if not self.require_login:
            reason = misdirected(request)
            if reason is not None:
                return await refusal(request, reason, 421)(scope, receive, send)
            return await self.app(scope, receive, send)
        if scope["path"] in OPEN_PATHS:
            return await self.app(scope, receive, send)
        login = request.session.get("login")
        rights = await run_in_threadpool(_pool_rights, request, login) if login else None
        if rights is None or not rights.sees:
            request.session.clear()
            return await _ask_login(request)(scope, receive, send)
        scope.setdefault("state", {})["rights"] = rights
        await self.app(scope, receive, send)


def misdirected(request: Request) -> str | None:
    """Why the open view does not answer this request, or None: its Host is no loopback name. A page
    of another site whose name is made to resolve to 127.0.0.1 (DNS rebinding) would otherwise read
    every page through the local user's browser (the adversary of issue 32 read /programs as
    Host: evil.example); a browser sends the name it resolved, so only 127.0.0.1, localhost, [::1]."""
    host = request.headers.get("host", "")
    if is_loopback(_split(f"//{host}").hostname or ""):
        return None
    port = (request.scope.get("server") or ("", "PORT"))[1]
    return MISDIRECTED.format(port=port, host=host[:80])


def _pool_rights(request: Request, login: str) -> Rights:
    with request.app.state.pool.connection() as conn:
        return rights_of(conn, login)


def _ask_login(request: Request) -> Response:
    if wants_json(request):
        return JSONResponse({"error": f"log in first: POST {LOGIN_PATH} with user and password"}, status_code=401)
    return RedirectResponse(f"{LOGIN_PATH}?next={quote(request.url.path)}", status_code=303)


def may_request(request: Request, conn: psycopg.Connection | None = None) -> bool:
    """The login of this request may request a program for a stored job (engine_runner, or the
    owner). On the open (loopback) app the local user acts as the service's own role, asked on
    `conn` if given (a page already holding one), else on a connection of the pool."""
    rights = getattr(request.state, "rights", None)
    if rights is not None:
        return rights.requests
    if conn is not None:
        return _service_rights(conn).requests
    with request.app.state.pool.connection() as conn:
        return _service_rights(conn).requests


def _service_rights(conn: psycopg.Connection) -> Rights:
    return rights_of(conn, scalar(conn.execute(SERVICE_LOGIN)))


def requester(request: Request) -> str:
    """Who asks, as program_request.client records it: the login, or "local" on the open app."""
    rights = getattr(request.state, "rights", None)
    return LOCAL_USER if rights is None else rights.login


def cross_site(request: Request, said: str = CROSS_SITE) -> str | None:
    """Why a form's POST may not have come from this service's own pages, or None (issue 32: a
    page of another site must not make the browser of a logged-in runner, or of the local user of
    the open loopback app, request a program). The browser's Origin (else Referer) must name this
    very host as the request reached it (Host), and on the open app that host must be a loopback
    one: a name of another site resolving to 127.0.0.1 (DNS rebinding) is its own origin there.
    `said`: the refusal, naming the action (a request, a logout)."""
    host = request.headers.get("host", "").lower()
    came_from = request.headers.get("origin") or request.headers.get("referer")
    if not came_from or not host:
        return said.format("it says no Origin or Referer, or no Host")
    if _split(came_from).netloc.lower() != host:
        return said.format(f"it came from {came_from[:80]!r}, not from {host[:80]!r}")
    if not request.app.state.require_login and not is_loopback(_split(f"//{host}").hostname or ""):
        return said.format(f"the open (loopback) view was reached as {host[:80]!r}; open it as 127.0.0.1")
    return None


def _split(address: str) -> SplitResult:
    """The parts of an address a browser sent; none of a malformed one (an unclosed [)."""
    try:
        return urlsplit(address)
    except ValueError:
        return urlsplit("")


async def login_form(request: Request) -> Response:
    return _login_page(request, None, request.query_params.get("next", "/"))


async def login(request: Request) -> Response:
    """Checks the user and password against PostgreSQL; the session then holds the user name."""
    form = await request.form()
    user, password, after = (str(form.get(key) or "") for key in ("user", "password", "next"))
    rights = await run_in_threadpool(check_login, request.app.state.database_url, user, password)
    if rights is None or not rights.sees:
        return _login_page(request, REFUSED if rights is None else NO_ROLE, after, status=401)
    request.session.clear()
    request.session["login"] = rights.login
    if wants_json(request):
        return JSONResponse({"login": rights.login, "requests": rights.requests})
    return RedirectResponse(_local(after), status_code=303)


async def logout(request: Request) -> Response:
    """Ends the session; only from this service's own pages (cross_site: another site's page must
    not log a user out, 403 and the session kept)."""
    reason = cross_site(request, LOGOUT_CROSS_SITE)
    if reason is not None:
        return refusal(request, reason, 403)
    request.session.clear()
    if wants_json(request):
        return JSONResponse({"logged_out": True})
    return RedirectResponse(LOGIN_PATH, status_code=303)


def _local(path: str) -> str:
    """Where to go after the login: a path of this site only (never another site's address)."""
    return path if path.startswith("/") and not path.startswith("//") and "\\" not in path else "/"


def _login_page(request: Request, refusal: str | None, after: str, status: int = 200) -> Response:
    if wants_json(request):
        return JSONResponse({"error": refusal or f"log in: POST {LOGIN_PATH} with user and password"},
                            status_code=status if refusal else 401)
    return TEMPLATES.TemplateResponse(request, "login.html", {"refusal": refusal, "next": _local(after)},
                                      status_code=status)


ROUTES = [
    Route(LOGIN_PATH, login_form, methods=["GET"], name="login_form"),
    Route(LOGIN_PATH, login, methods=["POST"], name="login"),
    Route("/logout", logout, methods=["POST"], name="logout"),
]
