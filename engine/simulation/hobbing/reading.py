"""A program read for the simulation with the verifier's own reader (engine.verifier:
the machine's dialect, line by line), plus the two things the verifier reads but does not keep:
the signed EGON terms (engine.simulation.hobbing.coupling) and a block's G and M codes (M20/M21 clamp
and release the tailstock, G4 dwells). A line the verifier refuses the simulation refuses too:
it cannot follow what it cannot read (fail closed)."""
from __future__ import annotations

from dataclasses import dataclass

from ...machines.records import Machine
from ...verifier import grammar
from ...verifier.blocks import TOKEN
from ...verifier.lines import Line, read_line
from ...verifier.refusals import Refused
from .report import SimulationError, where


@dataclass(frozen=True, slots=True)
class Step:
    number: int        # line number, from 1
    line: str          # as emitted
    item: Line         # what the verifier read it as (kind: header, comment, block, statement, shift)
    g_codes: frozenset = frozenset()
    m_codes: frozenset = frozenset()

    @property
    def kind(self) -> str:
        return self.item.kind


def machine_dialect(machine: Machine):
    """The grammar the verifier reads this machine's programs with, the record's door M codes included."""
    return grammar.dialect_for(machine)


def readable_dialect(machine: Machine):
    """The machine's grammar, or SimulationError: a machine whose programs no grammar reads."""
    try:
        return machine_dialect(machine)
    except Refused as refusal:
        raise SimulationError(f"machine {machine.name}: {refusal}; the simulation cannot read its programs") from None


def read_item(dialect, number: int, line: str, name: str):
    """One line read as the verifier reads it, or SimulationError: a program the simulation cannot
    follow is refused (shared by the hobbing and the turning simulation)."""
    try:
        return read_line(dialect, line)
    except Refused as refusal:
        raise SimulationError(f"{where(name, number, line)}: the simulation cannot read it ({refusal}); "
                              "a program it cannot follow is refused") from None


def read_program(lines: list[str], machine: Machine, name: str) -> list[Step]:
    dialect = readable_dialect(machine)
    return [_step(dialect, number, line, name) for number, line in enumerate(lines, start=1)]


def _step(dialect, number: int, line: str, name: str) -> Step:
    item = read_item(dialect, number, line, name)
    if item.kind != "block":
        return Step(number, line, item)
    codes: dict[str, set[int]] = {"G": set(), "M": set()}
    for token in line.partition(";")[0].split():
        word = TOKEN.fullmatch(token)
        assert word is not None   # the verifier read the block word by word
        address, equals, text = word.groups()
        if address in codes and not equals:
            codes[address].add(int(text))
    return Step(number, line, item, frozenset(codes["G"]), frozenset(codes["M"]))
