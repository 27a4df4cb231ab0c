"""The nightly re-factoring of the module library (design notes §5).

One transaction: identical component bodies are merged (found by hashing, linear), the
near-duplicates a human should unify are reported (engine.library.similarity, within one module
type, block numbers left out: lines that differ only in theirs are one family, reported once;
those not listed by an earlier run first, those marked intended only counted:
engine.library.intended), and the invariants are checked before commit — lossless (every class's assembled
template unchanged, compared by a digest the server computes per class), stored once (no
two components with the same body).
"""
from __future__ import annotations

from collections import defaultdict
from typing import TYPE_CHECKING

import msgspec
import psycopg

from ..db.connection import scalar
from ..errors import EngineError
from ..templates.store import load_template
from .intended import list_and_remember
from .similarity import Units, block_free, nc_units, similar_pairs

if TYPE_CHECKING:
    from ..db.connection import Connection

# Concurrent instantiations read either the old or the new library: writers wait for us,
# readers (plain SELECT, foreign-key checks) are not blocked and see the last committed
# state. The engine's writers lock the three tables in this order too (replace_class_template and
# the template_view triggers, in the database); a hand-made SQL edit may not, and a deadlock with it
# costs the refactor a retry, not the night.
LOCK = "LOCK TABLE gear_class, component, assembly IN SHARE ROW EXCLUSIVE MODE"
DEADLOCK_RETRIES = 3
# JIT compiling these one-pass statements costs more than it saves, and only on large
# libraries (PostgreSQL turns it on by the estimated cost), which made time grow faster
# than the library.
NO_JIT = "SET LOCAL jit = off"

# Per class: its own rows (id, n and the whole body), counted and digested by the server.
# A class's assembled template is a function of its lineage (gear_class.parent, locked and
# never written by the refactor) and of its ancestors' own rows, so own rows unchanged for
# every class means every assembled template unchanged.
OWN_ROW_DIGESTS = """
SELECT a.gear_class, count(*)::int,
       encode(sha256(convert_to(string_agg(
           concat_ws(',', a.id, a.n, quote_literal(c.t), quote_nullable(c.p_calc), quote_nullable(c.s),
                     quote_nullable(c.o), quote_nullable(c.p_emit)), E'\\n' ORDER BY a.id), 'UTF8')), 'hex')
FROM assembly a JOIN component c ON c.id = a.component_id
GROUP BY a.gear_class"""

# Every assembly row pointing at a later copy of a body is repointed to the body's lowest id.
REPOINT_DUPLICATES = """
WITH keyed AS (
    SELECT id, min(id) OVER (PARTITION BY component_body_key(t, o, p_calc, s, p_emit)) AS keep
    FROM component)
UPDATE assembly a SET component_id = k.keep
FROM keyed k WHERE a.component_id = k.id AND k.keep <> k.id"""

DELETE_UNUSED = """
DELETE FROM component c
WHERE NOT EXISTS (SELECT 1 FROM assembly a WHERE a.component_id = c.id)"""

# A body stored more than once (as component ids), and a class that uses one of them.
BODIES_STORED_TWICE = """
SELECT (SELECT min(a.gear_class) FROM assembly a WHERE a.component_id = ANY(twice.ids)), cardinality(twice.ids)
FROM (SELECT array_agg(id) AS ids FROM component
      GROUP BY component_body_key(t, o, p_calc, s, p_emit) HAVING count(*) > 1 LIMIT 1) twice"""

COMPONENTS_SHARED = """
SELECT count(*)::int FROM (
    SELECT component_id FROM assembly GROUP BY component_id
    HAVING count(DISTINCT gear_class) >= 2) shared"""

# Per line text of a module type: how many rows store it, and the first few (class, row id).
LINE_USES = """
SELECT c.t, c.o, count(*)::int,
       (array_agg(a.gear_class ORDER BY a.gear_class, a.id))[1:%(listed)s],
       (array_agg(a.id ORDER BY a.gear_class, a.id))[1:%(listed)s]
FROM assembly a JOIN component c ON c.id = a.component_id
WHERE c.o IS NOT NULL
GROUP BY c.t, c.o"""

STAGES = ("snapshot", "merge identical bodies", "find near-duplicates", "check invariants")


class RefactorReport(msgspec.Struct):
    changed: bool
    components_before: int
    components_after: int
    shared: int
    near_duplicates: list[dict] = []   # listed: new ones first
    threshold: float = 0.8
    new: int = 0         # listed pairs no earlier run listed
    known: int = 0       # listed pairs an earlier run listed
    intended: int = 0    # pairs found but not listed: marked intended (engine refactor intents)

    @property
    def families(self) -> int:
        """Listed entries that are families of lines differing only in their block number."""
        return sum(1 for entry in self.near_duplicates if entry["kind"] == "family")

    def as_dict(self) -> dict:
        return {"changed": self.changed, "components_before": self.components_before,
                "components_after": self.components_after, "shared": self.shared,
                "threshold": self.threshold, "new": self.new, "known": self.known, "intended": self.intended,
                "families": self.families, "near_duplicates": self.near_duplicates}


def refactor(conn: Connection, threshold: float = 0.8, progress=None) -> RefactorReport:
    """Merge identical bodies, report near-duplicates (threshold ≤ Sim < 1), check the
    invariants; all in one transaction that rolls back if an invariant breaks.
    `progress(stage, done, total)` is called before each stage."""
    if not 0 < threshold <= 1:
        raise EngineError(f"threshold {threshold} is outside (0, 1]; give e.g. --threshold 0.8")
    for attempt in range(1, DEADLOCK_RETRIES + 1):
        try:
            return _refactor_once(conn, threshold, _stepper(progress))
        except psycopg.errors.DeadlockDetected:
            if attempt == DEADLOCK_RETRIES:
                raise EngineError(f"refactor deadlocked {attempt} times with other writers of the template "
                                  "library; nothing was changed, run it again when they are done") from None
    raise AssertionError("unreachable: the last attempt returns or raises")


def _refactor_once(conn: Connection, threshold: float, step) -> RefactorReport:
    with conn.transaction():
        conn.execute(LOCK)
        conn.execute(NO_JIT)
        step()
        snapshot = template_digests(conn)
        before = _count_components(conn)
        step()
        repointed = conn.execute(REPOINT_DUPLICATES).rowcount
        deleted = conn.execute(DELETE_UNUSED).rowcount
        step()
        listed = list_and_remember(conn, near_duplicates(conn, threshold))
        step()
        check_invariants(conn, snapshot)
        return RefactorReport(changed=bool(repointed or deleted), components_before=before,
                              components_after=_count_components(conn),
                              shared=scalar(conn.execute(COMPONENTS_SHARED)),
                              near_duplicates=listed.pairs, threshold=threshold,
                              new=listed.new, known=listed.known, intended=listed.intended)


def _stepper(progress):
    done = iter(range(len(STAGES)))

    def step():
        index = next(done)
        if progress is not None:
            progress(STAGES[index], index, len(STAGES))
    return step


def _count_components(conn: Connection) -> int:
    return scalar(conn.execute("SELECT count(*)::int FROM component"))


def template_digests(conn: Connection) -> dict[str, tuple[int, str]]:
    """Per class with rows of its own: (row count, digest of those rows); computed by the server."""
    return {name: (count, digest) for name, count, digest in conn.execute(OWN_ROW_DIGESTS)}


def check_invariants(conn: Connection, snapshot: dict[str, tuple[int, str]]) -> None:
    """Lossless and stored once, or an EngineError naming the class that broke."""
    now = template_digests(conn)
    for name in sorted(set(snapshot) | set(now)):
        if snapshot.get(name) != now.get(name):
            raise EngineError(
                f"refactor would change the template of class {name!r} and of the classes deriving "
                f"from it (rows, digest {_shown(snapshot.get(name))} -> {_shown(now.get(name))}); "
                "nothing was changed, report this as a bug")
    twice = conn.execute(BODIES_STORED_TWICE).fetchone()
    if twice:
        raise EngineError(f"after refactor a body of class {twice[0]!r} is stored {twice[1]} times; "
                          "nothing was changed, report this as a bug")


def _shown(digest: tuple[int, str] | None) -> str:
    return "none" if digest is None else f"{digest[0]}, {digest[1][:16]}"


# A text used by hundreds of classes would repeat all its uses in every pair it is in;
# the report lists this many and counts the rest (template_view has them all).
USES_LISTED = 10


def near_duplicates(conn: Connection, threshold: float) -> list[dict]:
    """The families of texts of one module type that differ only in their block number (one
    entry each, `kind` family, its members; Sim 1 without the block number), then the pairs of
    texts with threshold ≤ Sim < 1, where Sim = K / (M + N − K) on the NC units of the lines
    without block number (K the longest common subsequence); a side that is a family is one
    text of the pair, its members listed. Per text or family its number of uses and the first
    USES_LISTED (class, row id)."""
    uses: dict[tuple[str, str], tuple[int, list]] = {}
    members: dict[tuple[str, str], list[str]] = defaultdict(list)   # (t, line without block number) → texts
    for t, o, count, classes, row_ids in conn.execute(LINE_USES, {"listed": USES_LISTED}):
        uses[(t, o)] = (count, [[name, row_id] for name, row_id in zip(classes, row_ids)])
        members[(t, block_free(o))].append(o)
    by_type: dict[str, dict[Units, list[str]]] = defaultdict(lambda: defaultdict(list))
    for t, line in members:
        by_type[t][nc_units(line)].append(line)
    families = [_family(t, members[(t, line)], uses) for t, line in sorted(members) if len(members[(t, line)]) > 1]
    pairs = []
    for t in sorted(by_type):
        lines_of = list(by_type[t].values())
        for i, j, sim in similar_pairs(list(by_type[t]), threshold):
            pairs += [_pair(t, sim, members[(t, a)], members[(t, b)], uses) for a in lines_of[i] for b in lines_of[j]]
    return families + sorted(pairs, key=lambda pair: (-pair["sim"], pair["t"], pair["a"], pair["b"]))


def _family(t: str, texts: list[str], uses) -> dict:
    """Texts that differ only in their block number, in the order of their first use (program
    order within a class); the first and the last are its a and b."""
    texts = sorted(texts, key=lambda text: (uses[(t, text)][1][:1], text))
    count, rows = _uses_of(t, texts, uses)
    return {"kind": "family", "t": t, "sim": 1.0, "a": texts[0], "b": texts[-1], "members": texts,
            "uses": count, "rows": rows}


def _pair(t: str, sim: float, texts_a: list[str], texts_b: list[str], uses) -> dict:
    """Two texts (or families, each shown by its first text) whose lines are near-duplicates."""
    (texts_a, texts_b) = sorted((sorted(texts_a), sorted(texts_b)))
    (uses_a, rows_a), (uses_b, rows_b) = _uses_of(t, texts_a, uses), _uses_of(t, texts_b, uses)
    return {"kind": "pair", "t": t, "sim": round(sim, 4), "a": texts_a[0], "b": texts_b[0],
            "uses_a": uses_a, "uses_b": uses_b, "rows_a": rows_a, "rows_b": rows_b,
            "members_a": texts_a, "members_b": texts_b}


def _uses_of(t: str, texts: list[str], uses) -> tuple[int, list]:
    """The rows using any of the texts: how many, and the first USES_LISTED (class, row id)."""
    count = sum(uses[(t, text)][0] for text in texts)
    return count, sorted(row for text in texts for row in uses[(t, text)][1])[:USES_LISTED]


class SharedRow(msgspec.Struct, frozen=True):
    id: int
    t: str
    o: str | None
    inherited_from: str
    shared_with: tuple[str, ...]   # the other classes whose assembled template has this body


SHARED_ROWS = """
WITH v AS (
    SELECT gear_class, id, t, o, inherited_from,
           component_body_key(t, o, p_calc, s, p_emit) AS body
    FROM template_view)
SELECT v.id, v.t, v.o, v.inherited_from,
       coalesce(array_agg(DISTINCT w.gear_class ORDER BY w.gear_class)
                FILTER (WHERE w.gear_class <> v.gear_class), '{}')
FROM v JOIN v w ON w.body = v.body
WHERE v.gear_class = %s
GROUP BY v.id, v.t, v.o, v.inherited_from
ORDER BY v.id"""


def shared_rows(conn: Connection, gear_class: str) -> list[SharedRow]:
    """Per row of the class's assembled template: which other classes use the same body."""
    load_template(conn, gear_class)   # names a missing class or a class without rows
    return [SharedRow(row_id, t, o, owner, tuple(others))
            for row_id, t, o, owner, others in conn.execute(SHARED_ROWS, (gear_class,))]
