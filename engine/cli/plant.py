"""Several plants, one template authority (issue 33; docs/design.md §12): `engine plant publish` at the
head office, `engine plant subscribe --head URL --number N` at a plant, `engine plant status` on both.
The library is engine/plants/, imported when a command runs (issue 28: start-up)."""
from __future__ import annotations

import click

from .context import connection, emit_json, record_dict


@click.group()
def plant():
    """Plants and their head office, by PostgreSQL's logical replication: the head office publishes
    its released templates and the records they run on; each plant receives them read-only, makes
    and proves its programs itself, and publishes its history (jobs, programs, requests) back.

    Example: engine plant status
    """


@plant.command("publish")
@click.pass_context
def plant_publish(ctx):
    """At the head office: publish the released template versions (a draft is never sent, a
    retired version never deleted at a plant), their releases, the classes, golden tests,
    machines, hobs and work-holdings. Needs wal_level = logical. Run again after an upgrade.

    Example: engine plant publish
    """
    from ..plants.publishing import publish

    with connection(ctx) as conn:
        name = publish(conn)
    click.echo(f"published {name}: plants subscribe with engine plant subscribe --head URL --number N")


@plant.command("subscribe")
@click.option("--head", "head_url", required=True, help="The head office's database URL (reached from this "
              "plant's server too: its subscription connects with it).")
@click.option("--number", type=click.IntRange(1, 9999), required=True,
              help="This plant's number, unique in the group: its ids are number·10^10 to (number+1)·10^10 − 1.")
@click.option("--plant-url", default=None, help="This database's URL as the head office's server reaches it "
              "(default: the URL in use).")
@click.pass_context
def plant_subscribe(ctx, head_url, number, plant_url):
    """At a new plant (migrated, not seeded): take a plant number and its id range, receive the
    head office's released templates read-only, publish this plant's history (insert only) and
    make the head office subscribe to it. Needs wal_level = logical here. Run again, it finishes
    a setup a failure left unfinished, and changes nothing on a finished plant.

    Example: engine plant subscribe --head postgresql://engine@head.example/engine --number 3
    """
    from ..db.connection import url_in_use
    from ..plants.publishing import subscribe

    with connection(ctx) as conn:
        made = subscribe(conn, head_url, number, plant_url or url_in_use(ctx.obj["database_url"])[0])
    click.echo(f"plant {made.number}: ids {made.first_id} to {made.last_id}; receiving the templates "
               f"({made.templates_subscription}); the head office receives this plant's history "
               f"({made.history_subscription}); see engine plant status")


@plant.command("status")
@click.option("--json", "as_json", is_flag=True, help="One JSON object instead of prose.")
@click.pass_context
def plant_status(ctx, as_json):
    """What this database publishes and receives, each subscription's lag and tables, the
    replication slots kept here and the WAL each holds, and warnings (an inactive slot keeps
    WAL until the disk is full).

    Example: engine plant status --json
    """
    from ..plants.status import plant_status as read_status

    with connection(ctx) as conn:
        status = read_status(conn)
    if as_json:
        return emit_json(record_dict(status))
    for line in status_lines(status):
        click.echo(line)


def status_lines(status) -> list[str]:
    """The status as text, a heading and one line per thing."""
    lines = [f"{status.role}; wal_level {status.wal_level}, max_slot_wal_keep_size {status.max_slot_wal_keep_size}"]
    for table in status.published:
        where = f" WHERE {table.row_filter}" if table.row_filter else ""
        lines.append(f"publishes {table.publication}: {table.table}{where}")
    for sub in status.subscriptions:
        lag = "unknown" if sub.lag_seconds is None else f"{sub.lag_seconds:.1f} s"
        lines.append(f"receives {sub.name}: {'receiving' if sub.receiving else 'NOT receiving'}, lag {lag}, "
                     f"{sum(state == 'ready' for state in sub.tables.values())}/{len(sub.tables)} tables ready")
    for slot in status.slots:
        held = "?" if slot.retained_bytes is None else f"{slot.retained_bytes / 1048576:.1f} MB"
        lines.append(f"slot {slot.name}: {'active' if slot.active else 'INACTIVE'}, holds {held} of WAL, "
                     f"{slot.behind_bytes or 0} bytes not yet confirmed")
    lines += [f"warning: {warning}" for warning in status.warnings]
    return lines
