"""Several plants, one template authority (issue 33; docs/design.md §12): `engine plant publish` at the
head office, `engine plant subscribe --head URL --number N` at a plant, `engine plant status` on both.
The library is engine/plants/, imported when a command runs (issue 28: start-up)."""
from __future__ import annotations

import click

from ..db.origin import LAST_PLANT
from ..errors import EngineError
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
@click.option("--number", type=click.IntRange(1, LAST_PLANT), required=True,
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
@click.option("--check", is_flag=True, help="Exit 1 if there is any warning (for monitoring), after the status.")
@click.pass_context
def plant_status(ctx, as_json, check):
    """What this database publishes and receives, each subscription's tables and the age of the
    publisher's last message (keepalives included: 0 to 30 s on an idle link, not a lag), the
    replication slots kept here with the WAL each holds and its lag (bytes its subscriber has not
    yet applied, and when behind, the age of the oldest of them), and warnings (an inactive slot
    keeps WAL until the disk is full). A link's lag is measured at its publisher: run this at the
    head office for the templates its plants receive, at a plant for the history it sends.

    Exit 0, whatever the warnings; with --check, exit 1 if there is any (one line on stderr).

    Example: engine plant status --check
    """
    from ..plants.status import plant_status as read_status

    with connection(ctx) as conn:
        status = read_status(conn)
    if as_json:
        emit_json(record_dict(status))
    else:
        for line in status_lines(status):
            click.echo(line)
    if check and status.warnings:
        raise EngineError(f"engine plant status --check: {len(status.warnings)} warning(s): {status.warnings[0]}")


def _lag(slot) -> str:
    """What the slot's subscriber has not yet applied: bytes, and the age of the oldest when behind."""
    if not slot.behind_bytes:
        return "0 bytes (caught up)"
    age = f", the oldest {slot.behind_seconds:.1f} s old" if slot.behind_seconds else ""
    return f"{slot.behind_bytes} bytes of WAL not yet confirmed applied by its subscriber{age}"


def status_lines(status) -> list[str]:
    """The status as text, a heading and one line per thing."""
    lines = [f"{status.role}; wal_level {status.wal_level}, max_slot_wal_keep_size {status.max_slot_wal_keep_size}"]
    for table in status.published:
        where = f" WHERE {table.row_filter}" if table.row_filter else ""
        lines.append(f"publishes {table.publication}: {table.table}{where}")
    for sub in status.subscriptions:
        age = "none yet" if sub.message_age_seconds is None else f"{sub.message_age_seconds:.1f} s ago"
        lines.append(f"receives {sub.name}: {'receiving' if sub.receiving else 'NOT receiving'}, publisher's last "
                     f"message {age}, {sum(state == 'ready' for state in sub.tables.values())}/{len(sub.tables)} "
                     "tables ready (its lag: engine plant status at the publisher)")
    for slot in status.slots:
        held = "?" if slot.retained_bytes is None else f"{slot.retained_bytes / 1048576:.1f} MB"
        lines.append(f"slot {slot.name}: {'active' if slot.active else 'INACTIVE'}, holds {held} of WAL, "
                     f"lag {_lag(slot)}")
    lines += [f"warning: {warning}" for warning in status.warnings]
    return lines
