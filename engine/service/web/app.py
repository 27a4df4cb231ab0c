"""The web view as an ASGI app: Starlette, Jinja2 pages rendered on the server, psycopg's
connection pool. Each page module (PAGE_MODULES) holds the routes of one concept as a list
ROUTES; the app gathers them, so a new page is a new module named here, not an edit of the
others. Pages read the database only through the engine's library (engine.programs,
engine.release), as the CLI does, so a page says what `engine … --json` says."""
from __future__ import annotations

from collections.abc import Callable
from contextlib import asynccontextmanager
from importlib import import_module
from typing import TYPE_CHECKING

from starlette.applications import Starlette
from starlette.exceptions import HTTPException
from starlette.middleware import Middleware
from starlette.middleware.sessions import SessionMiddleware
from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import BaseRoute

from .auth import SESSION_COOKIE, SESSION_SECONDS, LoginRequired, session_secret
from .pages import NotFramed, NulRefused, refusal

if TYPE_CHECKING:
    from ...programs.config import Config

# the concepts shown, each a module of this package with ROUTES (issue 32)
PAGE_MODULES = ("home", "auth", "gears", "jobs", "job_requests", "programs", "program_views", "classes", "machines")
POOL_SIZE = (1, 4)   # connections: one kept open, at most four pages answered at once
NO_PAGE = "no page at {path!r}: the home page / leads to every page (gears, jobs, programs, classes, machines)"
NOT_TAKEN = "{method} is not taken at {path!r}; it takes {allowed}"


def create_app(database_url: str, *, require_login: bool = False, session_secret: str | None = None,
               on_ready: Callable[[], None] | None = None, config: Config | None = None) -> Starlette:
    """The app on the database of `database_url` (resolved: engine.db.connection.resolve_url).
    require_login: every page but the login asks for a PostgreSQL login first (the service
    bound to an address other than loopback); else the local user sees every page.
    session_secret: the key the login's cookie is signed with (else ENGINE_SERVE_SECRET, else
    random per start: engine.service.web.auth). on_ready(): called once the pool is open and the
    server answers (engine serve says its address then, not before: a Ctrl-C earlier would stop
    uvicorn half started). config: the config file's settings a runner's request makes programs
    with (the line endings of each machine's files, as the FTP server's), else the config file
    read now (engine.programs.config.load_config: EngineError, one line, if it is malformed)."""
    from ...programs.config import load_config

    app = Starlette(routes=_routes(), lifespan=_lifespan(database_url, on_ready), middleware=_middleware(require_login,
                                                                                              session_secret),
                    exception_handlers={HTTPException: _http_error})
    app.state.require_login = require_login
    app.state.database_url = database_url   # the logins connect to it (auth); never shown
    app.state.config = config if config is not None else load_config()
    return app


def _middleware(require_login: bool, secret: str | None) -> list[Middleware]:
    """No answer in another site's frame; the session (a signed cookie holding the login's name);
    the login it asks for; an address holding a NUL refused (after the login: a visitor without
    one learns nothing more)."""
    return [Middleware(NotFramed),
            Middleware(SessionMiddleware, secret_key=session_secret(secret), session_cookie=SESSION_COOKIE,
                       max_age=SESSION_SECONDS, same_site="lax"),
            Middleware(LoginRequired, require_login=require_login),
            Middleware(NulRefused)]


def _http_error(request: Request, error: Exception) -> Response:
    """Starlette's own refusals (no such address, a method the address does not take) answered as
    every page's are: one line, as JSON {"error": …} when asked for, else the error page (Starlette
    says a bare text/plain "Not Found", which a program reading JSON cannot take)."""
    assert isinstance(error, HTTPException)
    path, allowed = request.url.path[:80], {k.lower(): v for k, v in (error.headers or {}).items()}.get("allow")
    message = (NO_PAGE.format(path=path) if error.status_code == 404 else
               NOT_TAKEN.format(method=request.method, path=path, allowed=", ".join(sorted(allowed.split(", "))))
               if allowed else str(error.detail))
    answer = refusal(request, message, error.status_code)
    answer.headers.update(error.headers or {})
    return answer


def _routes() -> list[BaseRoute]:
    routes: list[BaseRoute] = []
    for name in PAGE_MODULES:
        routes.extend(import_module(f"{__package__}.{name}").ROUTES)
    return routes


def _lifespan(database_url: str, on_ready: Callable[[], None] | None):
    """The pool lives as long as the app: opened at start-up, closed at shutdown."""
    @asynccontextmanager
    async def lifespan(app: Starlette):
        from psycopg_pool import ConnectionPool

        from ...db.json_numbers import read_bounded_json

        pool = ConnectionPool(database_url, min_size=POOL_SIZE[0], max_size=POOL_SIZE[1],
                              configure=read_bounded_json, open=False)
        pool.open(wait=True)
        app.state.pool = pool
        if on_ready is not None:
            on_ready()
        try:
            yield
        finally:
            pool.close()
    return lifespan
