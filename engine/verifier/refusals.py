"""What the verifier says when it refuses a program: the program, the line number, the block as
emitted (escaped, so the message stays one line whatever the block holds) and the reason."""
from __future__ import annotations

from ..errors import EngineError

SHOWN_CHARACTERS = 80   # of a block or a name in a message; a longer one is cut and marked


class LimitError(EngineError):
    """A program the verifier refuses: outside a machine or working-area limit, or not readable
    as plain blocks of the machine's dialect. Nothing of it is stored or written."""


class Refused(Exception):
    """The reason one block (or the machine record) is refused; the walk adds where."""


def shown(text: str) -> str:
    """Quoted and escaped: a control character in a block shows as \\n, \\x00 …, never as itself."""
    cut = text[:SHOWN_CHARACTERS]
    return repr(cut) + ("…" if len(text) > SHOWN_CHARACTERS else "")


def shown_name(name: str) -> str:
    return name if name.isascii() and name.isprintable() and len(name) <= SHOWN_CHARACTERS else shown(name)


def line_refused(program_name: str, number: int, line: str, reason: str) -> LimitError:
    return LimitError(f"{shown_name(program_name)} line {number} {shown(line)}: {reason}; nothing stored")
