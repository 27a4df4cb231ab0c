"""`nc_path(moves, rapid, feed, cw, ccw, thread)`: the template function that prints a tool
path, one NC block per move, each kind in the format its row gives. The loop is here, the
words of each dialect stay in the template rows:

    nc_path(moves, "G0 X{x:.3f} Z{z:.3f}", "G1 X{x:.3f} Z{z:.3f}",
            "G2 X{x:.3f} Z{z:.3f} R{r:.3f}", "G3 X{x:.3f} Z{z:.3f} R{r:.3f}", "G32 X{x:.3f} Z{z:.3f} F{pitch:.3f}")

A format may name only the fields of FIELDS, with a bounded format spec: no attribute or
index access, no conversions, nothing nested (str.format would otherwise reach into any
object). The result is one entry of the result table per block, all from the same row. Every
block is paid for from the instantiation's budget as it is printed (engine.templates.budget).
"""
from __future__ import annotations

import string

from .budget import paid
from .guards import check_format_spec

MOVE_KINDS = ("rapid", "feed", "cw", "ccw", "thread")   # engine.turning.moves.Move.kind, in the order of the formats
FIELDS = ("x", "z", "r", "i", "k", "pitch")   # x a diameter; r, i, k arc radius and centre offsets
MAX_PATH_BLOCKS = 200_000     # blocks one nc_path call may print
MAX_BLOCK_LENGTH = 512        # characters of one printed block
# A coordinate this close to 0 prints as 0, never as -0.000.
ZERO = 5e-10


class NcLines(tuple):
    """Blocks printed by nc_path: the decision table emits each as its own line."""


def nc_path(moves, rapid: str, feed: str, cw: str, ccw: str, thread: str) -> NcLines:
    formats = dict(zip(MOVE_KINDS, (rapid, feed, cw, ccw, thread)))
    parsed = {kind: _parsed(kind, text) for kind, text in formats.items()}
    if len(moves) > MAX_PATH_BLOCKS:
        raise ValueError(f"nc_path: {len(moves)} moves, more than {MAX_PATH_BLOCKS}")
    return paid(NcLines(_block(parsed, move) for move in moves))


def _parsed(kind: str, text) -> list[tuple[str, str | None, str]]:
    """(literal, field, spec) pieces of one format, checked."""
    if not isinstance(text, str):
        raise ValueError(f"nc_path: the {kind} format must be text, not {type(text).__name__}")
    pieces = []
    for literal, field, spec, conversion in string.Formatter().parse(text):
        if field is not None and (field not in FIELDS or conversion or "{" in (spec or "")):
            raise ValueError(f"nc_path: {kind} format {text!r} may use only "
                             f"{', '.join('{' + name + '}' for name in FIELDS)} with a plain format")
        check_format_spec(spec or "")   # checked once per format, not per printed block
        pieces.append((literal, field, spec or ""))
    return pieces


def _block(parsed: dict, move) -> str:
    kind = move.kind
    if kind not in parsed:
        raise ValueError(f"nc_path: move kind {kind!r} is not one of {', '.join(MOVE_KINDS)}")
    values = {"x": move.x, "z": move.z, "r": move.radius, "i": move.i, "k": move.k, "pitch": move.pitch}
    text = []
    for literal, field, spec in parsed[kind]:
        text.append(literal)
        if field is not None:
            value = values[field]
            if value is None:
                raise ValueError(f"nc_path: a {kind} move has no {field}; leave {{{field}}} out of its format")
            text.append(format(0.0 if abs(value) < ZERO else value, spec))
    block = "".join(text)
    if len(block) > MAX_BLOCK_LENGTH:
        raise ValueError(f"nc_path: a block longer than {MAX_BLOCK_LENGTH} characters")
    return paid(block)   # block by block: a long path stops at the run's budget, not after it
