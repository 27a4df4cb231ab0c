"""What the nightly refactor tests read back: every class exported as CSV, the components and
bodies stored, and the reference longest-common-subsequence similarity of design notes §5."""
from __future__ import annotations

from engine.templates.store import load_template
from engine.templates.template_csv import export_csv


def exports(conn) -> dict[str, str]:
    """Every class with rows, exported as the user would: `engine template export`."""
    names = [name for (name,) in conn.execute(
        "SELECT name FROM gear_class g WHERE EXISTS (SELECT 1 FROM class_template(g.name)) ORDER BY name")]
    return {name: export_csv(load_template(conn, name)) for name in names}


def component_count(conn) -> int:
    return conn.execute("SELECT count(*) FROM component").fetchone()[0]


def bodies_stored_twice(conn) -> int:
    # GROUP BY puts NULLs together: equal groups are equal bodies, independent of the md5 key.
    return conn.execute("SELECT count(*) FROM (SELECT 1 FROM component GROUP BY t, o, p_calc, s, p_emit "
                        "HAVING count(*) > 1) d").fetchone()[0]


def duplicate_row_body(conn, gear_class: str, row_id: int) -> tuple[int, int]:
    """Store a copy of the row's component and point the row at it: (original id, copy id)."""
    original = conn.execute("SELECT component_id FROM assembly WHERE gear_class = %s AND id = %s",
                            (gear_class, row_id)).fetchone()[0]
    copy = conn.execute("INSERT INTO component (t, o, p_calc, s, p_emit) SELECT t, o, p_calc, s, p_emit "
                        "FROM component WHERE id = %s RETURNING id", (original,)).fetchone()[0]
    conn.execute("UPDATE assembly SET component_id = %s WHERE gear_class = %s AND id = %s",
                 (copy, gear_class, row_id))
    return original, copy


def lcs_sim(a, b) -> float:
    if not a and not b:
        return 1.0
    table = [[0] * (len(b) + 1) for _ in range(len(a) + 1)]
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            table[i + 1][j + 1] = table[i][j] + 1 if x == y else max(table[i][j + 1], table[i + 1][j])
    k = table[-1][-1]
    return k / (len(a) + len(b) - k)
