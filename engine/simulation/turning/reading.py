"""A lathe program read for the turning simulation with the verifier's own reader (the
machine's dialect, line by line: engine.verifier), plus what the verifier reads but does not
keep: a block's G and M codes and the operation comment each template slot writes before its
tool change (`(OP n KIND Ttt)` in ISO, `; OP n KIND Tt` on the 840D). A line the verifier
refuses the simulation refuses too: it cannot follow what it cannot read (fail closed)."""
from __future__ import annotations

import re

import msgspec

from ...machines.records import Machine
from ...verifier.blocks import TOKEN, Block
from ...verifier.expansion import PlainLine
from ..hobbing.reading import plain_lines, read_item, readable_dialect

OPERATION_COMMENT = re.compile(r"\s*(?:\(|;)\s*OP (\d+) ([A-Z]+)\b")
ISO_COMMENT = re.compile(r"\([^()]*\)")


class Step(msgspec.Struct, frozen=True):
    number: int              # line number, from 1
    line: str                # as emitted
    block: Block | None      # None: a header or a comment
    g_codes: frozenset = frozenset()
    m_codes: frozenset = frozenset()
    operation: tuple[int, str] | None = None   # (n, KIND) of an operation comment
    blend: float = 0.0       # mm the control may run the move off its path (PlainLine.blend: LinuxCNC G64 P)


def read_lathe_program(lines: list[str], machine: Machine, name: str) -> list[Step]:
    """The steps of the lines the control runs (a real program's cycles, subprograms and
    parameters expanded as the verifier expands them), each naming the line as written."""
    dialect = readable_dialect(machine)
    return [_step(dialect, plain, name) for plain in plain_lines(dialect, lines, machine, name)]


def _step(dialect, plain: PlainLine, name: str) -> Step:
    number, line = plain.number, plain.source
    item = read_item(dialect, number, line, name, plain.text)
    comment = OPERATION_COMMENT.match(plain.text)
    operation = (int(comment.group(1)), comment.group(2)) if comment else None
    if not isinstance(item, Block):
        return Step(number, line, None, operation=operation)
    codes: dict[str, set[int]] = {"G": set(), "M": set()}
    for token in ISO_COMMENT.sub(" ", plain.text.partition(";")[0]).split():
        word = TOKEN.fullmatch(token)
        assert word is not None   # the verifier read the block word by word
        address, equals, text = word.groups()
        if address in codes and not equals:
            codes[address].add(int(text))
    return Step(number, line, item, frozenset(codes["G"]), frozenset(codes["M"]), operation, plain.blend)
