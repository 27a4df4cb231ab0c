"""Template rows as data: one NC line with the expressions that compute and decide it
(design notes §4), and a class's assembled template with its content hash. The CSV form
engineers export, edit and import is engine.templates.template_csv (imported by the commands
that read or write it, not by the instantiation: issue 28, start-up)."""
from __future__ import annotations

import ast
import hashlib
import json
import re
from collections.abc import Mapping
from functools import cached_property

import msgspec

from ..nc.lineage import lineage_shaped

CSV_COLUMNS = ("id", "t", "n", "p_calc", "s", "o", "p_emit")
MODULE_ORDER = ("main", "prep", "sync", "shift", "cutcond", "cutmotion")   # the module types, in program order
EXPRESSION_COLUMNS = ("p_calc", "s", "o", "p_emit")


class TemplateRow(msgspec.Struct, frozen=True):
    """One row of a template: one NC line of module t, number n, with the expressions that compute and decide it."""
    id: int
    t: str
    n: int
    p_calc: str | None
    s: str | None
    o: str | None
    p_emit: str | None

    def values(self) -> tuple:
        """(id, t, n, p_calc, s, o, p_emit): what dataclasses.astuple gave for these plain fields,
        without its deep copy of every value (11 s of the 14 s that exporting every class of a library
        with a 29,000-line program took)."""
        return (self.id, self.t, self.n, self.p_calc, self.s, self.o, self.p_emit)


class Template(msgspec.Struct, frozen=True, dict=True):   # dict: room for the cached properties
    """A class's template at one version: its rows in order, and the stored translations of its SQL conditions."""
    gear_class: str
    version: int
    rows: tuple[TemplateRow, ...]
    # SQL condition text → its stored Python translation (engine.templates.translations)
    translations: Mapping[str, str] = {}
    draft: bool = False   # not a released version (engine.templates.versions)

    def __eq__(self, other: object) -> bool:
        """Class, version and rows: the translations and the draft mark are not compared."""
        return isinstance(other, Template) and self._compared() == other._compared()

    def __hash__(self) -> int:
        return hash(self._compared())

    def _compared(self) -> tuple:
        return self.gear_class, self.version, self.rows

    @cached_property
    def cache_key(self) -> tuple:
        """What a compiled template depends on: class, version, rows and the stored translations of
        its SQL conditions (which the gate checks again when they change)."""
        return self.gear_class, self.version, self.hash, frozenset(self.translations.items())

    @cached_property
    def hash(self) -> str:
        """Content hash of the assembled rows: what a program records next to the version."""
        return rows_hash(self.rows)


def rows_hash(rows) -> str:
    payload = json.dumps([row.values() for row in rows], separators=(",", ":"))
    return hashlib.sha256(payload.encode()).hexdigest()[:16]


# An output that begins with a text literal (an f-string too): parsed to see what text it writes.
LITERAL_START = re.compile(r"\s*[fFrRuU]{0,2}[\"']")
FOLDED_TEXTS = 64   # enough for any real row; a row folding to more is left to the run-time check


def writes_lineage(o: str | None) -> bool:
    """True when the row's output is text, built from literals (concatenated, chosen by a
    condition, an f-string with its fields read as 0), that reads as the lineage line only the
    engine writes (engine.nc.lineage). What a row computes from its inputs is refused
    when the program is made (engine.programs.verified_run), so golden tests and the release
    gate catch it too."""
    if not o or not LITERAL_START.match(o):   # parsed only if it may be text: rows can be hostile
        return False
    try:
        texts = _folded_texts(ast.parse(o.strip(), mode="eval").body)
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return False
    return any(lineage_shaped(text) for text in texts)


def _folded_texts(node: ast.AST) -> list[str]:
    """Every text the expression can write, if it is built from literals only; else []."""
    if isinstance(node, ast.Constant):
        return [node.value] if isinstance(node.value, str) else []
    if isinstance(node, ast.JoinedStr):
        return ["".join(str(part.value) if isinstance(part, ast.Constant) else "0" for part in node.values)]
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        pairs = [a + b for a in _folded_texts(node.left) for b in _folded_texts(node.right)]
        return pairs[:FOLDED_TEXTS]
    if isinstance(node, ast.IfExp):
        return (_folded_texts(node.body) + _folded_texts(node.orelse))[:FOLDED_TEXTS]
    return []
