"""`engine`: a thin command-line shell; each command calls one library function.

Exit codes: 0 ok, 1 a handled error or bad input, option values included (one line on stderr),
2 unexpected (--traceback shows it).
"""
from __future__ import annotations

import json
from contextlib import contextmanager

import click

from ..errors import EngineError


def usage_error_line(error: click.UsageError) -> None:
    """A bad option or argument (of any command): one line naming it and the value, exit 1."""
    where = f" (see {error.ctx.command_path} --help)" if error.ctx else ""
    click.echo(f"error: {error.format_message()}{where}", err=True)
    raise click.exceptions.Exit(1)


class EngineGroup(click.Group):
    """Turns errors into one-line messages and exit codes."""

    def parse_args(self, ctx, args):
        try:
            return super().parse_args(ctx, args)
        except click.exceptions.NoArgsIsHelpError:
            raise
        except click.UsageError as error:
            usage_error_line(error)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except click.exceptions.NoArgsIsHelpError:
            raise
        except click.UsageError as error:
            usage_error_line(error)
        except (click.exceptions.Exit, click.ClickException, click.Abort):
            raise
        except EngineError as error:
            if ctx.meta.get("traceback"):
                raise
            click.echo(f"error: {error}", err=True)
            for problem in getattr(error, "problems", ()):
                click.echo(f"  {problem}", err=True)
            ctx.exit(1)
        except Exception as error:  # the promise: no stack trace without --traceback
            if ctx.meta.get("traceback"):
                raise
            first_line = (str(error).strip().splitlines() or [""])[0]
            click.echo(f"unexpected error: {type(error).__name__}: {first_line} "
                       "(run with --traceback for details)", err=True)
            ctx.exit(2)


@click.group(cls=EngineGroup)
@click.option("--database-url", envvar="DATABASE_URL", default=None,
              help="PostgreSQL URL. Default: DATABASE_URL, else libpq PG* variables, else the embedded server.")
@click.option("--traceback", is_flag=True, help="Show the full stack trace of an error.")
@click.pass_context
def main(ctx, database_url, traceback):
    """NC program template engine for gear hobbing (Siemens 840D).

    Templates live in PostgreSQL as rows (one per NC line, with the expressions that
    compute and decide it); `engine instantiate --gear ID` turns them into a program.
    """
    ctx.ensure_object(dict)
    ctx.obj["database_url"] = database_url
    ctx.meta["traceback"] = traceback


@contextmanager
def connection(ctx, migrated: bool = True):
    from ..db.connection import connect
    from ..db.migrate import require_current

    with connect(ctx.obj["database_url"]) as conn:
        if migrated:
            require_current(conn)
        yield conn


def emit_json(payload: dict) -> None:
    click.echo(json.dumps(payload, indent=2, default=str))


@main.command()
@click.option("--gear", "gear_id", default=42, show_default=True, help="Gear to instantiate.")
@click.pass_context
def demo(ctx, gear_id):
    """Migrate, seed and instantiate one gear on the embedded PostgreSQL; print the program."""
    from ..programs.instantiate import instantiate_gear
    from ..db.migrate import migrate
    from ..db.seed import seed

    with connection(ctx, migrated=False) as conn:
        applied = migrate(conn)
        report = seed(conn)
        program = instantiate_gear(conn, gear_id)
    click.echo(f"migrations applied: {len(applied)}; {report}", err=True)
    click.echo(program.text, nl=False)
    click.echo(f"program {program.program_id} ({len(program.lines)} lines) from template "
               f"{program.gear_class} v{program.template_version} ({program.template_hash})", err=True)


@main.group()
def db():
    """Database schema: apply or list the numbered SQL migrations."""


@db.command("migrate")
@click.pass_context
def db_migrate(ctx):
    """Apply pending migrations in order, each in its own transaction."""
    from ..db.migrate import migrate

    with connection(ctx, migrated=False) as conn:
        applied = migrate(conn)
    click.echo(f"applied {len(applied)} migration(s)" + "".join(f"\n  {m.path.name}" for m in applied))


@db.command("status")
@click.pass_context
def db_status(ctx):
    """Show every migration: applied (when), pending, or CHANGED since applied."""
    from ..db.migrate import status

    with connection(ctx, migrated=False) as conn:
        for state in status(conn):
            when = f" {state.applied_at:%Y-%m-%d %H:%M}" if state.applied_at else ""
            click.echo(f"{state.state:8} {state.migration.path.name}{when}")


@main.command("seed")
@click.pass_context
def seed_command(ctx):
    """Load seed_templates/: classes, standard code, machines, hobs, sample gears (adds only what is missing)."""
    from ..db.seed import seed

    with connection(ctx) as conn:
        click.echo(str(seed(conn)))


from . import commands  # noqa: E402,F401  (registers the remaining commands on `main`)
from .hobs import hobs  # noqa: E402
main.add_command(hobs)
from .cases import cases, suggest  # noqa: E402  (cutting data from the machining history)
main.add_command(suggest)
main.add_command(cases)
from .nc_import import import_nc_command  # noqa: E402
main.add_command(import_nc_command)
from .refactor import refactor_command  # noqa: E402  (also registers `template shared`)
main.add_command(refactor_command)
from .turning import import_dxf_command, plot_command  # noqa: E402  (turning jobs from DXF drawings)
main.add_command(import_dxf_command)
main.add_command(plot_command)
