"""`engine`: the command group, its error handling, and every command registered on it; each
command calls one library function (the command modules of engine.cli).

Exit codes: 0 ok, 1 a handled error or bad input, option values included (one line on stderr;
with --json one JSON object {"error": ..., "exit": 1}): nothing stored,
2 unexpected (--traceback shows it),
3 programs stored but their files not written (engine.programs.outputs.StoredNotWritten: the
message names the programs and the files; "exit": 3 with --json),
130 interrupted (Ctrl-C, SIGINT: 128 + 2, as shells report it): one line, what was not yet
committed rolled back (issue 31: a batch's workers end with it, quietly).
"""
from __future__ import annotations

import io
import json
import logging
import os
import sys
import traceback
import unicodedata

import click

from ..errors import EngineError
from ..memory import command_collection
from .commands import COMMAND_MODULES, LazyCommands
from .context import CONFIG
from .conventions import JSON_SEEN, apply_conventions, apply_to_one, default_map, json_from_defaults

JSON_ARGS = "engine.json_args"   # ctx.meta: --json among the invocation's arguments
INTERRUPTED = 130   # the exit code of Ctrl-C: 128 + SIGINT, what a shell shows for a command it interrupted


def usage_error_line(error: click.UsageError) -> None:
    """A bad option or argument (of any command): one line naming it and the value, exit 1; JSON
    also when the command's --json is on by the environment or the config file."""
    where = f" (see {error.ctx.command_path} --help)" if error.ctx else ""
    as_json = json_mode(click.get_current_context(silent=True)) or bool(error.ctx and json_from_defaults(error.ctx))
    fail(f"{error.format_message()}{where}", 1, as_json=as_json)


def one_line(text: str) -> str:
    """The text with its control characters and line breaks escaped as repr escapes them (a
    newline as \\n): an error naming a value typed with a newline or an escape sequence stays one
    line, and a terminal shows the characters instead of obeying them."""
    return "".join(repr(char)[1:-1] if unicodedata.category(char) in LINE_BREAKING else char for char in text)


LINE_BREAKING = ("Cc", "Zl", "Zp")   # Unicode categories: control characters, line and paragraph separators


def fail(message: str, code: int, problems=(), prefix: str = "error: ", as_json: bool | None = None) -> None:
    """The one line on stderr and the exit code; with --json the same as one JSON object,
    {"error": ..., "exit": code} (and "problems" when the error lists them)."""
    if as_json is None:
        as_json = json_mode(click.get_current_context(silent=True))
    message, problems = one_line(message), [one_line(str(problem)) for problem in problems]
    if as_json:
        click.echo(json.dumps({"error": message, "exit": code, **({"problems": list(problems)} if problems else {})},
                              default=str), err=True)
        raise click.exceptions.Exit(code)
    click.echo(f"{prefix}{message}", err=True)
    for problem in problems:
        click.echo(f"  {problem}", err=True)
    raise click.exceptions.Exit(code)


def json_mode(ctx) -> bool:
    """The invocation asked for JSON: its command's --json is on, or --json is among its arguments."""
    return ctx is not None and bool(ctx.meta.get(JSON_SEEN) or ctx.meta.get(JSON_ARGS))


def wants_json(args: list[str]) -> bool:
    """--json among the arguments (before a `--`): known before any option is parsed, so a
    usage error of a --json invocation is JSON too."""
    return "--json" in (args[:args.index("--")] if "--" in args else args)


class EngineGroup(click.Group):
    """Reads the config file, turns errors into one-line messages (JSON with --json) and exit codes."""

    def main(self, *args, **extra):
        """The command, with the cycle collector as a command wants it (engine.memory.command_collection)."""
        with command_collection():
            return super().main(*args, **extra)

    def make_context(self, info_name, args, parent=None, **extra):
        """The config file's option defaults (engine.programs.config) are the context's default_map."""
        config, defaults = _read_config(self, args, extra.get("resilient_parsing", False))
        extra.setdefault("default_map", defaults)
        ctx = super().make_context(info_name, args, parent, **extra)
        ctx.meta[CONFIG] = config
        return ctx

    def format_commands(self, ctx, formatter):
        """click's list of commands, each command's short help from engine.cli.short_help where it
        is not imported yet: `engine --help` imports no command module (issue 12's start-up)."""
        if not isinstance(self.commands, LazyCommands):   # a group whose commands are all imported
            return super().format_commands(ctx, formatter)
        names = [name for name in self.list_commands(ctx) if not _hidden(self.commands, name)]
        if names:
            limit = formatter.width - 6 - max(map(len, names))   # click's: three times the default spacing
            with formatter.section("Commands"):
                formatter.write_dl([(name, _short_help(self.commands, name, limit)) for name in names])

    def parse_args(self, ctx, args):
        ctx.meta[JSON_ARGS] = wants_json(args)
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
        except (click.exceptions.Exit, click.Abort):
            raise
        except click.ClickException as error:   # one line too (a file click could not open, …)
            fail(error.format_message(), error.exit_code)
        except EngineError as error:
            if ctx.meta.get("traceback"):
                raise
            fail(str(error), error.exit_code, getattr(error, "problems", ()))
        except KeyboardInterrupt:   # Ctrl-C: one line, not click's "Aborted!" with exit 1 (which says refused)
            fail("interrupted (Ctrl-C); what was not yet committed was rolled back", INTERRUPTED)
        except BrokenPipeError:   # the reader left (engine … | head): it has what it wanted, no message
            _silence_stdout()
            ctx.exit(1)
        except Exception as error:  # the promise: no stack trace without --traceback
            if ctx.meta.get("traceback"):
                raise
            first_line = (str(error).strip().splitlines() or [""])[0]
            if _refused_by_role(error):   # a role without the right: a handled refusal, nothing was stored
                from .refusals import refusal_line  # on a refusal only: start-up loads no more (issue 28)
                fail(refusal_line(first_line), 1)
            if _read_only_here(error):   # a plant's copy of the head office's tables (issue 33)
                fail(f"{first_line}; nothing stored", 1)
            if _database_failure(error):   # the server, not the engine: exit 1, and say what was kept
                fail(_database_failure_message(error, first_line), 1)
            fail(f"unexpected error: {type(error).__name__}: {first_line} (run with --traceback for details)", 2,
                 prefix="")


def _hidden(commands: LazyCommands, name: str) -> bool:
    return name in commands.imported() and commands[name].hidden


def _short_help(commands: LazyCommands, name: str, limit: int) -> str:
    """The command's short help shortened to `limit` characters: click shortens it (a stand-in
    command of that help, where the command is not imported)."""
    from .short_help import SHORT_HELP  # the listing's only: a command's own start-up loads none of it

    if name in commands.imported() or name not in SHORT_HELP:
        return commands[name].get_short_help_str(limit)
    return click.Command(name, help=SHORT_HELP[name]).get_short_help_str(limit)


def _silence_stdout() -> None:
    """Python flushes stdout again at exit, which would fail on the closed pipe a second time
    (the recipe of the Python docs, 'Note on SIGPIPE')."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError, io.UnsupportedOperation):   # not a real file (a test runner's buffer)
        pass


def _read_config(group: click.Group, args: list[str], completing: bool):
    """The config file (engine.programs.config) and its option defaults; a malformed file (an unknown
    command or option too) ends the command with one line naming it (JSON with --json), exit 1,
    except while the shell completes a word (then no file)."""
    from ..programs.config import load_config

    try:
        config = load_config()
        return config, default_map(group, config)
    except EngineError as error:
        if not completing:
            fail(str(error), 1, as_json=wants_json(list(args)))
        return None, None


def _refused_by_role(error: Exception) -> bool:
    """The server refused a statement for the session's role (SQLSTATE 42501)."""
    psycopg = sys.modules.get("psycopg")
    return psycopg is not None and isinstance(error, psycopg.errors.InsufficientPrivilege)


def _read_only_here(error: Exception) -> bool:
    """A plant refused a write to the head office's tables (refuse_at_a_plant, which names itself
    head_office_writes_it: schema/schema.sql, section plants), or a row's id outside this database's
    plant range (a_plant_id: a sequence moved by hand): bad state, not a bug. Any other read-only
    refusal (a READ ONLY transaction, a standby) is a write the command should not have tried: exit 2
    (tests/test_read_only_database.py)."""
    psycopg = sys.modules.get("psycopg")
    if psycopg is None:
        return False
    named = getattr(getattr(error, "diag", None), "constraint_name", None)
    return (isinstance(error, psycopg.errors.ReadOnlySqlTransaction) and named == "head_office_writes_it") or (
        isinstance(error, psycopg.errors.CheckViolation) and named == "a_plant_id")


def _database_failure(error: Exception) -> bool:
    """The server ended the work: the connection lost or terminated (pg_terminate_backend, a
    restart), a statement cancelled, a deadlock, the disk full. psycopg is only looked at if
    the command loaded it (`engine --help` does not)."""
    psycopg = sys.modules.get("psycopg")
    return psycopg is not None and isinstance(error, psycopg.OperationalError)


def _database_failure_message(error: Exception, first_line: str) -> str:
    """What the user must know: whether anything was stored. A transaction the server ended
    before COMMIT stored nothing; one lost during its COMMIT may or may not have been stored."""
    committing = any(frame.f_code.co_name == "_commit_gen" for frame, _ in traceback.walk_tb(error.__traceback__))
    if committing:
        return (f"the database connection failed while committing ({first_line}); whether the work was stored "
                "is unknown: check (e.g. engine template history, the program table) before running it again")
    return (f"the database ended the command ({first_line}); its transaction was rolled back, nothing of it "
            "was stored: run the command again when the server is back")


@click.group(cls=EngineGroup)
@click.option("--database-url", envvar="DATABASE_URL", default=None,
              help="PostgreSQL URL. Default: DATABASE_URL, else libpq PG* variables, else the embedded server.")
@click.option("--traceback", is_flag=True, help="Show the full stack trace of an error.")
@click.version_option(package_name="nc-template-engine", message="%(package)s %(version)s")
@click.pass_context
def main(ctx, database_url, traceback):
    """NC program template engine for gear hobbing (Siemens 840D and Fanuc) and turning.

    Templates live in PostgreSQL as rows (one per NC line, with the expressions that
    compute and decide it); `engine instantiate --gear ID` turns them into a program.
    """
    ctx.ensure_object(dict)
    ctx.obj["database_url"] = database_url
    ctx.meta["traceback"] = traceback
    if not traceback:   # psycopg logs what it ignores while a lost connection unwinds; the error says it
        logging.getLogger("psycopg").addHandler(logging.NullHandler())


def _given_conventions(name: str, command: click.Command) -> None:
    apply_conventions(command, f"engine {name}")


# each command imported as it is first looked up (engine.cli.commands), with the conventions
# (environment variables, examples in --help, --json errors: engine.cli.conventions)
main.commands = LazyCommands(COMMAND_MODULES, _given_conventions)
apply_to_one("engine", main)
