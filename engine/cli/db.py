"""Setting up and operating the database: `engine db migrate|status`, `engine db url|psql|stop`
(the embedded server), `engine db backup|restore FILE`, `engine seed [--samples]`, and
`engine demo`, which migrates and seeds the embedded server's database and instantiates one gear
(or, --turning, the sample drawing's turning job)."""
from __future__ import annotations

import os

import click

from ..errors import EngineError
from .context import connection
from .output import Column, emit_list, list_options


@click.command()
@click.option("--gear", "gear_id", default=42, show_default=True, help="Gear to instantiate (without --turning).")
@click.option("--turning", is_flag=True,
              help="Instead of a gear: import the sample lathe drawing (seed-000 convention) as a turning "
                   "job on the default lathe and instantiate it.")
@click.option("--sample-path", is_flag=True,
              help="Only print where the sample lathe drawing is, to copy it as the start of your own; "
                   "no database.")
@click.pass_context
def demo(ctx, gear_id, turning, sample_path):
    """Migrate, seed (with the samples) and instantiate one gear in the database engine_demo of
    the embedded PostgreSQL; print the program. Never on another database: --database-url and
    DATABASE_URL are ignored, and the embedded server's own database `engine` is not touched.

    With --turning, the sample lathe drawing (profile on layer 0, ROUGH, SLOT, FINISH and THREAD
    on layers 1-4, a tool-change POINT) becomes a turning job whose program is printed; stderr
    says where the drawing is, to copy it.

    Example: engine demo --gear 43

    Example: engine demo --turning
    """
    from importers.sample import sample_turning_job

    from ..paths import SAMPLE_DRAWING
    from ..programs.demo import DEMO_DATABASE, run_demo

    if sample_path:
        return click.echo(str(SAMPLE_DRAWING))
    if turning and ctx.get_parameter_source("gear_id") is click.core.ParameterSource.COMMANDLINE:
        raise EngineError("demo: --gear and --turning exclude each other: --turning instantiates the sample "
                          "drawing's turning job, not a gear; leave one out")
    if ctx.obj["database_url"]:
        click.echo("demo: --database-url/DATABASE_URL ignored: the demo writes sample data and runs only on "
                   "the embedded PostgreSQL; to load the samples into that database run `engine seed --samples`",
                   err=True)
    result = run_demo(gear_id, sample_turning_job if turning else None)
    program = result.program
    click.echo(f"demo: in the database {DEMO_DATABASE} of the embedded PostgreSQL (data in {result.data_dir}); "
               f"migrations applied: {result.applied}; {result.report}", err=True)
    if result.sample:
        say_sample(result.sample)
    click.echo(program.text, nl=False)
    click.echo(f"program {program.program_id} ({len(program.lines)} lines) from template "
               f"{program.gear_class} v{program.template_version} ({program.template_hash})", err=True)


def say_sample(sample) -> None:
    """Where the sample drawing is (to copy) and what its job holds, on stderr."""
    from ..programs.demo import operations_line

    click.echo(f"demo: sample drawing {sample.drawing} (copy it to start a drawing of your own; "
               "`engine demo --sample-path` prints just the path)", err=True)
    click.echo(f"demo: job {sample.job.job_id} on {sample.job.machine}: {operations_line(sample.job)}", err=True)


@click.group()
def db():
    """The database: apply or list the numbered SQL migrations; the URL in use, psql on it,
    stopping the embedded PostgreSQL; backing it up to a file and restoring it."""


@db.command("migrate")
@click.pass_context
def db_migrate(ctx):
    """Apply pending migrations in order, each in its own transaction.

    Example: engine db migrate
    """
    from ..db.migrate import migrate

    with connection(ctx, migrated=False) as conn:
        applied = migrate(conn)
    click.echo(f"applied {len(applied)} migration(s)" + "".join(f"\n  {m.path.name}" for m in applied))


MIGRATION_COLUMNS = (Column("state", "state"), Column("migration", "migration"), Column("applied", "applied_at"))


@db.command("status")
@list_options("migrations")
@click.pass_context
def db_status(ctx, output):
    """Show every migration: applied (when), pending, or CHANGED since applied.

    Example: engine db status
    """
    from ..db.migrate import status

    with connection(ctx, migrated=False) as conn:
        states = status(conn)
    if output:
        records = [{"migration": state.migration.path.name, "state": state.state, "applied_at": state.applied_at}
                   for state in states]
        return emit_list(output, "migrations", MIGRATION_COLUMNS, records)
    for state in states:
        when = f" {state.applied_at:%Y-%m-%d %H:%M}" if state.applied_at else ""
        click.echo(f"{state.state:8} {state.migration.path.name}{when}")


@db.command("start")
@click.option("--wal-level", type=click.Choice(["replica", "logical"]), default=None,
              help="Make this the embedded server's wal_level, restarting it if it runs with another "
                   "(logical: a head office or a plant, engine plant publish|subscribe).")
@click.pass_context
def db_start(ctx, wal_level):
    """Start the embedded PostgreSQL (if it is not running) and print its URL; with --wal-level,
    set its wal_level and restart it if needed (its sessions end; committed work is kept). Only
    the embedded server: for another server, set wal_level in its postgresql.conf and restart it.

    Example: engine db start --wal-level logical
    """
    from ..db.connection import LIBPQ_VARIABLES
    from ..db.embedded import start_embedded

    if ctx.obj["database_url"] or any(os.environ.get(name) for name in LIBPQ_VARIABLES):
        raise EngineError("db start: --database-url, DATABASE_URL or the PG* variables name another server; "
                          "engine db start starts the embedded one: set that server's wal_level in its "
                          "postgresql.conf and restart it")
    url, restarted = start_embedded(wal_level)
    click.echo(url)
    if restarted:
        click.echo(f"restarted the embedded PostgreSQL with wal_level = {wal_level}", err=True)


@db.command("url")
@click.pass_context
def db_url(ctx):
    """Print the URL of the database in use (--database-url, DATABASE_URL, the PG* variables, else
    the embedded PostgreSQL, which is started if it is not running); where it came from on stderr.

    Example: engine db url  (then psql "$(engine db url)")
    """
    from ..db.connection import url_in_use

    url, source = url_in_use(ctx.obj["database_url"])
    click.echo(url)
    click.echo(f"from {source}", err=True)


@db.command("psql", context_settings={"ignore_unknown_options": True})
@click.argument("psql_args", nargs=-1, type=click.UNPROCESSED)
@click.pass_context
def db_psql(ctx, psql_args):
    """Open psql on the database in use: the embedded package's own psql, else the one on PATH;
    further arguments go to psql. Without any psql, says which command to run.

    Example: engine db psql -c 'SELECT name, parent FROM gear_class'
    """
    from ..db.connection import psql_command

    command = psql_command(ctx.obj["database_url"], psql_args)
    os.execvp(command[0], command)


@db.command("stop")
def db_stop():
    """Stop the embedded PostgreSQL cleanly (committed work is kept), also when run as root;
    the next command that needs it starts it again.

    Example: engine db stop
    """
    from ..db.embedded import stop_embedded

    state = stop_embedded()
    if state.running:
        click.echo(f"stopped the embedded PostgreSQL (pid {state.pid}, data in {state.data_dir})")
    else:
        click.echo(f"the embedded PostgreSQL is not running (data in {state.data_dir}); nothing to stop")


@db.command("backup")
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--force", is_flag=True, help="Replace FILE if it exists (in one step, once the dump is whole).")
@click.pass_context
def db_backup(ctx, file, force):
    """Back up the database in use to FILE, in pg_dump's custom format, with the pg_dump of the
    server's major version: the embedded package's own for the embedded server, else one on PATH
    (or /usr/lib/postgresql/N/bin); none of that version is refused, naming the versions found.
    The dump is written beside FILE and takes its name only when whole.

    Example: engine db backup /srv/backup/engine-2026-11-29.dump
    """
    from pathlib import Path

    from ..db.backup import backup
    from ..db.connection import resolve_url

    done = backup(resolve_url(ctx.obj["database_url"]), Path(file), force)
    click.echo(f"backed up the database {done.database} to {done.file} ({done.size:,} bytes, "
               f"pg_dump {done.tools.version}: {done.tools.pg_dump})")


@db.command("restore")
@click.argument("file", type=click.Path(dir_okay=False))
@click.pass_context
def db_restore(ctx, file):
    """Restore a backup FILE of `engine db backup` into the database in use, which must be empty
    (a new database: CREATE DATABASE, or a fresh ENGINE_DATA_DIR for the embedded server), in one
    transaction, with the pg_restore of the server's major version. The backup's migrations must be
    this installation's, unchanged; ones it lacks are then applied by `engine db migrate`.

    Example: DATABASE_URL=postgresql://engine@dbhost/engine_restored engine db restore engine.dump
    """
    from pathlib import Path

    from ..db.backup import restore
    from ..db.connection import resolve_url

    done = restore(resolve_url(ctx.obj["database_url"]), Path(file))
    pending = f"; {done.pending} migration(s) pending: run `engine db migrate`" if done.pending else ""
    click.echo(f"restored {done.file} into the database {done.database} (pg_restore {done.tools.version}: "
               f"{done.tools.pg_restore}); its migrations match this installation's{pending}")


@click.command("seed")
@click.option("--samples", is_flag=True,
              help="Also the sample gears, hobs, machining-history cases and the golden tests on sample gears.")
@click.pass_context
def seed_command(ctx, samples):
    """Load seed_templates/ (adds only what is missing, overwrites nothing): the class tree, the
    standard code of every class (released), the machine records and the golden tests that need
    no sample gear. A shop's gears, hobs and history are its own: the samples only with --samples.

    Example: engine seed --samples
    """
    from ..library.seed import seed

    with connection(ctx) as conn:
        click.echo(str(seed(conn, samples=samples)))
