"""Literal similarity of NC lines (design notes §5, paper definitions 1–2).

A line expression is compared by the units of the NC line it produces: string literals
and f-string parts are tokenised as NC text, each `{…}` placeholder is one unit.
Sim = K / (M + N − K), K the longest common subsequence of the two unit lists.

Finding every pair with Sim ≥ t does not compare all pairs (quadratic in the number of
distinct lines, which grows with the library): a pair can only reach t if the lines
have similar lengths and share enough units, so each line is indexed by its few rarest
units (prefix filtering, Bayardo et al., "Scaling up all pairs similarity search", WWW
2007) and rapidfuzz's built-in Indel scorer checks only lines that share one of them.
The result is exactly that of comparing every pair (tested against `process.cdist`).
"""
from __future__ import annotations

import ast
import math
import re
from collections import Counter, defaultdict
from collections.abc import Iterator, Sequence

from ..nc.tokens import NUMBER, SPACE, WORD, tokenise
from ..templates.guards import parse_python

CODE_ADDRESSES = ("G", "M")   # their numbers name a function: `G1` is one unit, as `M8`
# Float slack for Sim compared with a threshold: 0.8 * 10 must count as 8, not 8.000…1.
TOLERANCE = 1e-9

Units = tuple[str, ...]


# The block number at the start of a line expression's NC line: `"N0380 G1 …"`, `f"/N20 X{x}"`.
_BLOCK_NUMBER = re.compile(r"""^(\s*[fF]?["'][ \t]*/?[ \t]*)[Nn]\d+(?![\d.])[ \t]*""")


def block_free(text: str) -> str:
    """The line expression without the block number its NC line starts with. A block number
    says where a line stands, not what it does: `N0380 G1 X10` and `N0400 G1 X10` are one line
    (issue 17), compared and keyed without it."""
    return _BLOCK_NUMBER.sub(r"\1", text, count=1)


def nc_units(text: str) -> Units:
    """The units of the NC line a line expression produces; blanks are dropped."""
    try:
        node = parse_python(text.strip()).body
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
            units.extend(_text_units(piece))
    return tuple(units)


def _literal_pieces(node, in_sum: bool = False) -> list[tuple[str, bool]] | None:
    """(text, is_placeholder) pieces of a string, an f-string or a `+` of them, where an
    operand that is not a string (`"G25 X" + fmt(x)`) is a placeholder; None for any
    other expression."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [(node.value, False)]
    if isinstance(node, ast.JoinedStr):
        return [(str(part.value), False) if isinstance(part, ast.Constant) else (_placeholder(part), True)
                for part in node.values]
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _literal_pieces(node.left, True), _literal_pieces(node.right, True)
        return None if left is None or right is None else left + right
    return [("{" + ast.unparse(node) + "}", True)] if in_sum else None


def _placeholder(field: ast.expr) -> str:   # a replacement field of an f-string
    """`{x_in:.3f}`: the field with its conversion and format, as one unit."""
    return ast.unparse(ast.JoinedStr(values=[field]))[2:-1]


def _text_units(text: str) -> list[str]:
    """NC tokens without blanks; a G or M word and its number are one unit (`G25`, `M8`)."""
    units: list[str] = []
    previous = None
    for token in tokenise(text):
        joins_code = (token.kind == NUMBER and token.address in CODE_ADDRESSES and previous is not None
                      and previous.kind == WORD and previous.text.upper() == token.address)
        if joins_code:
            units[-1] += token.text
        elif token.kind != SPACE:
            units.append(token.text)
        previous = token
    return units


def _sim(common: int, m: int, n: int) -> float:
    return common / (m + n - common) if m + n else 1.0


def similar_pairs(lines: Sequence[Units], threshold: float) -> Iterator[tuple[int, int, float]]:
    """(i, j, Sim) with i < j for every pair of distinct unit lists with threshold ≤ Sim < 1."""
    from rapidfuzz import process
    from rapidfuzz.distance import Indel

    prefixes = _rare_prefixes(lines, threshold)
    index: dict[int, list[int]] = defaultdict(list)
    for i in sorted(range(len(lines)), key=lambda k: len(lines[k])):
        candidates = sorted(_candidates(i, lines, prefixes[i], index, threshold))
        # Indel.similarity = M + N − distance = 2K: whole numbers, so Sim is exact here.
        scores = process.extract(lines[i], [lines[j] for j in candidates], scorer=Indel.similarity,
                                 limit=None) if candidates else ()
        for _, twice_common, position in scores:
            j = candidates[position]
            sim = _sim(twice_common // 2, len(lines[i]), len(lines[j]))
            if threshold - TOLERANCE <= sim < 1 - TOLERANCE:
                yield min(i, j), max(i, j), sim
        for element in prefixes[i]:
            index[element].append(i)


def _candidates(i: int, lines, prefix, index, threshold: float) -> set[int]:
    """Lines already indexed (none longer than line i) that share a prefix unit and are
    long enough: Sim ≤ shorter / longer."""
    shortest = threshold * len(lines[i]) - TOLERANCE
    return {j for element in prefix for j in index[element] if len(lines[j]) >= shortest}


def _rare_prefixes(lines: Sequence[Units], threshold: float) -> list[list[int]]:
    """Per line, its rarest units (occurrence-numbered, so a repeated unit counts as often
    as it occurs): |x| − ⌈t·|x|⌉ + 1 of them. Two lines with Sim ≥ t have at least
    ⌈t·|x|⌉ units in common (K ≥ t(M + N)/(1 + t) ≥ t·max(M, N)), so their prefixes meet."""
    elements = [_numbered(line) for line in lines]
    frequency = Counter(element for line in elements for element in line)
    rank = {element: position for position, element in
            enumerate(sorted(frequency, key=lambda e: (frequency[e], e)))}
    prefixes = []
    for line in elements:
        size = len(line)
        keep = size - math.ceil(threshold * size - TOLERANCE) + 1
        prefixes.append(sorted(rank[element] for element in line)[:keep])
    return prefixes


def _numbered(units: Units) -> list[tuple[str, int]]:
    seen: Counter = Counter()
    numbered = []
    for unit in units:
        numbered.append((unit, seen[unit]))
        seen[unit] += 1
    return numbered
