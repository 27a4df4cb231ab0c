"""Real programs expanded into the plain lines their dialect's grammar reads (issue 27).

A shop's own lathe program is not made of plain blocks alone: an ISO program calls canned cycles
(G70–G76) and subprograms in the file (M98/M99), an 840D program computes with R-parameters and
DEF variables and jumps (IF/GOTO/WHILE), a LinuxCNC program calls o-word subroutines with
numbered and named parameters. The verifier and the simulation follow the moves the control
makes, so a dialect that has such constructs names an expander: a bounded interpreter that turns
the program as written into the plain lines the control really runs, each tagged with the line
of the program it comes from. The verifier reads the plain lines with the dialect's grammar and
names the line as written when it refuses one; the turning simulation follows the same lines.

What an expander cannot turn into plain moves (a vendor cycle without a model, a subprogram not
in the file, a loop past its step bound) it refuses naming the line and the construct: fail
closed stays. A dialect without an expander is read line by line as written (the engine's own
output, whose lines are plain already)."""
from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING

import msgspec

from .refusals import Refused

if TYPE_CHECKING:
    from ..machines.records import Machine

# The most plain lines one program may expand to, and the most lines an interpreter may step
# through (a loop counts each pass): a program past either is refused, not followed for ever.
# An interpreter steps at about 40 µs a line, so a million steps is under a minute of CPU for the
# worst program (the adversary's 4.8 million-step loop ran past 5 minutes); a 100,000-line real
# program with its loops and subprograms stays well inside.
MAX_PLAIN_LINES = 1_000_000
MAX_STEPS = 1_000_000


class PlainLine(msgspec.Struct, frozen=True):
    """One line the dialect's grammar reads, and the line of the program it comes from."""
    text: str       # a plain line: a header, a comment or a block of address words
    number: int     # that program line's number, from 1
    source: str     # that program line as written
    # mm the control may run a move off its programmed path (LinuxCNC G64 P: blended corners,
    # collinear feeds merged): the turning simulation lets the move be anywhere that close to it;
    # 0 for every dialect that follows the programmed path exactly
    blend: float = 0.0


class ExpansionRefused(Refused):
    """A program line the expander cannot turn into plain lines; `number` and `source` say which."""

    def __init__(self, number: int, source: str, reason: str) -> None:
        super().__init__(reason)
        self.number, self.source = number, source


Expander = Callable[[list[str], "Machine"], list[PlainLine]]
EXPANDERS: dict[str, Expander] = {}    # expander name (Dialect.expander) -> the function
# expander name -> the module that registers it, imported on the first program of that dialect:
# an 840D hobbing program (no expander) loads none of the lathe interpreters (about 60 ms of a
# command's start, issue 28), a lathe program only its own
EXPANDER_MODULES = {
    "iso": "engine.verifier.expanders.iso",               # Fanuc/Haas lathe programs
    "linuxcnc": "engine.verifier.expanders.linuxcnc",     # LinuxCNC lathe programs
    "840d-lathe": "engine.verifier.expanders.sinumerik",  # 840D lathe programs
}


def register_expander(name: str) -> Callable[[Expander], Expander]:
    """Registers a dialect's expander under the name its Dialect row gives (Dialect.expander)."""
    def register(function: Expander) -> Expander:
        if name in EXPANDERS and EXPANDERS[name] is not function:
            raise ValueError(f"two expanders named {name!r}")
        EXPANDERS[name] = function
        return function
    return register


def expand(name: str | None, lines: list[str], machine: Machine) -> list[PlainLine] | None:
    """The plain lines of `lines` by the expander `name`; None for a dialect read as written.
    A dialect that names an expander no module registered is refused (fail closed)."""
    if name is None:
        return None
    plain = expander_named(name)(lines, machine)
    if len(plain) > MAX_PLAIN_LINES:
        raise Refused(f"the program expands to more than {MAX_PLAIN_LINES:,} blocks; split it")
    return plain


def expander_named(name: str) -> Expander:
    """The expander registered as `name`, its module imported on first use; refused when no
    module registers it (fail closed)."""
    if name not in EXPANDERS and name in EXPANDER_MODULES:
        importlib.import_module(EXPANDER_MODULES[name])
    expander = EXPANDERS.get(name)
    if expander is None:
        raise Refused(f"the {name} expander is not loaded (please report this)")
    return expander


def as_written(lines: list[str]) -> list[PlainLine]:
    """Every line as its own plain line (for a dialect whose expander passes a line on unchanged)."""
    return [PlainLine(line, number, line) for number, line in enumerate(lines, start=1)]
