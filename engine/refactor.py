"""The nightly re-factoring of the module library (design notes §5).

One transaction: identical component bodies are merged (found by hashing, linear), the
near-duplicates a human should unify are reported (rapidfuzz on token lists, within one
module type), and the invariants are checked before commit — lossless (every class's
assembled template unchanged), stored once (no two components with the same body).
"""
from __future__ import annotations

import ast
from collections import defaultdict
from dataclasses import dataclass, field

from .errors import EngineError
from .nc_tokens import SPACE, tokenise
from .templates import TemplateRow, load_template, rows_hash

# Concurrent instantiations read either the old or the new library: writers wait for us,
# readers (plain SELECT) are not blocked and see the last committed state.
LOCK = "LOCK TABLE component, assembly IN SHARE ROW EXCLUSIVE MODE"

ASSEMBLED_ROWS = """
SELECT g.name, r.id, c.t, r.n, c.p_calc, c.s, c.o, c.p_emit
FROM gear_class g
CROSS JOIN LATERAL class_template(g.name) r
JOIN component c ON c.id = r.component_id
ORDER BY g.name, r.id"""

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

BODIES_STORED_TWICE = """
SELECT min(a.gear_class), count(DISTINCT c.id)::int
FROM component c LEFT JOIN assembly a ON a.component_id = c.id
GROUP BY component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit)
HAVING count(DISTINCT c.id) > 1
LIMIT 1"""

COMPONENTS_SHARED = """
SELECT count(*)::int FROM (
    SELECT component_id FROM assembly GROUP BY component_id
    HAVING count(DISTINCT gear_class) >= 2) shared"""

# Line texts with the classes and row ids that store them, per module type.
LINE_USES = """
SELECT c.t, c.o, a.gear_class, a.id
FROM assembly a JOIN component c ON c.id = a.component_id
WHERE c.o IS NOT NULL
ORDER BY c.t, c.o, a.gear_class, a.id"""

STAGES = ("snapshot", "merge identical bodies", "find near-duplicates", "check invariants")


@dataclass
class RefactorReport:
    changed: bool
    components_before: int
    components_after: int
    shared: int
    near_duplicates: list[dict] = field(default_factory=list)
    threshold: float = 0.8

    def as_dict(self) -> dict:
        return {"changed": self.changed, "components_before": self.components_before,
                "components_after": self.components_after, "shared": self.shared,
                "threshold": self.threshold, "near_duplicates": self.near_duplicates}


def refactor(conn, threshold: float = 0.8, progress=None) -> RefactorReport:
    """Merge identical bodies, report near-duplicates (threshold ≤ Sim < 1), check the
    invariants; all in one transaction that rolls back if an invariant breaks.
    `progress(stage, done, total)` is called before each stage."""
    if not 0 < threshold <= 1:
        raise EngineError(f"threshold {threshold} is outside (0, 1]; give e.g. --threshold 0.8")
    step = _stepper(progress)
    with conn.transaction():
        conn.execute(LOCK)
        step()
        snapshot = assembled_templates(conn)
        before = _count_components(conn)
        step()
        repointed = conn.execute(REPOINT_DUPLICATES).rowcount
        deleted = conn.execute(DELETE_UNUSED).rowcount
        step()
        pairs = near_duplicates(conn, threshold)
        step()
        check_invariants(conn, snapshot)
        return RefactorReport(changed=bool(repointed or deleted), components_before=before,
                              components_after=_count_components(conn),
                              shared=conn.execute(COMPONENTS_SHARED).fetchone()[0],
                              near_duplicates=pairs, threshold=threshold)


def _stepper(progress):
    done = iter(range(len(STAGES)))

    def step():
        index = next(done)
        if progress is not None:
            progress(STAGES[index], index, len(STAGES))
    return step


def _count_components(conn) -> int:
    return conn.execute("SELECT count(*)::int FROM component").fetchone()[0]


def assembled_templates(conn) -> dict[str, tuple[TemplateRow, ...]]:
    """Every class's assembled rows (own and inherited), in id order; one statement."""
    rows = defaultdict(list)
    for name, *values in conn.execute(ASSEMBLED_ROWS):
        rows[name].append(TemplateRow(*values))
    return {name: tuple(found) for name, found in rows.items()}


def check_invariants(conn, snapshot: dict[str, tuple[TemplateRow, ...]]) -> None:
    """Lossless and stored once, or an EngineError naming the class that broke."""
    now = assembled_templates(conn)
    for name in sorted(set(snapshot) | set(now)):
        if snapshot.get(name, ()) != now.get(name, ()):
            raise EngineError(
                f"refactor would change the assembled template of class {name!r} "
                f"(hash {rows_hash(snapshot.get(name, ()))} -> {rows_hash(now.get(name, ()))}); "
                "nothing was changed, report this as a bug")
    twice = conn.execute(BODIES_STORED_TWICE).fetchone()
    if twice:
        raise EngineError(f"after refactor a body of class {twice[0]!r} is stored {twice[1]} times; "
                          "nothing was changed, report this as a bug")


def nc_units(text: str) -> tuple[str, ...]:
    """The tokens of the NC line a line expression produces: string literals and f-string
    parts are tokenised as NC text, each `{…}` placeholder is one unit; anything else is
    tokenised as it stands. Blanks are dropped."""
    try:
        node = ast.parse(text.strip(), mode="eval").body
    except SyntaxError:
        node = None
    pieces = _literal_pieces(node) if node is not None else None
    if pieces is None:
        pieces = [(text, False)]
    units: list[str] = []
    for piece, is_placeholder in pieces:
        if is_placeholder:
            units.append(piece)
        else:
            units.extend(token.text for token in tokenise(piece) if token.kind != SPACE)
    return tuple(units)


def _literal_pieces(node) -> list[tuple[str, bool]] | None:
    """(text, is_placeholder) pieces of a string, f-string or `+` of them; None otherwise."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [(node.value, False)]
    if isinstance(node, ast.JoinedStr):
        pieces = []
        for part in node.values:
            if isinstance(part, ast.Constant):
                pieces.append((str(part.value), False))
            else:
                pieces.append(("{" + ast.unparse(part.value) + "}", True))
        return pieces
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _literal_pieces(node.left), _literal_pieces(node.right)
        if left is None or right is None:
            return None
        return left + right
    return None


def near_duplicates(conn, threshold: float) -> list[dict]:
    """Pairs of distinct line texts of one module type with threshold ≤ Sim < 1, where
    Sim = K / (M + N − K) on token lists (K the longest common subsequence)."""
    uses: dict[tuple[str, str], list[list]] = defaultdict(list)
    for t, o, gear_class, row_id in conn.execute(LINE_USES):
        uses[(t, o)].append([gear_class, row_id])
    by_type: dict[str, dict[tuple[str, ...], list[str]]] = defaultdict(lambda: defaultdict(list))
    for t, o in uses:
        by_type[t][nc_units(o)].append(o)
    pairs = []
    for t in sorted(by_type):
        for (a, b), sim in _similar_pairs(list(by_type[t]), threshold):
            for text_a in by_type[t][a]:
                for text_b in by_type[t][b]:
                    pairs.append({"t": t, "sim": round(sim, 4), "a": text_a, "b": text_b,
                                  "rows_a": uses[(t, text_a)], "rows_b": uses[(t, text_b)]})
    return sorted(pairs, key=lambda pair: (-pair["sim"], pair["t"], pair["a"], pair["b"]))


def _similar_pairs(units: list[tuple[str, ...]], threshold: float):
    """((units a, units b), Sim) for every pair of distinct token lists with Sim ≥ threshold."""
    if len(units) < 2:
        return
    from rapidfuzz import process
    from rapidfuzz.distance import Indel

    # Indel's normalized similarity ns = 2K / (M + N); Sim = ns / (2 − ns) grows with ns.
    cutoff = 2 * threshold / (1 + threshold)
    scores = process.cdist(units, units, scorer=Indel.normalized_similarity,
                           score_cutoff=cutoff - 1e-9, workers=-1)
    for i in range(len(units)):
        for j in range(i + 1, len(units)):
            ns = float(scores[i][j])
            sim = ns / (2 - ns)
            if threshold - 1e-9 <= sim < 1 - 1e-12:
                yield (units[i], units[j]), sim


@dataclass(frozen=True)
class SharedRow:
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


def shared_rows(conn, gear_class: str) -> list[SharedRow]:
    """Per row of the class's assembled template: which other classes use the same body."""
    load_template(conn, gear_class)   # names a missing class or a class without rows
    return [SharedRow(row_id, t, o, owner, tuple(others))
            for row_id, t, o, owner, others in conn.execute(SHARED_ROWS, (gear_class,))]
