"""`engine`: the command group, its error handling, and every command registered on it; each
command calls one library function (the command modules of engine.cli).

Exit codes: 0 ok, 1 a handled error or bad input, option values included (one line on stderr),
2 unexpected (--traceback shows it).
"""
from __future__ import annotations

import click

from ..errors import EngineError
from .cases import cases, suggest
from .db import db, demo, seed_command
from .explain import explain
from .gears import classify, gears
from .hobs import hobs
from .instantiate import instantiate
from .nc_import import import_nc_command
from .refactor import refactor_command
from .templates import lint, template
from .turning import import_dxf_command, plot_command


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


COMMANDS = (demo, db, seed_command, gears, classify, instantiate, explain, template, lint, hobs, suggest, cases,
            import_nc_command, refactor_command, import_dxf_command, plot_command)


def _register(group: click.Group, commands) -> None:
    for command in commands:
        group.add_command(command)


_register(main, COMMANDS)
