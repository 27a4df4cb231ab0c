"""`engine serve` and `engine serve stop`: the shop floor's side of the engine (issue 32), run
from the command line. The service's modules (engine.service: starlette, uvicorn, jinja2) are
imported inside the commands, so no other command pays for them (issue 28: start-up)."""
from __future__ import annotations

import click

from .context import connection, settings

PORT = click.IntRange(1, 65535)
DEFAULT_PORT = 8080


@click.group("serve", invoke_without_command=True)
@click.option("--host", default="127.0.0.1", show_default=True,
              help="Address to listen on. Any address but loopback (127.0.0.1, ::1, localhost) asks "
                   "every visitor for a PostgreSQL login first.")
@click.option("--port", type=PORT, default=DEFAULT_PORT, show_default=True, help="Port of the web view.")
@click.option("--ftp-port", type=PORT, help="Also serve the machines by FTP on this port (2121, say): each "
              "machine logs in with its name and the secret in ENGINE_FTP_SECRET_<MACHINE> (or the variable its "
              "config table's ftp_secret_env names), lists its programs and fetches each proved at that moment.")
@click.option("--ftp-host", help="Address of the FTP server (default: --host's): the controls' network.")
@click.option("--requests", "requests", type=click.Path(file_okay=False), help="Also answer request files in "
              "ROOT/<machine>/ (an 840D writes NAME.REQ holding `JOB 17` and waits for NAME.RDY or NAME.ERR).")
@click.option("--request-machine", "request_machines", multiple=True, metavar="MACHINE",
              help="With --requests: a machine whose folder is answered (repeat it; default: every machine).")
@click.pass_context
def serve(ctx, host, port, ftp_port, ftp_host, requests, request_machines):
    """Serve the web view of gears, jobs and programs (each page also as JSON with
    `Accept: application/json`) on the database in use, until Ctrl-C (exit 130) or
    `engine serve stop`. Prints the address to open: http://127.0.0.1:8080/ by default. A
    program's page checks the program as `engine programs show` does, and shows its plot, trace
    and simulation only of a MATCH. One service runs per user: its pid file is in the engine's
    runtime folder (ENGINE_RUNTIME_DIR overrides it).

    With --ftp-port and --requests it also delivers programs to the controls: a machine's program
    is made from the released version, proved (verifier and simulation) and recorded when the
    machine asks for it; what cannot be proved is refused with its reason, and recorded.

    Example: engine serve --port 8080 --ftp-port 2121 --requests /srv/nc-requests
    """
    if ctx.invoked_subcommand is not None:
        return
    from ..db.connection import resolve_url
    from ..errors import EngineError
    from ..service import server

    if request_machines and requests is None:
        raise EngineError("--request-machine names a machine whose request folder is answered: give --requests "
                          "ROOT too")
    if ftp_host is not None and ftp_port is None:
        raise EngineError("--ftp-host is where the FTP server listens: give --ftp-port too")
    with connection(ctx) as conn:   # the database is there and migrated before anything listens
        machines = tuple(request_machines) or _every_machine(conn) if requests is not None else ()
    options = server.ServeOptions(resolve_url(ctx.obj["database_url"]), host, port, ftp_host, ftp_port, requests,
                                  machines, settings(ctx))
    server.serve(options, click.echo)


def _every_machine(conn) -> tuple[str, ...]:
    return tuple(row[0] for row in conn.execute("SELECT name FROM machine ORDER BY name"))


@serve.command("stop")
def serve_stop():
    """Stop the `engine serve` running for this user (it finishes the answers under way); refused
    when none runs.

    Example: engine serve stop
    """
    from ..service.server import stop_service

    click.echo(stop_service())
