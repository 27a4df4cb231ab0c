"""Template versions of a class: history, diff between two versions, restore of one.

Every committed version's assembled rows are in template_version_rows (written at commit by
the trigger template_rows_match_version); template_audit says which rows each version changed; each version
also records the layout its programs are written with (line ending, final newline).
"""
from __future__ import annotations

from datetime import datetime
from typing import TYPE_CHECKING

import msgspec

from ..db.connection import scalar
from ..errors import EngineError
from ..nc.layout import NcLayout, class_layout, store_layout
from .rows import CSV_COLUMNS, TemplateRow
from .store import replace_template

if TYPE_CHECKING:
    from ..db.connection import Connection


class VersionEntry(msgspec.Struct, frozen=True):
    version: int
    created_at: datetime
    created_by: str
    rows: int
    changes: tuple[tuple[int, str], ...]   # (row id, INSERT/UPDATE/DELETE) from template_audit
    state: str = ""                        # released, retired, draft, superseded (template_version_state)
    release: ReleaseEntry | None = None  # the release of this version, if it was released
    layout: NcLayout = NcLayout()          # the line ending and final newline its programs are written with


class ReleaseEntry(msgspec.Struct, frozen=True):
    """Who released a version, when, how, and what the releasing session states the gate saw:
    tests run, programs changed of jobs (claims: engine.release.recheck says what is true)."""
    version: int
    released_at: datetime
    released_by: str
    role: str
    tests: int                       # golden tests the caller of release_template states it ran
    changed: int | None
    jobs: int | None
    note: str | None
    released_via: str = "sql"        # engine, seed, sql (by hand), unrecorded: what the caller said
    golden_tests: list | None = None  # the golden tests the database recorded with the release
    failed: int | None = None        # stored jobs the session states the released version failed for
    without_tests: bool = False      # the releasing session accepted releasing with no golden test


class RowChange(msgspec.Struct, frozen=True):
    row_id: int
    kind: str            # added, removed, changed
    old: dict | None     # the row in the first version (None: added)
    new: dict | None     # the row in the second version (None: removed)

    @property
    def columns(self) -> list[str]:
        """The columns whose values differ (every column for an added or removed row)."""
        return [column for column in CSV_COLUMNS if (self.old or {}).get(column) != (self.new or {}).get(column)]


# Each stored version with the audit rows written since the version stored before it
# (several bumps in one transaction store only the committed one).
HISTORY = """
WITH versions AS (
    SELECT version, created_at, created_by, jsonb_array_length(rows) AS row_count, line_ending, final_newline,
           lag(version, 1, -1) OVER (ORDER BY version) AS previous
    FROM template_version_rows WHERE gear_class = %(class)s)
SELECT v.version, v.created_at, v.created_by, v.row_count, v.line_ending, v.final_newline,
       coalesce(array_agg(a.row_id ORDER BY a.id) FILTER (WHERE a.id IS NOT NULL), '{}'),
       coalesce(array_agg(a.operation ORDER BY a.id) FILTER (WHERE a.id IS NOT NULL), '{}')
FROM versions v
LEFT JOIN template_audit a ON a.gear_class = %(class)s
     AND a.template_version > v.previous AND a.template_version <= v.version
GROUP BY v.version, v.created_at, v.created_by, v.row_count, v.line_ending, v.final_newline
ORDER BY v.version"""


# The checks key of a release accepted with no golden test (engine template release --without-golden-tests).
WITHOUT_TESTS = "accepted_without_golden_tests"
STATES = "SELECT version, state FROM template_version_state WHERE gear_class = %s"
RELEASES = """
SELECT version, released_at, released_by, role, jsonb_array_length(tests), (impact ->> 'changed')::int,
       (impact ->> 'jobs')::int, note, released_via, golden_tests, (impact ->> 'failed')::int,
       coalesce((checks ->> %s)::boolean, false)
FROM template_release WHERE gear_class = %s"""


def history(conn: Connection, gear_class: str) -> list[VersionEntry]:
    """Every stored version of the class, oldest first, with who made it, which rows changed, its
    state (released, retired, draft, superseded) and its release."""
    _require_class(conn, gear_class)
    states: dict[int, str] = dict(conn.execute(STATES, (gear_class,)).fetchall())   # version -> state
    releases = {row[0]: ReleaseEntry(*row) for row in conn.execute(RELEASES, (WITHOUT_TESTS, gear_class))}
    return [VersionEntry(version, created_at, created_by, row_count, tuple(zip(row_ids, operations)),
                         states.get(version, ""), releases.get(version), NcLayout(line_ending, final_newline))
            for version, created_at, created_by, row_count, line_ending, final_newline, row_ids, operations
            in conn.execute(HISTORY, {"class": gear_class})]


def diff(conn: Connection, gear_class: str, from_version: int, to_version: int) -> list[RowChange]:
    """Rows added, removed or changed from one version to the other, in row id order."""
    old = {row["id"]: row for row in version_rows_json(conn, gear_class, from_version)}
    new = {row["id"]: row for row in version_rows_json(conn, gear_class, to_version)}
    return [_row_change(row_id, old.get(row_id), new.get(row_id))
            for row_id in sorted(old.keys() | new.keys()) if old.get(row_id) != new.get(row_id)]


def layout_change(conn: Connection, gear_class: str, from_version: int, to_version: int) -> tuple[NcLayout,
                                                                                                  NcLayout] | None:
    """The layouts of the two versions if they differ (the bytes of their programs do), else None."""
    old, new = (class_layout(conn, gear_class, version) for version in (from_version, to_version))
    return None if old == new else (old, new)


def _row_change(row_id: int, old: dict | None, new: dict | None) -> RowChange:
    kind = "added" if old is None else "removed" if new is None else "changed"
    return RowChange(row_id, kind, old, new)


def restore(conn: Connection, gear_class: str, version: int) -> tuple[bool, int]:
    """Make the class's template what it was in `version`, its rows and its layout, as a new
    version (history stays append-only). Returns (changed, the class's version now); unchanged if identical.

    The stored rows are the assembled template; replace_template keeps as the class's own
    rows only those that differ from what it inherits now."""
    with conn.transaction():
        rows = [TemplateRow(**row) for row in version_rows_json(conn, gear_class, version)]
        if not rows:
            raise EngineError(f"class {gear_class!r} version {version} has no template rows; nothing to restore")
        changed = replace_template(conn, gear_class, rows)
        changed = store_layout(conn, gear_class, class_layout(conn, gear_class, version)) or changed
        current = scalar(conn.execute("SELECT template_version FROM gear_class WHERE name = %s", (gear_class,)))
    return changed, current


def version_rows_json(conn: Connection, gear_class: str, version: int) -> list[dict]:
    """The class's assembled rows in `version`; an error naming the stored versions if absent."""
    found = conn.execute("SELECT rows FROM template_version_rows WHERE gear_class = %s AND version = %s",
                         (gear_class, version)).fetchone()
    if found is None:
        _require_class(conn, gear_class)
        raise EngineError(f"class {gear_class!r} has no version {version}; "
                          f"stored versions: {_version_list(conn, gear_class)}")
    return found[0]


def _version_list(conn: Connection, gear_class: str) -> str:
    versions = [row[0] for row in conn.execute(
        "SELECT version FROM template_version_rows WHERE gear_class = %s ORDER BY version", (gear_class,))]
    return ", ".join(map(str, versions)) or "none"


def _require_class(conn: Connection, gear_class: str) -> None:
    if conn.execute("SELECT 1 FROM gear_class WHERE name = %s", (gear_class,)).fetchone() is None:
        raise EngineError(f"gear class {gear_class!r} does not exist; see `engine template list`")
