"""Safe names: what a program, drawing, hob, gear class or machine may be called, as one table.

These names leave the database as text the machine reads: a program name becomes the
840D program `%_N_<name>_MPF` and the file `<name>.MPF` in --out; drawing, hob, class and
machine names are printed inside the program's comments (`; HOB …`, ISO `(DRAWING …)`).
A newline in any of them would start a new NC block after the comment, and a `/` or `..`
in a program name a file outside --out. So every name is checked where it enters (CSV
imports, DXF import, options) and where it is used, against the patterns below; the
database holds the same patterns (schema/schema.sql, function safe_name) for
what is written in SQL. A name that does not fit is refused, never altered.
"""
from __future__ import annotations

import re

import msgspec

from .errors import EngineError


class NameRule(msgspec.Struct, frozen=True):
    """A kind of name the engine stores (program, class, machine): the pattern it fits and the rule said to the user."""
    pattern: str     # a regular expression both Python and PostgreSQL read the same way (no anchors)
    rule: str        # what a name must be, said to the user

    def fits(self, name: object) -> bool:
        return isinstance(name, str) and re.fullmatch(self.pattern, name, re.ASCII) is not None


# 840D program names (docs/reference/hobbing.md §A1): letters, digits and _; the first two
# characters letters, or _ and a letter; at most 24 characters. The NC does not tell upper
# from lower case, so two names differing only in case are one program (engine.programs.outputs).
# Comments: `;` ends an 840D block's code and `(` `)` delimit an ISO comment, so neither may
# appear in a name printed inside one; nor may any control character.
NAME_RULES = {
    "program": NameRule(r"(?:[A-Za-z]{2}|_[A-Za-z])[A-Za-z0-9_]{0,22}",
                        "letters, digits and _, starting with two letters or _ and a letter, "
                        "at most 24 characters (an 840D program name)"),
    "drawing": NameRule(r"[A-Za-z0-9_][A-Za-z0-9_. -]{0,79}",
                        "letters, digits, _, -, . and spaces, starting with a letter, digit or _, "
                        "at most 80 characters"),
    "hob": NameRule(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,31}",
                    "letters, digits, _, - and ., starting with a letter or digit, at most 32 characters"),
    "class": NameRule(r"[a-z][a-z0-9_]{0,62}",
                      "lower-case letters, digits and _, starting with a letter, at most 63 characters"),
    "machine": NameRule(r"[A-Za-z][A-Za-z0-9_.-]{0,31}",
                        "letters, digits, _, - and ., starting with a letter, at most 32 characters"),
}

# Characters that end or hide an NC line: C0 controls but tab, DEL, C1 controls, the Unicode
# line and paragraph separators. No program line and no text of a job may hold one.
LINE_BREAKING = re.compile("[\x00-\x08\x0a-\x1f\x7f-\x9f\u2028\u2029]")

SHOWN_LENGTH = 60


def shown(value: object) -> str:
    """The value as a message shows it: quoted, control characters escaped, so the message
    stays one line; long values cut (the message only; the name itself is refused, not cut)."""
    text = repr(value)
    return text if len(text) <= SHOWN_LENGTH else f"{text[:SHOWN_LENGTH - 1]}…"


def said(kind: str, name: object) -> str:
    """A name in a message: as it is when it is safe, else shown (quoted and escaped)."""
    return name if isinstance(name, str) and is_safe(kind, name) else shown(name)   # a safe name is text


def is_safe(kind: str, name: object) -> bool:
    return NAME_RULES[kind].fits(name)


def checked(kind: str, name: object, what: str, remedy: str = "") -> str:
    """The name if it fits its kind's rule, else EngineError naming `what` (e.g. "hob id")."""
    if isinstance(name, str) and is_safe(kind, name):   # a safe name is text
        return name
    advice = f"; {remedy}" if remedy else ""
    raise EngineError(f"{what} {shown(name)} is not a safe {kind} name: use {NAME_RULES[kind].rule}{advice}")


def line_breaking(text: str) -> str | None:
    """The first character of `text` that would break an NC line, or None."""
    found = LINE_BREAKING.search(text)
    return found.group() if found else None
