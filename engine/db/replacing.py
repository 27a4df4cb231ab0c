"""Replacing stored rows with a file's (`import --replace` of gears, hobs, work-holdings and cases,
issue 31): which fields of each stored row the file changes, said old → new, and the refusal of a
change to a row a stored job was made from.

A stored program was proved on its job's gear, hob and work-holding as their records held them
(docs/design.md §10: the screens prove it again against today's records), and a case records what
its job ran. A file that changed such a row under them would leave programs that no longer match,
or are refused, with nothing saying why; so a row a stored job refers to may be replaced by itself
only (a file exported and imported again), and a changed one takes a new id."""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from decimal import Decimal
from typing import TYPE_CHECKING, Any

import msgspec

from ..errors import EngineError

if TYPE_CHECKING:
    from .connection import Connection


class Change(msgspec.Struct, frozen=True):
    """One field of a stored row that an import with --replace changes: old → new."""

    key: Any
    field: str
    old: Any
    new: Any

    def said(self, kind: str) -> str:
        """`gear 42: module 2 → 3`."""
        return f"{kind} {self.key}: {self.field} {said(self.old)} → {said(self.new)}"


def said(value: Any) -> str:
    """A value as a change line shows it: a number as written (2, not 2.000; every digit it has),
    nothing as (none)."""
    if value is None:
        return "(none)"
    return format(value.normalize(), "f") if isinstance(value, Decimal) else str(value)


def plain(value: Any) -> Any:
    """A Decimal as the JSON number it is (whole numbers as int)."""
    if not isinstance(value, Decimal):
        return value
    return int(value) if value == value.to_integral_value() else float(value)


def changed_fields(stored: dict[Any, dict[str, Any]], rows: Iterable[dict[str, Any]], key: str,
                   names: Sequence[str]) -> list[Change]:
    """Per row of the file whose `key` is stored, per field of `names`, the stored value and the
    file's where they differ (numbers by value: 2 and 2.0 are one number)."""
    return [Change(row[key], name, stored[row[key]][name], row[name])
            for row in rows if row[key] in stored
            for name in names if stored[row[key]][name] != row[name]]


def jobs_of(conn: Connection, query: Any, keys: list[Any]) -> dict[Any, list[int]]:
    """{key: ids of the stored jobs} of a query `SELECT key, array_agg(job id) … WHERE key = ANY(%s)
    GROUP BY key`; keys no job refers to are absent."""
    return dict(conn.execute(query, (keys,)).fetchall())


MADE_FROM = "{jobs} {were} made from it"   # how stored jobs refer to a gear, hob or work-holding


def refuse_held(source: Any, kind: str, changes: list[Change], jobs: dict[Any, list[int]],
                relation: str = MADE_FROM) -> None:
    """EngineError naming the first changed row that stored jobs refer to (`relation` says how, of
    `{jobs}` and `{were}`: `job 7 was made from it`, `it records what jobs 7, 9 ran`), its jobs and its
    first change; else nothing."""
    held = [change for change in changes if change.key in jobs]
    if not held:
        return
    first = held[0]
    others = len({change.key for change in held}) - 1
    more = f" (and {others} more {kind}(s) of stored jobs)" if others else ""
    raise EngineError(f"{source}: {kind} {first.key}: the file changes its {first.field} {said(first.old)} → "
                      f"{said(first.new)}, but {_related(relation, jobs[first.key])}{more}; "
                      f"nothing imported: a stored program keeps the records it was proved on, so give the "
                      f"changed {kind} a new id")


def _related(relation: str, ids: list[int], shown: int = 5) -> str:
    """The relation said of the jobs: `job 7 was …`, `jobs 1, 2, 3, 4, 5 and 3 more were …`."""
    listed = ", ".join(map(str, ids[:shown])) + (f" and {len(ids) - shown} more" if len(ids) > shown else "")
    many = len(ids) > 1
    return relation.format(jobs=f"job{'s' * many} {listed}", were="were" if many else "was")
