"""A class's template in the database: loading it, listing classes, creating a class and
replacing its rows.

Rows are stored as components (bodies, shared between classes when identical) and each
class's assembly (row id, module number N, component). See design notes §4, §5.
"""
from __future__ import annotations

from ..errors import EngineError
from ..names import checked
from .checks import check_rows
from .rows import Template, TemplateRow
from .translations import load_translations, store_translations

# A class's rows: its own and those it inherits from its ancestors (nearest wins by id).
LOAD_ROWS = """
SELECT r.id, c.t, r.n, c.p_calc, c.s, c.o, c.p_emit
FROM class_template(%s) r JOIN component c ON c.id = r.component_id
ORDER BY r.id"""

# One statement, so version and rows come from one snapshot even while an editor or the
# nightly refactor commits.
LOAD_TEMPLATE = """
SELECT g.template_version, r.id, c.t, r.n, c.p_calc, c.s, c.o, c.p_emit
FROM gear_class g
LEFT JOIN LATERAL class_template(g.name) r ON true
LEFT JOIN component c ON c.id = r.component_id
WHERE g.name = %s ORDER BY r.id"""


def load_template(conn, gear_class: str) -> Template:
    """The class's assembled template; an error if the class does not exist or has no rows."""
    found = conn.execute(LOAD_TEMPLATE, (gear_class,)).fetchall()
    if not found:
        raise EngineError(f"gear class {gear_class!r} does not exist; see `engine template list`")
    if found[0][1] is None:
        raise EngineError(f"gear class {gear_class!r} has no template rows; "
                          f"import them with `engine template import --class {gear_class} FILE.csv`")
    rows = tuple(TemplateRow(*row[1:]) for row in found)
    return Template(gear_class, found[0][0], rows, load_translations(conn, rows))


def list_classes(conn) -> list[tuple]:
    """(name, parent, template_version, row count, description) of every class."""
    return conn.execute("""
        SELECT g.name, g.parent, g.template_version, count(r.id)::int, g.description
        FROM gear_class g LEFT JOIN assembled_row r ON r.gear_class = g.name
        GROUP BY g.name ORDER BY g.name""").fetchall()


def ensure_class(conn, name: str, parent: str | None = None, description: str = "") -> bool:
    """Create the class if it is new; return True if created. A class name is printed in its
    programs' comments: one that is not a safe class name (engine/names.py) is refused."""
    checked("class", name, "class name")
    if parent is not None and not _class_exists(conn, parent):
        raise EngineError(f"parent class {parent!r} does not exist; create it first")
    created = conn.execute(
        "INSERT INTO gear_class (name, parent, description) VALUES (%s, %s, %s) "
        "ON CONFLICT (name) DO NOTHING RETURNING name", (name, parent, description)).fetchone()
    return created is not None


def _class_exists(conn, name: str) -> bool:
    return conn.execute("SELECT 1 FROM gear_class WHERE name = %s", (name,)).fetchone() is not None


def replace_template(conn, gear_class: str, rows: list[TemplateRow], check=check_rows) -> bool:
    """Make `rows` the class's template, reusing identical component bodies.

    A derived class (one whose ancestors have rows) stores only the rows that differ from
    what it inherits; inherited rows the file leaves out stay inherited. Returns True if
    anything changed; the class's version and its descendants' versions are then bumped and
    template_audit records each changed row of the class. `check(gear_class, rows)` refuses
    rows that could never run, before they are written; a caller that passes a check running
    in the background (engine import-nc) waits for its verdict before it commits."""
    with conn.transaction():
        conn.execute(LOCK_FOR_WRITING)
        conn.execute("SELECT 1 FROM gear_class WHERE name = %s FOR UPDATE", (gear_class,))
        inherited = {row.id: row for row in inherited_rows(conn, gear_class)}
        own = [row for row in rows if inherited.get(row.id) != row]
        check(gear_class, merge_rows(inherited.values(), own))
        current = tuple(TemplateRow(*row) for row in conn.execute(OWN_ROWS, (gear_class,)))
        if current == tuple(own):
            return False
        before = conn.execute("SELECT class_rows_json(%s)::text", (gear_class,)).fetchone()[0]
        old_components = [r[0] for r in conn.execute(
            "DELETE FROM assembly WHERE gear_class = %s RETURNING component_id", (gear_class,))]
        _insert_assembly(conn, gear_class, own)
        _delete_orphans(conn, old_components)
        conn.execute(BUMP_VERSIONS, (gear_class,))
        # template_audit: one row per row of the class's assembled template that changed.
        conn.execute("SELECT audit_class_change(%s, %s::jsonb)", (gear_class, before))
        store_translations(conn, own)
    return True


# Writers take their locks on the library in the refactor's order (engine.library.refactor.LOCK), so
# a writer that started first finishes and the refactor waits for it, never a deadlock.
# ROW EXCLUSIVE: writers do not wait for each other.
LOCK_FOR_WRITING = "LOCK TABLE gear_class, component, assembly IN ROW EXCLUSIVE MODE"

OWN_ROWS = """
SELECT a.id, c.t, a.n, c.p_calc, c.s, c.o, c.p_emit
FROM assembly a JOIN component c ON c.id = a.component_id
WHERE a.gear_class = %s ORDER BY a.id"""

# The class and every class below it: their assembled templates change together.
BUMP_VERSIONS = """
WITH RECURSIVE below(name, depth) AS (
    SELECT name, 0 FROM gear_class WHERE name = %s
    UNION ALL
    SELECT g.name, b.depth + 1 FROM gear_class g JOIN below b ON g.parent = b.name WHERE b.depth < 50)
UPDATE gear_class SET template_version = template_version + 1
WHERE name IN (SELECT name FROM below)"""


def inherited_rows(conn, gear_class: str) -> list[TemplateRow]:
    """The rows the class would have with no rows of its own: its parent's assembled template."""
    parent = conn.execute("SELECT parent FROM gear_class WHERE name = %s", (gear_class,)).fetchone()
    if parent is None or parent[0] is None:
        return []
    return [TemplateRow(*row) for row in conn.execute(LOAD_ROWS, (parent[0],))]


def merge_rows(inherited, own) -> list[TemplateRow]:
    """Own rows override inherited rows with the same id; the result in id order."""
    merged = {row.id: row for row in inherited}
    merged.update((row.id, row) for row in own)
    return [merged[row_id] for row_id in sorted(merged)]


# The rows' bodies found or added a whole template at a time, in a few statements whose plans see
# all the rows (a lookup per row, from Python or in component_for, was planned for the library as
# it was before the import: a sequential scan per row once the library had grown by thousands of
# bodies). Identity of bodies as in component_for: the component_body key, then the exact columns;
# the oldest of identical bodies; each found body locked against a concurrent cleanup.
BODY_TABLE = "CREATE TEMPORARY TABLE template_body (position integer, t text, o text, p_calc text, s text, p_emit text)"
COPY_BODY_TABLE = "COPY template_body FROM STDIN"
FIND_BODIES = """
SELECT DISTINCT ON (b.position) b.position, c.id
FROM template_body b
JOIN component c ON component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit)
                    = component_body_key(b.t, b.o, b.p_calc, b.s, b.p_emit)
 AND c.t = b.t AND c.o IS NOT DISTINCT FROM b.o AND c.p_calc IS NOT DISTINCT FROM b.p_calc
 AND c.s IS NOT DISTINCT FROM b.s AND c.p_emit IS NOT DISTINCT FROM b.p_emit
ORDER BY b.position, c.id"""
LOCK_BODIES = "SELECT id FROM component WHERE id = ANY(%s) FOR KEY SHARE"
NEW_IDS = "SELECT nextval(pg_get_serial_sequence('component', 'id')) FROM generate_series(1, %s)"
COPY_BODIES = "COPY component (id, t, o, p_calc, s, p_emit) FROM STDIN"
COPY_ASSEMBLY = "COPY assembly (gear_class, id, n, component_id) FROM STDIN"


def _insert_assembly(conn, gear_class: str, rows: list[TemplateRow]) -> None:
    """The class's assembly rows, each pointing at the component holding its body (COPY: an
    imported program stores 100,000 rows)."""
    if not rows:
        return
    bodies = list(dict.fromkeys(_body(row) for row in rows))
    found = _found(conn, bodies)
    kept = {row[0] for row in conn.execute(LOCK_BODIES, (list(found.values()),))}
    ids = {bodies[position - 1]: component for position, component in found.items() if component in kept}
    missing = [body for body in bodies if body not in ids]
    if missing:
        new_ids = [row[0] for row in conn.execute(NEW_IDS, (len(missing),))]
        with conn.cursor().copy(COPY_BODIES) as copy:
            for component, body in zip(new_ids, missing):
                copy.write_row((component, *body))
        ids.update(zip(missing, new_ids))
    with conn.cursor().copy(COPY_ASSEMBLY) as copy:
        for row in rows:
            copy.write_row((gear_class, row.id, row.n, ids[_body(row)]))


def _body(row: TemplateRow) -> tuple:
    return row.t, row.o, row.p_calc, row.s, row.p_emit


def _found(conn, bodies: list[tuple]) -> dict[int, int]:
    """Position (from 1) of each body already stored → the oldest component holding it. The bodies
    go in by COPY (as arrays, psycopg quoted every text in Python: seconds for an import)."""
    conn.execute(BODY_TABLE)
    with conn.cursor().copy(COPY_BODY_TABLE) as copy:
        for position, body in enumerate(bodies, start=1):
            copy.write_row((position, *body))
    found = dict(conn.execute(FIND_BODIES).fetchall())
    conn.execute("DROP TABLE template_body")
    return found


def _delete_orphans(conn, component_ids: list[int]) -> None:
    if component_ids:
        conn.execute("DELETE FROM component c WHERE c.id = ANY(%s) AND NOT EXISTS "
                     "(SELECT 1 FROM assembly a WHERE a.component_id = c.id)", (component_ids,))
