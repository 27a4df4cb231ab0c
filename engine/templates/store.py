"""A class's template in the database: loading it, listing classes, creating a class and
replacing its rows.

Rows are stored as components (bodies, shared between classes when identical) and each
class's assembly (row id, module number N, component). See design notes §4, §5.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from psycopg.types.json import Jsonb

from ..db.connection import scalar
from ..db.origin import this_plant
from ..errors import EngineError
from ..names import checked
from .rows import Template, TemplateRow
from .translations import load_translations, store_translations

if TYPE_CHECKING:
    from ..db.connection import Connection

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


def load_template(conn: Connection, gear_class: str) -> Template:
    """The class's assembled template; an error if the class does not exist or has no rows."""
    found = conn.execute(LOAD_TEMPLATE, (gear_class,)).fetchall()
    if not found:
        raise EngineError(f"gear class {gear_class!r} does not exist; see `engine template list`")
    if found[0][1] is None:
        plant = this_plant(conn)
        if plant > 0:   # issue 33: a plant receives released versions only, never the editable rows
            raise EngineError(f"gear class {gear_class!r} has no editable template rows here: this database is plant "
                              f"{plant}, which receives the head office's released versions only (see "
                              "released_template_view); templates are edited and imported at the head office")
        raise EngineError(f"gear class {gear_class!r} has no template rows; "
                          f"import them with `engine template import --class {gear_class} FILE.csv`")
    rows = tuple(TemplateRow(*row[1:]) for row in found)
    return Template(gear_class, found[0][0], rows, load_translations(conn, rows))


CLASSES = """
SELECT g.name AS class, g.parent, g.template_version, count(r.id)::int AS rows, released_version(g.name) AS released,
       g.description
FROM gear_class g LEFT JOIN assembled_row r ON r.gear_class = g.name
GROUP BY g.name ORDER BY g.name"""
# At a plant (issue 33): no editable rows and no draft counter are received, only released versions,
# so a class's version is its released one and its rows are that version's.
PLANT_CLASSES = """
SELECT g.name AS class, g.parent, released_version(g.name) AS template_version,
       coalesce(jsonb_array_length(v.rows), 0)::int AS rows, released_version(g.name) AS released, g.description
FROM gear_class g
LEFT JOIN template_version_rows v ON v.gear_class = g.name AND v.version = released_version(g.name)
ORDER BY g.name"""


def class_records(conn: Connection) -> list[dict]:
    """Every class by name: its parent, template version, row count (own and inherited), released
    version, description. At a plant, its released version's rows are all it has: its version is
    the released one."""
    from ..db.listing import records  # the listings' module: `engine template list` (issue 28: start-up)

    return records(conn.execute(PLANT_CLASSES if this_plant(conn) > 0 else CLASSES))


def ensure_class(conn: Connection, name: str, parent: str | None = None, description: str = "") -> bool:
    """Create the class if it is new; return True if created. A class name is printed in its
    programs' comments: one that is not a safe class name (engine/names.py) is refused."""
    checked("class", name, "class name")
    if parent is not None and not _class_exists(conn, parent):
        raise EngineError(f"parent class {parent!r} does not exist; create it first")
    created = conn.execute(
        "INSERT INTO gear_class (name, parent, description) VALUES (%s, %s, %s) "
        "ON CONFLICT (name) DO NOTHING RETURNING name", (name, parent, description)).fetchone()
    return created is not None


# The database's own walk down the class tree (classes_and_below): the class first, then those below it.
CLASS_AND_BELOW = "SELECT name FROM classes_and_below(ARRAY[%(class)s]) ORDER BY name <> %(class)s, name"


def class_and_descendants(conn: Connection, gear_class: str) -> list[str]:
    """The class, then every class derived from it (their templates inherit its rows)."""
    found = [row[0] for row in conn.execute(CLASS_AND_BELOW, {"class": gear_class})]
    if not found:
        raise EngineError(f"gear class {gear_class!r} does not exist; see `engine template list`")
    return found


def _class_exists(conn: Connection, name: str) -> bool:
    return conn.execute("SELECT 1 FROM gear_class WHERE name = %s", (name,)).fetchone() is not None


def replace_template(conn: Connection, gear_class: str, rows: list[TemplateRow], check=None) -> bool:
    """Make `rows` the class's template, reusing identical component bodies.

    A derived class (one whose ancestors have rows) stores only the rows that differ from
    what it inherits; inherited rows the file leaves out stay inherited. Returns True if
    anything changed; the class's version and its descendants' versions are then bumped and
    template_audit records each changed row of the class. The database does the writing
    (replace_class_template, SECURITY DEFINER), so an editor needs no rights on the library tables.
    `check(gear_class, rows)` refuses rows that could never run, before they are written (by
    default engine.templates.checks.check_rows, imported here: reading a template does not need
    it, issue 28); a caller that passes a check running in the background (engine import-nc)
    waits for its verdict before it commits."""
    if check is None:
        from .checks import check_rows as check
    with conn.transaction():
        inherited = inherited_rows(conn, gear_class)
        check(gear_class, merge_rows(inherited, rows))
        changed = scalar(conn.execute(REPLACE, (gear_class, Jsonb([_row_json(row) for row in rows]))))
        if changed:
            store_translations(conn, rows)
    return changed


_ROW_FIELDS = TemplateRow.__struct_fields__


def _row_json(row: TemplateRow) -> dict:
    """The row as replace_class_template reads it: what asdict gives for these plain fields, at a
    tenth of its cost (asdict deep-copies every value: a quarter of a long import's Python time)."""
    return {name: getattr(row, name) for name in _ROW_FIELDS}


# Locks the library in the refactor's order (engine.library.refactor.LOCK) in the database.
REPLACE = "SELECT replace_class_template(%s, %s)"


def inherited_rows(conn: Connection, gear_class: str) -> list[TemplateRow]:
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
