"""`engine plant status`: what this database publishes and receives, how far behind each
subscription is, the replication slots kept here for its subscribers and the WAL each holds, and
warnings (docs/design.md §12: an inactive slot keeps WAL until the disk is full)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from ..db.connection import scalar
from .tables import HISTORY_PUBLICATION, ID_SEQUENCES, TEMPLATES_PUBLICATION

if TYPE_CHECKING:
    from ..db.connection import Connection

MEGABYTE = 1024 * 1024
RETAINED_WARNING = 1024 * MEGABYTE   # an active slot holding more than this is falling behind
BEHIND_WARNING_SECONDS = 300   # an active slot whose oldest unapplied change is older than this


class PublishedTable(msgspec.Struct, frozen=True):
    publication: str
    table: str
    columns: list[str] | None
    row_filter: str | None


class Subscription(msgspec.Struct, frozen=True):
    name: str
    enabled: bool
    receiving: bool              # its apply worker runs (the publisher is reachable)
    tables: dict[str, str]       # table -> state: copying, synchronised, ready …
    # since the publisher's last message, keepalives included (0 to wal_sender_timeout / 2 on an idle,
    # caught-up link): that the link lives, not a lag; the lag is measured at the publisher (Slot)
    message_age_seconds: float | None


class Slot(msgspec.Struct, frozen=True):
    name: str
    active: bool
    wal_status: str | None
    retained_bytes: int | None   # WAL kept for it (from its restart point)
    behind_bytes: int | None     # the lag: WAL its subscriber has not yet confirmed applying
    behind_seconds: float | None   # when behind: the age of the oldest change not yet applied (replay_lag)


class PlantStatus(msgspec.Struct, frozen=True):
    role: str                    # head office, plant N, or single (no replication)
    number: int
    wal_level: str
    max_slot_wal_keep_size: str
    published: list[PublishedTable]
    subscriptions: list[Subscription]
    slots: list[Slot]
    warnings: list[str]


TABLE_STATES = {"i": "initializing", "d": "copying", "f": "copied", "s": "synchronised", "r": "ready"}

PUBLISHED = """SELECT pubname, tablename, attnames::text[], rowfilter FROM pg_publication_tables
WHERE pubname = ANY(%s) ORDER BY pubname, tablename"""
SUBSCRIPTIONS = """SELECT s.subname, s.subenabled,
       EXISTS (SELECT 1 FROM pg_stat_subscription w WHERE w.subid = s.oid AND w.pid IS NOT NULL AND w.relid IS NULL),
       (SELECT extract(epoch FROM now() - max(w.last_msg_receipt_time))::float8 FROM pg_stat_subscription w
        WHERE w.subid = s.oid AND w.relid IS NULL),
       coalesce((SELECT jsonb_object_agg(r.srrelid::regclass::text, r.srsubstate) FROM pg_subscription_rel r
                 WHERE r.srsubid = s.oid), '{}')
FROM pg_subscription s WHERE s.subdbid = (SELECT oid FROM pg_database WHERE datname = current_database())
ORDER BY s.subname"""
SLOTS = """SELECT s.slot_name, s.active, s.wal_status,
       pg_wal_lsn_diff(pg_current_wal_lsn(), s.restart_lsn)::bigint,
       greatest(pg_wal_lsn_diff(pg_current_wal_lsn(), s.confirmed_flush_lsn), 0)::bigint,
       CASE WHEN pg_current_wal_lsn() > s.confirmed_flush_lsn THEN coalesce(extract(epoch FROM r.replay_lag), 0)
            ELSE 0 END::float8
FROM pg_replication_slots s LEFT JOIN pg_stat_replication r ON r.pid = s.active_pid
WHERE s.database = current_database() ORDER BY s.slot_name"""
MOVED_SEQUENCES = """SELECT s.sequencename, s.last_value, plant_first_id(plant_number()), plant_last_id(plant_number())
FROM pg_sequences s WHERE s.schemaname = current_schema() AND s.sequencename = ANY(%s)
  AND s.last_value NOT BETWEEN plant_first_id(plant_number()) AND plant_last_id(plant_number())
ORDER BY s.sequencename"""


def plant_status(conn: Connection) -> PlantStatus:
    """Read from the catalogs and statistics views; changes nothing."""
    number = int(scalar(conn.execute("SELECT plant_number()")))
    published = [PublishedTable(*row) for row in
                 conn.execute(PUBLISHED, ([TEMPLATES_PUBLICATION, HISTORY_PUBLICATION],)).fetchall()]
    subscriptions = [Subscription(name, enabled, receiving, {t: TABLE_STATES.get(s, s) for t, s in tables.items()},
                                  lag) for name, enabled, receiving, lag, tables in conn.execute(SUBSCRIPTIONS)]
    slots = [Slot(*row) for row in conn.execute(SLOTS).fetchall()]
    wal_level = scalar(conn.execute("SHOW wal_level"))
    keep = scalar(conn.execute("SHOW max_slot_wal_keep_size"))
    role = _role(number, published, subscriptions)
    return PlantStatus(role, number, wal_level, keep, published, subscriptions, slots,
                       warnings(wal_level, keep, published, subscriptions, slots) + moved_sequences(conn))


def moved_sequences(conn: Connection) -> list[str]:
    """A sequence of the rows this database makes, moved by hand out of its plant's ids (setval):
    every new row is refused (a_plant_id), whose message sends the user here."""
    return [f"sequence {name} is at {value}, outside this database's ids {first} to {last}: each new row is "
            f"refused; set it back, SELECT setval('{name}', <the largest id of the table in that range>)"
            for name, value, first, last in conn.execute(MOVED_SEQUENCES, (list(ID_SEQUENCES),))]


def _role(number: int, published: list[PublishedTable], subscriptions: list[Subscription]) -> str:
    if number > 0:
        return f"plant {number}"
    if any(table.publication == TEMPLATES_PUBLICATION for table in published) or subscriptions:
        return "head office"
    return "single (no replication)"


def warnings(wal_level: str, keep: str, published: list[PublishedTable], subscriptions: list[Subscription],
             slots: list[Slot]) -> list[str]:
    """What needs a person: each warning says what to do."""
    found = []
    if published and wal_level != "logical":
        found.append(f"wal_level is {wal_level}: nothing published is sent; set wal_level = logical and restart")
    found += [said for said in (_slot_warning(slot, keep) for slot in slots) if said]
    for subscription in subscriptions:
        if not subscription.enabled:
            found.append(f"subscription {subscription.name} is disabled: ALTER SUBSCRIPTION {subscription.name} ENABLE")
        elif not subscription.receiving:
            found.append(f"subscription {subscription.name} receives nothing: its publisher is unreachable or its "
                         "worker stopped on an error (see the server's log)")
        waiting = sorted(table for table, state in subscription.tables.items() if state != "ready")
        if waiting:
            found.append(f"subscription {subscription.name}: tables not yet copied: {', '.join(waiting)}")
    return found


def _slot_warning(slot: Slot, keep: str) -> str | None:
    held = f"{(slot.retained_bytes or 0) / MEGABYTE:.1f} MB of WAL"
    if slot.wal_status in ("lost", "unreserved"):
        return (f"slot {slot.name} is {slot.wal_status}: the WAL its subscriber needs is (about to be) removed; "
                "that subscriber must be subscribed again")
    if not slot.active:
        bound = "unbounded (max_slot_wal_keep_size = -1)" if keep == "-1" else f"up to max_slot_wal_keep_size {keep}"
        return (f"slot {slot.name} is inactive and holds {held}, {bound}: its subscriber is down or gone; if it is "
                f"gone for good, drop its subscription there or here: SELECT pg_drop_replication_slot('{slot.name}')")
    if (slot.retained_bytes or 0) > RETAINED_WARNING:
        return f"slot {slot.name} holds {held}: its subscriber is falling behind"
    if (slot.behind_seconds or 0) > BEHIND_WARNING_SECONDS:
        return (f"slot {slot.name}: its subscriber is {slot.behind_seconds:.0f} s behind ({slot.behind_bytes} bytes "
                "not yet applied): see its server's log")
    return None
