"""One emitted line read with the grammar of its dialect (engine.verifier.grammar): a
header, a comment, a statement, a line of the hob-shift clamp, or a block of address words with
an optional comment. Reading a line needs no machine and no other line, so what a line reads as
(or why it is refused) is kept per dialect and text: a template's constant lines are read once."""
from __future__ import annotations

import re
from typing import ClassVar, Literal

import msgspec

from .blocks import Block, read_block
from .characters import check_characters
from .grammar import ISO_COMMENT_TEXT, Dialect, Header
from .refusals import Refused
from .shift_clamp import ShiftLine, read_shift_line
from .statements import STATEMENT, Statement, read_statement

MAX_REMEMBERED = 20_000   # lines kept per dialect; the memory starts again when full
ISO_LINE = re.compile(rf"([^()]*?) ?(?:\(({ISO_COMMENT_TEXT})\))?")


class HeaderLine(msgspec.Struct, frozen=True):
    """A program's header line as read: the program name (or ISO number) it gives."""
    kind: ClassVar[Literal["header"]] = "header"
    what: str
    places: frozenset[str]
    name: str | None = None        # the program name it gives (%_N_<name>_MPF, ISO O<n> (<name>))
    number: int | None = None      # the ISO program number


class CommentLine(msgspec.Struct, frozen=True):
    """A line that is only a comment."""
    kind: ClassVar[Literal["comment"]] = "comment"


Line = HeaderLine | CommentLine | ShiftLine | Statement | Block   # what a line reads as, by its kind
COMMENT = CommentLine()
_remembered: dict[str, dict[str, Line | Refused]] = {}    # dialect name -> line -> what it reads as


def remembered_lines(dialect: Dialect) -> dict[str, Line | Refused]:
    """line -> what it reads as (or why it is refused), for the lines of `dialect` read so far."""
    return _remembered.setdefault(dialect.name, {})


def read_line(dialect: Dialect, line: str) -> Line:
    """What `line` reads as, or Refused with the reason (both remembered)."""
    if type(line) is not str:
        raise Refused(f"a line must be text, not {type(line).__name__}")
    remembered = remembered_lines(dialect)
    found = remembered.get(line)
    if found is None:
        found = _read_fresh(dialect, line)
        if len(remembered) >= MAX_REMEMBERED:
            remembered.clear()
        remembered[line] = found
    if isinstance(found, Refused):
        raise found
    return found


def _read_fresh(dialect: Dialect, line: str) -> Line | Refused:
    try:
        return _read(dialect, line)
    except Refused as refusal:
        return refusal


def _read(dialect: Dialect, line: str) -> Line:
    check_characters(line)
    for header in dialect.headers:
        match = header.pattern.fullmatch(line)
        if match:
            return _header(header, match.groupdict())
    code = SPLIT_COMMENT[dialect.comment](line).strip()
    if not code:
        return COMMENT
    if dialect.shift_clamp:
        shift = read_shift_line(dialect.shift_clamp, code)
        if shift is not None:
            return shift
    if dialect.synchronisations:   # a Fanuc gear box's reader: loaded only for a dialect that has one (issue 28)
        from .synchronisation import read_synchronisation

        synchronisation = read_synchronisation(dialect, code)
        if synchronisation is not None:
            return synchronisation
    statement = STATEMENT.fullmatch(code)
    if statement and statement.group(1) in dialect.statements:
        return read_statement(*statement.groups())
    return read_block(dialect, code)


def _header(header: Header, groups: dict[str, str | None]) -> HeaderLine:
    number = groups.get("number")
    return HeaderLine(header.what, header.places, groups.get("name"), int(number) if number else None)


def _semicolon(line: str) -> str:
    """840D: a comment runs from `;` to the end of the line; `;$…` is a directive, not a comment."""
    code, semicolon, comment = line.partition(";")
    if comment.startswith("$"):
        raise Refused("a ;$ directive other than the path line in the second line")
    if not (semicolon or code.strip()):
        raise Refused("an empty line: leave the row's o out, or give it a p_emit condition")
    return code


def _parentheses(line: str) -> str:
    """ISO: one comment `(text)` at the end of the block, with no parenthesis inside (the
    control ends a comment at the first `)`, and would read what follows as words)."""
    match = ISO_LINE.fullmatch(line)
    if match is None:
        raise Refused("a comment is one (…) at the end of the block, with no ( or ) inside")
    if not (match.group(1).strip() or match.group(2) is not None):
        raise Refused("an empty line: leave the row's o out, or give it a p_emit condition")
    return match.group(1)


def _parentheses_without_semicolon(line: str) -> str:
    """Fanuc hobbing: as ISO, and no `;` in the comment either. Fanuc's manuals print `;` for the
    end of block (reference iso-lathe.md, Lines), so a reader or DNC link that takes it so would
    run the rest of the comment (`(A;G1 Z-300.;)`) as a block the verifier read as a comment."""
    code = _parentheses(line)
    if ";" in line[len(code):]:
        raise Refused("a ; in a comment: Fanuc prints ; for the end of block, and a reader taking it so would run "
                      "what follows as a block nobody checked")
    return code


SPLIT_COMMENT = {"semicolon": _semicolon, "parentheses": _parentheses,
                 "parentheses without ;": _parentheses_without_semicolon}
