"""SQL-style conditions translated once and kept in the database (table sql_translation), so that
instantiating a template whose conditions are all translated does not load sqlglot (a tenth of
a second of every command). A translation is looked up by a hash of the translator's version and
the condition's text; what is read back passes the expression gate like any expression."""
from __future__ import annotations

import functools
import hashlib
import re
from importlib.metadata import version
from typing import TYPE_CHECKING

from psycopg.errors import InsufficientPrivilege

from .guards import parse_python

if TYPE_CHECKING:
    from ..db.connection import Connection

TRANSLATOR = "sqlcond-1"   # a change of our translator's output changes this, and so every key

FIND = "SELECT sql, python FROM sql_translation WHERE text_hash = ANY(%s)"
STORE = "INSERT INTO sql_translation (text_hash, sql, python) VALUES (%s, %s, %s) ON CONFLICT DO NOTHING"


def text_hash(text: str) -> str:
    return hashlib.sha256(f"{translator()}\n{text}".encode()).hexdigest()


@functools.lru_cache(maxsize=1)
def translator() -> str:
    """Our translator's version and sqlglot's: an upgrade of either gives new keys, so no
    translation made by another version is used."""
    return f"{TRANSLATOR}/sqlglot-{version('sqlglot')}"


def expression_texts(rows) -> set[str]:
    """Every expression text of the rows that may be a condition in SQL (not `s`, which assigns)."""
    return {text for row in rows for text in (row.p_calc, row.o, row.p_emit) if text is not None}


def sql_texts(rows) -> set[str]:
    """The texts that are not Python: conditions written the way a DBA writes SQL."""
    return {text for text in expression_texts(rows) if not _is_python(text)}


def load_translations(conn: Connection, rows) -> dict[str, str]:
    """Stored translations of the rows' SQL conditions: text → Python expression."""
    texts = sql_texts(rows)
    if not texts:
        return {}
    found = conn.execute(FIND, ([text_hash(text) for text in texts],)).fetchall()
    return {sql: python for sql, python in found if sql in texts}


def store_translations(conn: Connection, rows) -> int:
    """Translate the rows' SQL conditions that have no stored translation and keep them; a role
    that may not write them (runners) leaves them to be translated when used. The number stored."""
    from .expressions import translated_python

    missing = sql_texts(rows) - set(load_translations(conn, rows))
    made = [(text_hash(text), text, translated_python(text)) for text in sorted(missing)]
    made = [row for row in made if row[2] is not None]
    if not made:
        return 0
    try:
        with conn.transaction(), conn.cursor() as cursor:
            cursor.executemany(STORE, made)
    except InsufficientPrivilege:
        return 0
    return len(made)


# A text in quotes with no quote or backslash inside, f-string or not: a written NC line (most
# rows of an imported program). Python parses it first whatever it means in SQL, so it is never
# a SQL condition, and needs no parse to say so (nor does one the f-string parser would refuse:
# it is refused as Python and as SQL).
_QUOTED = re.compile(r"""f?"[^"\\\n]*"|f?'[^'\\\n]*'""")


def _is_python(text: str) -> bool:
    if _QUOTED.fullmatch(text.strip()):
        return True
    try:
        parse_python(text.strip())
    except (SyntaxError, RecursionError, MemoryError, ValueError):
        return False
    return True
