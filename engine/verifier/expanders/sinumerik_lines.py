"""One line of an 840D program as stored on the control, taken apart before it is run: its
block number N…, its label (`LOOP1:`), its code without the `;` comment (a comment may hold any
text, umlauts included; a `;` inside a "string" is no comment), and the code's words.

A word is an address with a number (`X12.5`, `G1`, `M30`), a name with `=` and an expression
(`X=R1+2`, `CR=5`, `LIMS=3000`, `R1=2.5`, `T="ROUGH"`), a keyword (`DIAMON`, `GOTOF`), or a
name with arguments (`MSG("…")`, `CYCLE95(…)`). The control ignores case and the blanks around
operators; so does the reader, outside strings."""
from __future__ import annotations

import re

import msgspec

from ..characters import check_characters, check_comment_characters
from ..refusals import Refused

BLOCK_NUMBER = re.compile(r"(?:N|:)\d+\s*")
LABEL = re.compile(r"([A-Z_][A-Z0-9_]{1,31}):(?!=)\s*")
SPACED_OPERATOR = re.compile(r"\s*(==|<>|<=|>=|[=+\-*/<>,])\s*")
OPENING = re.compile(r"(?<=[A-Z0-9_])\s+\(|\(\s+")     # "MSG (" and "( R1" close up; ") K" stays two words
CLOSING = re.compile(r"\s+\)")
NAME = re.compile(r"\$?[A-Z_][A-Z0-9_]*")
ADDRESS_NUMBER = re.compile(r"([A-Z]+)(\d*)")
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)")
# An operator spelt as a word stands between blanks (`R1=R2 DIV 2`, the manual's spelling): the
# expression runs on across those blanks (reference sinumerik-lathe §S3).
WORD_OPERATORS = ("DIV", "MOD", "AND", "OR", "XOR")
WORD_OPERATOR = re.compile(rf" +(?:{'|'.join(WORD_OPERATORS)}) +(?=[^ ])")


class Word(msgspec.Struct, frozen=True):
    name: str           # address or name, upper case: "X", "CR", "R1", "DIAMON", "CYCLE95"
    value: str = ""     # the number, the expression after `=`, or the arguments inside (…)
    form: str = "number"   # "number" (X12.5), "equals" (X=…), "keyword" (DIAMON), "call" (MSG(…))


class SourceLine(msgspec.Struct, frozen=True):
    number: int                 # line number, from 1
    text: str                   # as written
    block_number: str | None    # "N10"
    label: str | None           # "LOOP1"
    code: str                   # without number, label and comment; blanks around operators removed
    comment_only: bool          # a line of nothing but a comment


def read_source(number: int, text: str) -> SourceLine:
    code, comment = _split_comment(text)
    code = _upper_outside_strings(code).strip()
    block = BLOCK_NUMBER.match(code)
    block_number = block.group(0).strip() if block else None
    code = code[block.end():] if block else code
    label_match = LABEL.match(code)
    label = label_match.group(1) if label_match else None
    code = code[label_match.end():] if label_match else code
    if block is None and (block := BLOCK_NUMBER.match(code)):     # a label before the block number
        block_number, code = block.group(0).strip(), code[block.end():]
    return SourceLine(number, text, block_number, label, _collapse(code.strip()),
                      comment and not code.strip() and block_number is None and label is None)


def check_line_characters(text: str) -> None:
    """The code holds printable ASCII only; the comment any printable text, no control character."""
    code, comment = _split_comment(text)
    check_characters(code)
    if comment:
        check_comment_characters(text[len(code):], len(code) + 1)


def _split_comment(text: str) -> tuple[str, bool]:
    """The code before the first `;` outside a string, and whether there was a comment."""
    quoted = False
    for index, character in enumerate(text):
        if character == '"':
            quoted = not quoted
        elif character == ";" and not quoted:
            return text[:index], True
    return text, False


def _upper_outside_strings(code: str) -> str:
    parts = code.split('"')
    return '"'.join(part if index % 2 else part.upper() for index, part in enumerate(parts))


def _collapse(code: str) -> str:
    parts = code.split('"')
    return '"'.join(part if index % 2 else _closed_up(part) for index, part in enumerate(parts))


def _closed_up(part: str) -> str:
    return CLOSING.sub(")", OPENING.sub("(", SPACED_OPERATOR.sub(r"\1", part)))


def words(code: str) -> list[Word]:
    """The words of `code`, in order; Refused for text that is no word."""
    found, position = [], 0
    while position < len(code):
        if code[position] == " ":
            position += 1
            continue
        word, position = _word(code, position)
        found.append(word)
    return found


def _word(code: str, position: int) -> tuple[Word, int]:
    name = NAME.match(code, position)
    if name is None:
        raise Refused(f"{code[position:position + 16]!r} is not a word of an 840D block")
    end = name.end()
    following = code[end:end + 1]
    if following == "=":
        value, end = _until_blank(code, end + 1)
        return Word(name.group(0), value, "equals"), end
    if following == "(":
        value, end = _until_blank(code, end)
        return Word(name.group(0), value, "call"), end
    return _address_word(code, name.group(0), end)


def _address_word(code: str, name: str, end: int) -> tuple[Word, int]:
    split = ADDRESS_NUMBER.fullmatch(name)
    if split is None or name.startswith("$"):
        raise Refused(f"{name}: a system variable or name the verifier cannot read as a word")
    letters, digits = split.groups()
    number = NUMBER.match(code, end) if not digits else re.compile(r"\.?\d*").match(code, end)
    rest = number.group(0) if number else ""
    if not digits and not rest:
        if name in WORD_OPERATORS:
            raise Refused(f"{name} is an operator between two values (R1=R2 {name} 2), not a word of its own")
        return Word(name, "", "keyword"), end
    return Word(letters, digits + rest, "number"), end + len(rest)


def _until_blank(code: str, position: int) -> tuple[str, int]:
    """An expression runs to the first blank outside parentheses and strings."""
    depth, quoted, index = 0, False, position
    while index < len(code):
        character = code[index]
        if character == '"':
            quoted = not quoted
        elif not quoted and character in "([":
            depth += 1
        elif not quoted and character in ")]":
            depth -= 1
        elif character == " " and depth <= 0 and not quoted:
            operator = WORD_OPERATOR.match(code, index)
            if operator is None:
                break
            index = operator.end()
            continue
        index += 1
    if quoted or depth > 0:
        raise Refused(f"{code[position:index]!r}: an unclosed string or parenthesis")
    return code[position:index], index
