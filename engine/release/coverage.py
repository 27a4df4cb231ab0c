"""Template coverage (`engine test --coverage`): the rows of each class's current template that
neither a golden test nor a program stored lately emitted or ran. A row nothing exercises is
a row a change could break unnoticed: a DBA adds a test that reaches it, or retires it."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from ..templates.versions import draft_template
from .golden import run_golden_tests

if TYPE_CHECKING:
    from ..db.connection import Connection

# Rows that the class's programs stored in the last N days emitted (row_ids) or ran (the trace).
PROGRAM_ROWS = """
SELECT DISTINCT r FROM program p CROSS JOIN LATERAL unnest(p.row_ids) AS r
WHERE p.gear_class = %(class)s AND p.created_at >= now() - make_interval(days => %(days)s)
UNION
SELECT DISTINCT (e ->> 'row')::integer FROM program p
CROSS JOIN LATERAL jsonb_array_elements(CASE WHEN jsonb_typeof(p.trace -> 'rows') = 'array'
                                             THEN p.trace -> 'rows' ELSE '[]' END) AS e
WHERE p.gear_class = %(class)s AND p.created_at >= now() - make_interval(days => %(days)s)
  AND (e -> 'calc' = 'true' OR e -> 'emit' = 'true')"""
CLASSES_WITH_ROWS = "SELECT DISTINCT gear_class FROM assembly ORDER BY gear_class"


class UncoveredRow(msgspec.Struct, frozen=True):
    gear_class: str
    row_id: int
    t: str
    o: str | None

    def as_dict(self) -> dict:
        return {"class": self.gear_class, "row": self.row_id, "t": self.t, "o": self.o}


def coverage(conn: Connection, days: int = 30, classes: list[str] | None = None) -> list[UncoveredRow]:
    """The current rows of each class (all classes with rows if None) that no golden test and no
    program of the class stored in the last `days` days emitted or ran."""
    if days < 0:
        raise EngineError(f"--days {days}: give a number of days, 0 or more")
    chosen = classes if classes is not None else [row[0] for row in conn.execute(CLASSES_WITH_ROWS)]
    tested = _tested_rows(run_golden_tests(conn, chosen, draft=True))
    return [row for gear_class in chosen for row in _uncovered(conn, gear_class, days, tested.get(gear_class, set()))]


def _tested_rows(results) -> dict[str, set[int]]:
    rows: dict[str, set[int]] = {}
    for result in results:
        rows.setdefault(result.gear_class, set()).update(result.row_ids, result.ran_rows)
    return rows


def _uncovered(conn: Connection, gear_class: str, days: int, tested: set[int]) -> list[UncoveredRow]:
    template = draft_template(conn, gear_class)
    stored = {row[0] for row in conn.execute(PROGRAM_ROWS, {"class": gear_class, "days": days})}
    covered = tested | stored
    return [UncoveredRow(gear_class, row.id, row.t, row.o) for row in template.rows if row.id not in covered]
