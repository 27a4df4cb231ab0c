"""A Fanuc/Haas lathe program's lines read into words (issue 27), before the ISO expander follows
them: blank lines and `%`, the program number line `O<n>` with or without `(NAME)`, the sequence
number N, the optional block skip `/`, comments in parentheses (nested parentheses inside a
comment are part of it, as Haas reads them; an unbalanced one is refused), `;` as the end of the
block as printed in manuals, and words of one capital letter and a plain number (X.15, Z-1.,
T0101). A line with a `#` variable, a bracketed expression or a macro statement (IF, GOTO,
WHILE … DO, END) is kept as written for engine.verifier.expanders.iso_macro_flow. Anything else on
a line (a `,C` chamfer word, a lowercase word) is refused naming it: the expander does not guess
what a control would make of it."""
from __future__ import annotations

import re

import msgspec

from ..characters import check_characters
from ..expansion import ExpansionRefused
from ..numbers import why_not_plain
from ..refusals import Refused

HEADER = re.compile(r"(?P<tape>%)?[O:](?P<number>\d{1,5})\s*(?:\((?P<name>[^()%]*)\))?\s*;?")
EXPONENT = re.compile(r"[eE][-+]?\d")
WORD = re.compile(r"\s*([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
TAPE, HEADER_LINE, BLOCK, NOTHING, MACRO = "tape", "header", "block", "nothing", "macro"
LABEL = re.compile(r"N\s*(?P<number>\d+)\s*")
# a custom macro B line: a variable, an expression, or a statement (engine.verifier.expanders.iso_macro_flow)
MACRO_LINE = re.compile(r"[^(]*[#\[]|\s*(?:IF|WHILE|GOTO|END\s*\d|DO\s*\d)")
COMMENT_REASON = "a comment is one (…) at the end of the block"


class Source(msgspec.Struct):
    """One line of the program as read: its kind, and for a block its words in order (letter, text)."""
    number: int
    text: str
    kind: str
    words: list[tuple[str, str]] = []
    label: int | None = None          # its N number
    program: int | None = None        # the O number of a header line
    name: str | None = None           # the (NAME) of a header line
    comment: str | None = None        # its comments' text, passed on (the simulation reads "(OP n …)")
    tape: bool = False                # a header line `%O1200` that also holds the tape mark
    macro: str | None = None          # a custom macro B line's code, evaluated as the program runs

    def refuse(self, reason: str) -> ExpansionRefused:
        return ExpansionRefused(self.number, self.text, reason)


def read_sources(lines: list[str]) -> list[Source]:
    return [read_source(number, line) for number, line in enumerate(lines, start=1)]


def read_source(number: int, line: str) -> Source:
    try:
        return _read(number, line)
    except Refused as refusal:
        raise ExpansionRefused(number, line if isinstance(line, str) else "", str(refusal)) from None


def _read(number: int, line: str) -> Source:
    check_characters(line)
    stripped = line.strip()
    if stripped == "%":
        return Source(number, line, TAPE)
    header = HEADER.fullmatch(stripped)
    if header and (number == 1 or not header["tape"]):
        return Source(number, line, HEADER_LINE, program=int(header["number"]), name=header["name"],
                      tape=bool(header["tape"]))
    code, comment = _code(stripped)
    if code.startswith("/"):
        code = code[1:]     # optional block skip: read as run (the switch off, its state at power-on)
    if code.endswith(";"):
        code = code[:-1]
    if MACRO_LINE.match(code):
        return _macro(number, line, code, comment)
    words = _words(code)
    label = None
    if words and words[0][0] == "N":
        label = _whole(words.pop(0), "a sequence number")
    return Source(number, line, BLOCK if words else NOTHING, words, label, comment=comment)


def _macro(number: int, line: str, code: str, comment: str | None) -> Source:
    label = LABEL.match(code)
    if label is not None:
        code = code[label.end():]
    return Source(number, line, MACRO, label=int(label["number"]) if label else None, comment=comment,
                  macro=code.strip())


def _code(line: str) -> tuple[str, str | None]:
    """The line without its comments, and their text (inner parentheses left out); a `%` inside
    one would end the tape on a read-in."""
    depth, kept, said, closed = 0, [], [], False
    for char in line:
        if depth == 0 and closed and not char.isspace() and char not in "(;":
            raise Refused(f"{COMMENT_REASON}: the control would read what follows the ) as words")
        if char == "(":
            depth += 1
        elif char == ")":
            if depth == 0:
                raise Refused("a ) without its ( : the control would read the rest as words")
            depth -= 1
            closed = depth == 0
        elif depth:
            if char == "%":
                raise Refused("a % inside a comment ends the program on a read-in")
            said.append(char)
        else:
            kept.append(char)
    if depth:
        raise Refused("a comment without its closing ): the control would read the next line as the comment")
    return "".join(kept).strip(), ("".join(said).strip() if "(" in line else None)


def _words(code: str) -> list[tuple[str, str]]:
    words, at = [], 0
    while at < len(code):
        match = WORD.match(code, at)
        if match is None:
            rest = code[at:].strip()
            if not rest:
                break
            token = rest.split()[0]
            why = why_not_plain(token, None) if token[:1].isalpha() else None
            if why:
                raise Refused(f"{token}: {why}")
            raise Refused(f"{token!r} is not a word of the ISO lathe grammar (one capital letter and "
                          "a plain number)")
        _whole_token(code, match)
        words.append((match.group(1), match.group(2)))
        at = match.end()
    return words


def _whole_token(code: str, match: re.Match[str]) -> None:
    """A number that runs on into an exponent (F1e-05, X1.5E3) is refused as the whole token, not
    read as a word and a stray rest."""
    token = code[match.start():].split()[0] if code[match.start():].strip() else ""
    if EXPONENT.match(code, match.end()):
        why = why_not_plain(token.lstrip(), None)
        raise Refused(f"{token.strip()}: {why or 'an exponent'}")


def _whole(word: tuple[str, str], what: str) -> int:
    letter, text = word
    if not re.fullmatch(r"\d+", text):
        raise Refused(f"{letter}{text} is not {what} (a whole number)")
    return int(text)
