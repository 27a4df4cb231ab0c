"""Near-duplicate pairs a person has judged (issue 16): the nightly refactor remembers which
pairs it reported (new ones are listed first) and leaves out the pairs marked intended, whose
marks say who, why and when (near_duplicate_intended, schema/schema.sql).

A pair's identity is its module type and its two line texts, in either order. Not component
ids: the refactor merges copies into the lowest id and deletes the rest, and an edit through
template_view copies a shared body into a new component, so ids change while the lines a person
looked at stay the same. Not the whole body: similarity is measured on the line text alone
(two rows with the same text and different conditions are one text in the report), so a
judgement about two texts holds for every row that has them. The module type belongs to it:
texts are compared within one type only, and a decision about two sync lines says nothing about
the same texts in another module. The order is not: (a, b) and (b, a) are one pair, the texts
sorted by code point (not by a database collation, which varies between servers).

Block numbers are not part of it (issue 17): a text is keyed by its line without the block
number it starts with (engine.library.similarity.block_free), so `N0380 G1 X10` against `N0400
G1 X11` is the pair `G1 X10`/`G1 X11`, and the lines that differ only in their block number are one
family, keyed by their common line whatever members join it later. Its a and b in the tables
are two of its members. A text without a block number keeps the key it always had.

Marks and seen pairs stored before that carry the key of their full texts, block numbers
included. Every row holds its texts (t, a, b), so a row is keyed again as it is read, the way
this version keys them: a mark keeps working, and keeps who made it, when and why, and the key
it was made under (`engine refactor unintend` takes it). Nothing is rewritten.
"""
from __future__ import annotations

import hashlib
import json
import re
from datetime import datetime
from typing import TYPE_CHECKING

import msgspec
import psycopg

from ..errors import EngineError
from .similarity import block_free

if TYPE_CHECKING:
    from ..db.connection import Connection

KEY_SHOWN = 12      # hex digits of the key the report prints: unique among millions of pairs
KEY_TYPED = 8       # the fewest hex digits `engine refactor intend KEY` accepts
HEX = re.compile(r"^[0-9a-f]+$")


def pair_key(t: str, a: str, b: str) -> str:
    """The pair's full key: sha256 of [t, the two texts sorted] as JSON (unambiguous whatever
    the texts hold)."""
    identity = json.dumps([t, *sorted((a, b))], ensure_ascii=True)
    return hashlib.sha256(identity.encode("ascii")).hexdigest()


def family_key(t: str, line: str) -> str:
    """The key of the family of texts whose line without block number is `line`: sha256 of
    [t, line] as JSON (two elements: never a pair's key)."""
    identity = json.dumps([t, line], ensure_ascii=True)
    return hashlib.sha256(identity.encode("ascii")).hexdigest()


def near_duplicate_key(t: str, a: str, b: str) -> str:
    """The key of what two texts are, their block numbers left out: one family, or a pair."""
    line_a, line_b = block_free(a), block_free(b)
    return family_key(t, line_a) if line_a == line_b else pair_key(t, line_a, line_b)


def shown_key(full_key: str) -> str:
    return full_key[:KEY_SHOWN]


# --- what a refactor run reports --------------------------------------------------------------

# Rows as stored, keyed again by near_duplicate_key as they are read. A seen row's a is one of the
# texts it was listed with, whatever version stored it; marks are people's, few: all of them.
MARKS_IN_FORCE = "SELECT pair_key, t, a, b FROM near_duplicate_intended WHERE withdrawn_at IS NULL"
SEEN_AMONG = "SELECT pair_key, t, a, b FROM near_duplicate_seen WHERE a = ANY(%s)"
REMEMBER_SEEN = """
INSERT INTO near_duplicate_seen (pair_key, t, a, b)
SELECT * FROM unnest(%s::text[], %s::text[], %s::text[], %s::text[])
ON CONFLICT (pair_key) DO UPDATE SET last_seen = excluded.last_seen"""


class Listed(msgspec.Struct, frozen=True):
    """The pairs a run lists (new first) and how many it found of each kind."""
    pairs: list[dict]
    new: int
    known: int
    intended: int


def list_and_remember(conn: Connection, pairs: list[dict]) -> Listed:
    """Leave out the pairs marked intended, flag each other pair `new` (no earlier run listed
    it), put the new ones first (each part in its given order), and remember them all as seen."""
    full = {id(pair): near_duplicate_key(pair["t"], pair["a"], pair["b"]) for pair in pairs}
    keys = list(full.values())
    intended = set(marks_in_force(conn)).intersection(keys)
    seen = set(rekeyed(conn.execute(SEEN_AMONG, (listed_texts(pairs),)))).intersection(keys)
    listed = [dict(pair, key=shown_key(full[id(pair)]), new=full[id(pair)] not in seen)
              for pair in pairs if full[id(pair)] not in intended]
    listed.sort(key=lambda pair: not pair["new"])   # stable: the order within each part is kept
    _remember(conn, [(full[id(pair)], pair) for pair in pairs if full[id(pair)] not in intended])
    new = sum(pair["new"] for pair in listed)
    return Listed(listed, new, len(listed) - new, len(pairs) - len(listed))


def listed_texts(pairs: list[dict]) -> list[str]:
    """Every text the pairs list: both sides, each family's members."""
    return sorted({text for pair in pairs
                   for text in (pair.get("members") or pair["members_a"] + pair["members_b"])})


def marks_in_force(conn: Connection) -> dict[str, str]:
    """The marks in force: the key this version computes for the texts → the key stored."""
    return rekeyed(conn.execute(MARKS_IN_FORCE))


def rekeyed(rows) -> dict[str, str]:
    """(stored key, t, a, b) rows → {key of (t, a, b) as near_duplicate_key computes it: stored key}."""
    return {near_duplicate_key(t, a, b): stored for stored, t, a, b in rows}


def _remember(conn: Connection, keyed: list[tuple[str, dict]]) -> None:
    columns = ([key for key, _ in keyed], [pair["t"] for _, pair in keyed],
               [pair["a"] for _, pair in keyed], [pair["b"] for _, pair in keyed])
    conn.execute(REMEMBER_SEEN, columns)


# --- marks -------------------------------------------------------------------------------------

class Intent(msgspec.Struct, frozen=True):
    key: str
    t: str
    a: str
    b: str
    why: str
    marked_by: str
    marked_role: str
    marked_at: datetime

    def as_dict(self) -> dict:
        return {"key": self.key, "t": self.t, "a": self.a, "b": self.b, "why": self.why,
                "marked_by": self.marked_by, "marked_role": self.marked_role,
                "marked_at": self.marked_at.isoformat(timespec="seconds")}


INTENTS = """
SELECT pair_key, t, a, b, why, marked_by, marked_role, marked_at FROM near_duplicate_intended
WHERE withdrawn_at IS NULL ORDER BY marked_at, id"""
SEEN_BY_PREFIX = "SELECT pair_key, t, a, b FROM near_duplicate_seen WHERE left(pair_key, %s) = %s"
INTENT_BY_PREFIX = """
SELECT pair_key, t, a, b, why, marked_by, marked_role, marked_at FROM near_duplicate_intended
WHERE withdrawn_at IS NULL AND left(pair_key, %s) = %s"""
MARK = """
INSERT INTO near_duplicate_intended (pair_key, t, a, b, why) VALUES (%s, %s, %s, %s, %s)
RETURNING pair_key, t, a, b, why, marked_by, marked_role, marked_at"""
WITHDRAW = "UPDATE near_duplicate_intended SET withdrawn_at = now() WHERE withdrawn_at IS NULL AND pair_key = %s"
# The module types in which both texts are lines of some class.
TYPES_OF_BOTH = """
SELECT c.t FROM component c JOIN assembly s ON s.component_id = c.id WHERE c.o = %s
INTERSECT
SELECT c.t FROM component c JOIN assembly s ON s.component_id = c.id WHERE c.o = %s
ORDER BY 1"""


def intents(conn: Connection) -> list[Intent]:
    """The marks in force, oldest first."""
    return [_intent(row) for row in conn.execute(INTENTS)]


def _intent(row) -> Intent:
    full, *rest = row
    return Intent(shown_key(full), *rest)


def intend(conn: Connection, why: str, key: str | None = None, texts: tuple[str, str] | None = None,
           t: str | None = None) -> Intent:
    """Mark a pair intended, named by the key a report printed or by its two texts (and module
    type when the texts are lines of more than one). Refused: an empty why, an unknown pair,
    a pair marked already."""
    if not why or not why.strip():
        raise EngineError('--why is empty; say why the pair stays as it is, e.g. --why "the helical '
                          'differential is part of the coupling"')
    if key is not None and texts is not None:
        raise EngineError("name the pair once: by its KEY or by --a and --b, not both")
    full, t, a, b = _reported_pair(conn, key) if key is not None else _pair_of_texts(conn, texts, t)
    try:
        with conn.transaction():
            _refuse_marked_twice(conn, full)
            return _intent(conn.execute(MARK, (full, t, a, b, why.strip())).fetchone())
    except psycopg.errors.UniqueViolation:   # a concurrent mark of the same pair committed first
        raise EngineError(f"pair {shown_key(full)} was marked intended meanwhile by another session; "
                          "engine refactor intents shows the mark") from None


def unintend(conn: Connection, key: str) -> Intent:
    """Withdraw the mark in force of the pair KEY: the next refactor run reports the pair again."""
    with conn.transaction():
        mark = _one(conn.execute(INTENT_BY_PREFIX, _prefix(key)).fetchall(), key, "pairs marked intended",
                    "engine refactor intents lists them")
        conn.execute(WITHDRAW, (mark[0],))
        return _intent(mark)


def _reported_pair(conn: Connection, key: str) -> tuple[str, str, str, str]:
    return _one(conn.execute(SEEN_BY_PREFIX, _prefix(key)).fetchall(), key, "pairs a refactor run reported",
                "run engine refactor for the current keys, or give --a and --b")


def _prefix(key: str) -> tuple[int, str]:
    typed = key.strip().lower()
    if len(typed) < KEY_TYPED or not HEX.match(typed):
        raise EngineError(f"pair key {key!r} is not a key: give the {KEY_SHOWN} hex digits the report "
                          f"prints (at least {KEY_TYPED})")
    return len(typed), typed


def _one(rows: list, key: str, among: str, hint: str):
    if not rows:
        raise EngineError(f"pair key {key!r} is not among the {among}; {hint}")
    if len(rows) > 1:
        raise EngineError(f"pair key {key!r} names {len(rows)} pairs; give more of its hex digits")
    return rows[0]


def _pair_of_texts(conn: Connection, texts: tuple[str, str] | None, t: str | None) -> tuple[str, str, str, str]:
    if texts is None or not all(texts):
        raise EngineError("name the pair: its KEY from the refactor report, or both texts with --a and --b")
    a, b = sorted(texts)
    if a == b:
        raise EngineError(f"--a and --b are the same text {a!r}; a near-duplicate pair is two different lines")
    t = _module_type(conn, a, b, t)
    return near_duplicate_key(t, a, b), t, a, b


def _module_type(conn: Connection, a: str, b: str, t: str | None) -> str:
    types = [found for (found,) in conn.execute(TYPES_OF_BOTH, (a, b))]
    if not types or (t is not None and t not in types):
        where = f"module type {t!r}" if t is not None else "one module type"
        raise EngineError(f"the texts {a!r} and {b!r} are not both lines of {where} in the library; "
                          "copy them from the refactor report (the o column of template_view)")
    if t is None and len(types) > 1:
        raise EngineError(f"the texts are lines of module types {', '.join(types)}; choose one with --type")
    return t or types[0]


def _refuse_marked_twice(conn: Connection, full: str) -> None:
    """A pair marked already, under this key or under the key of its full texts (before issue 17)."""
    stored = marks_in_force(conn).get(full, full)
    mark = conn.execute(INTENT_BY_PREFIX, (len(stored), stored)).fetchone()
    if mark:
        intent = _intent(mark)
        raise EngineError(f"pair {intent.key} is marked intended already (by {intent.marked_by}, "
                          f"{intent.marked_at:%Y-%m-%d}: {intent.why}); engine refactor unintend {intent.key} first")
