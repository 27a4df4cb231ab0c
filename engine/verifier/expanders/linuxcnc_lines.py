"""One LinuxCNC line as the RS274/NGC interpreter reads it (docs/reference/linuxcnc-lathe.md §1):
comments `( … )` and `; …` taken out, letters lower case, spaces and tabs ignored, a line number
`N…` dropped; what is left is an o-word statement (`o100 while [#1 gt 0]`, `o<od> call [1][2]`)
or words (`g1 x[#1*2] f#<feed>`) and parameter settings (`#1 = [#1 + 1]`).

A `%` line marks the start and the end of the program text; `/` (block delete) is refused, since
whether the line runs is the operator's switch, not the program's."""
from __future__ import annotations

import re

import msgspec

from ..refusals import Refused

O_WORD = re.compile(r"o(\d+|<[^>]*>)([a-z]+)(.*)")
KEYWORDS = frozenset({"sub", "endsub", "call", "do", "while", "endwhile", "if", "elseif", "else", "endif",
                      "repeat", "endrepeat", "break", "continue", "return"})
LINE_NUMBER = re.compile(r"n\d+(?:\.\d*)?")


class OWord(msgspec.Struct, frozen=True):
    label: str          # "100" or "<od>"
    keyword: str        # "while", "call" …
    rest: str           # the condition, count or arguments (no spaces, lower case)


def code_of(line: str) -> str:
    """The line without its comments and spaces, lower case ('' for a comment or empty line)."""
    code, at = [], 0
    while at < len(line):
        char = line[at]
        if char == ";":
            break
        if char == "(":
            end = line.find(")", at)
            if end < 0:
                raise Refused("a comment ( … without its closing )")
            if "(" in line[at + 1:end]:
                raise Refused("a ( inside a comment: LinuxCNC refuses nested comments")
            at = end + 1
            continue
        code.append(char)
        at += 1
    text = "".join(code)
    if not text.isascii():
        raise Refused("a non-ASCII character outside a comment")
    return "".join(text.split()).lower()


def read(line: str) -> OWord | str:
    """An o-word statement, or the words of the line ('' for nothing to do)."""
    code = code_of(line)
    if code.startswith("/"):
        raise Refused("block delete /: whether the line runs is the operator's switch; remove the /")
    number = LINE_NUMBER.match(code)
    if number:
        code = code[number.end():]
    if not code.startswith("o"):
        return code
    match = O_WORD.fullmatch(code)
    if match is None or match.group(2) not in KEYWORDS:
        raise Refused("an o-word without one of " + ", ".join(sorted(KEYWORDS)))
    label, keyword, rest = match.groups()
    return OWord(label.lstrip("0") or "0" if label.isdigit() else label, keyword, rest)
