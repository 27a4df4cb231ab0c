"""A program read for the simulation with the verifier's own reader (engine.verifier:
the machine's dialect, line by line), plus the two things the verifier reads but does not keep:
the signed EGON terms (engine.simulation.hobbing.coupling) and a block's G and M codes (M20/M21 clamp
and release the tailstock, G4 dwells). A line the verifier refuses the simulation refuses too:
it cannot follow what it cannot read (fail closed)."""
from __future__ import annotations

from functools import lru_cache

import msgspec

from ...machines.records import Machine
from ...verifier import grammar
from ...verifier.blocks import TOKEN
from ...verifier.expansion import ExpansionRefused, PlainLine, as_written, expand
from ...verifier.lines import Line, read_line
from ...verifier.refusals import Refused
from .fanuc_egb import c_word_problem
from .report import SimulationError, where


class Step(msgspec.Struct, frozen=True):
    """One line of the program as the simulation follows it, with the G and M codes it gives."""
    number: int        # line number, from 1
    line: str          # as emitted
    item: Line         # what the verifier read it as (kind: header, comment, block, statement, shift)
    g_codes: frozenset = frozenset()
    m_codes: frozenset = frozenset()
    kind: str = ""   # the item's kind, kept: the rules ask it of every step, hundreds of times

    def __post_init__(self) -> None:
        """Only copies item.kind: running again (a Struct does when it is unpickled) changes nothing."""
        msgspec.structs.force_setattr(self, "kind", self.item.kind)


def machine_dialect(machine: Machine):
    """The grammar the verifier reads this machine's programs with, the record's door M codes included."""
    return grammar.dialect_for(machine)


def readable_dialect(machine: Machine):
    """The machine's grammar, or SimulationError: a machine whose programs no grammar reads."""
    try:
        return machine_dialect(machine)
    except Refused as refusal:
        raise SimulationError(f"machine {machine.name}: {refusal}; the simulation cannot read its programs") from None


def read_item(dialect, number: int, line: str, name: str, text: str | None = None):
    """One line read as the verifier reads it, or SimulationError: a program the simulation cannot
    follow is refused (shared by the hobbing and the turning simulation). `text` is the plain
    line an expander made of `line` (engine.verifier.expansion); None: the line is plain."""
    try:
        return read_line(dialect, line if text is None else text)
    except Refused as refusal:
        raise SimulationError(f"{where(name, number, line)}: the simulation cannot read it ({refusal}); "
                              "a program it cannot follow is refused") from None


def plain_lines(dialect, lines: list[str], machine: Machine, name: str) -> list[PlainLine]:
    """The lines the control runs, as the verifier expands them (cycles, subprograms, parameters
    and jumps of a real program: engine.verifier.expansion), each with the line it comes from."""
    try:
        plain = expand(dialect.expander, lines, machine)
    except ExpansionRefused as refusal:
        raise SimulationError(f"{where(name, refusal.number, refusal.source)}: the simulation cannot follow it "
                              f"({refusal}); a program it cannot follow is refused") from None
    except Refused as refusal:
        raise SimulationError(f"{name}: the simulation cannot follow it ({refusal})") from None
    return as_written(lines) if plain is None else plain


def read_program(lines: list[str], machine: Machine, name: str) -> list[Step]:
    dialect = readable_dialect(machine)
    return [_step(dialect, plain, name) for plain in plain_lines(dialect, lines, machine, name)]


def _step(dialect, plain: PlainLine, name: str) -> Step:
    number, line, text = plain.number, plain.source, plain.text
    if dialect.comment.startswith("parentheses"):   # ISO and Fanuc hobbing: `(text)` comments
        problem = c_word_problem(text.partition("(")[0]) if dialect.synchronisations else None
        if problem:
            raise SimulationError(f"{where(name, number, line)}: {problem}")
        item = read_item(dialect, number, line, name, text)
        if item.kind == "header":
            return Step(number, line, item)
        line, text = semicolon_form(line), semicolon_form(text)
    else:
        item = read_item(dialect, number, line, name, text)
    if item.kind != "block":
        return Step(number, line, item)
    return Step(number, line, item, *block_codes(text.partition(";")[0]))


def semicolon_form(line: str) -> str:
    """An ISO line `code (comment)` as `code ; comment`, the form the header and cut-comment rules
    read (`(CYCLE TIME 1.6 MIN)` is `; CYCLE TIME 1.6 MIN`; the verifier has read it as one
    comment at the end of the block). A Fanuc program's findings quote its lines in this form."""
    code, parenthesis, comment = line.partition("(")
    if not parenthesis:
        return line
    return f"{code}; {comment.removesuffix(')')}" if code.strip() else f"; {comment.removesuffix(')')}"


@lru_cache(maxsize=4096)
def block_codes(code: str) -> tuple[frozenset, frozenset]:
    """The G and the M codes of a block's words (its text before the comment). Remembered: a
    batch's programs repeat most of their blocks (the approach, the retract, the M codes)."""
    codes: dict[str, set[int]] = {"G": set(), "M": set()}
    for token in code.split():
        word = TOKEN.fullmatch(token)
        assert word is not None   # the verifier read the block word by word
        address, equals, text = word.groups()
        if address in codes and not equals:
            codes[address].add(int(text))
    return frozenset(codes["G"]), frozenset(codes["M"])
