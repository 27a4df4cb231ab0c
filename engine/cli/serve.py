"""`engine serve` and `engine serve stop`: the shop floor's side of the engine (issue 32), run
from the command line. The service's modules (engine.service: starlette, uvicorn, jinja2) are
imported inside the commands, so no other command pays for them (issue 28: start-up)."""
from __future__ import annotations

import click

from .context import connection

PORT = click.IntRange(1, 65535)
DEFAULT_PORT = 8080


@click.group("serve", invoke_without_command=True)
@click.option("--host", default="127.0.0.1", show_default=True,
              help="Address to listen on. Any address but loopback (127.0.0.1, ::1, localhost) asks "
                   "every visitor for a PostgreSQL login first.")
@click.option("--port", type=PORT, default=DEFAULT_PORT, show_default=True, help="Port of the web view.")
@click.pass_context
def serve(ctx, host, port):
    """Serve the web view of gears, jobs and programs (each page also as JSON with
    `Accept: application/json`) on the database in use, until Ctrl-C (exit 130) or
    `engine serve stop`. Prints the address to open: http://127.0.0.1:8080/ by default. A
    program's page checks the program as `engine programs show` does, and shows its plot, trace
    and simulation only of a MATCH. One service runs per user: its pid file is in the engine's
    runtime folder (ENGINE_RUNTIME_DIR overrides it).

    Example: engine serve --port 8080
    """
    if ctx.invoked_subcommand is not None:
        return
    from ..db.connection import resolve_url
    from ..service import server

    with connection(ctx):   # the database is there and migrated before anything listens
        pass
    options = server.ServeOptions(resolve_url(ctx.obj["database_url"]), host, port)
    server.serve(options, click.echo)


@serve.command("stop")
def serve_stop():
    """Stop the `engine serve` running for this user (it finishes the answers under way); refused
    when none runs.

    Example: engine serve stop
    """
    from ..service.server import stop_service

    click.echo(stop_service())
