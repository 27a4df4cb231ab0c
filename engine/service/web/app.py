"""The web view as an ASGI app: Starlette, Jinja2 pages rendered on the server, psycopg's
connection pool. Each page module (PAGE_MODULES) holds the routes of one concept as a list
ROUTES; the app gathers them, so a new page is a new module named here, not an edit of the
others. Pages read the database only through the engine's library (engine.programs,
engine.release), as the CLI does, so a page says what `engine … --json` says."""
from __future__ import annotations

from contextlib import asynccontextmanager
from importlib import import_module

from starlette.applications import Starlette
from starlette.routing import BaseRoute

# the concepts shown, each a module of this package with ROUTES (issue 32)
PAGE_MODULES = ("home", "gears", "jobs", "programs", "program_views")
POOL_SIZE = (1, 4)   # connections: one kept open, at most four pages answered at once


def create_app(database_url: str, *, require_login: bool = False, session_secret: str | None = None) -> Starlette:
    """The app on the database of `database_url` (resolved: engine.db.connection.resolve_url).
    require_login: every page but the login asks for a PostgreSQL login first (the service
    bound to an address other than loopback); else the local user sees every page."""
    app = Starlette(routes=_routes(), lifespan=_lifespan(database_url))
    app.state.require_login = require_login
    app.state.session_secret = session_secret
    return app


def _routes() -> list[BaseRoute]:
    routes: list[BaseRoute] = []
    for name in PAGE_MODULES:
        routes.extend(import_module(f"{__package__}.{name}").ROUTES)
    return routes


def _lifespan(database_url: str):
    """The pool lives as long as the app: opened at start-up, closed at shutdown."""
    @asynccontextmanager
    async def lifespan(app: Starlette):
        from psycopg_pool import ConnectionPool

        from ...db.json_numbers import read_bounded_json

        pool = ConnectionPool(database_url, min_size=POOL_SIZE[0], max_size=POOL_SIZE[1],
                              configure=read_bounded_json, open=False)
        pool.open(wait=True)
        app.state.pool = pool
        try:
            yield
        finally:
            pool.close()
    return lifespan
