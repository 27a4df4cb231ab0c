"""Setting up the database: `engine db migrate|status`, `engine seed`, and `engine demo`, which
does both on the embedded server and instantiates one gear."""
from __future__ import annotations

import click

from .context import connection


@click.command()
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


@click.group()
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


@click.command("seed")
@click.pass_context
def seed_command(ctx):
    """Load seed_templates/: classes, standard code, machines, hobs, sample gears (adds only what is missing)."""
    from ..db.seed import seed

    with connection(ctx) as conn:
        click.echo(str(seed(conn)))
