"""The ISO lathe expander (Fanuc/Haas style, issue 27): a program as shops write it followed in
order, the way the control runs it, into plain blocks the ISO lathe grammar reads: absolute mm
(inch programs under G20 converted, U/W increments added up, G50 X/Z coordinate setting applied),
the motion G code in every moving block, the spindle speed a bound in r/min (G96 constant surface
speed read as its clamp G50 S, the worst case), feed per revolution (G99) as mm/min at that speed,
G28 as the moves to the machine's reference point (machine.reference_x/_z), the cycles G70–G76 as
the moves they make (engine.verifier.expanders.cycles), subprograms in the file (M98 P, Haas M97)
inlined. What it cannot follow it refuses naming the line and the construct (fail closed).
Facts and sources: docs/reference/iso-lathe.md."""
from __future__ import annotations

from typing import TYPE_CHECKING

import engine.verifier.expanders.iso_labels as iso_labels
import engine.verifier.expanders.iso_rules as iso_rules
import engine.verifier.expansion as expansion  # read at call time: a test may lower MAX_STEPS

from ...names import is_safe
from ..expansion import ExpansionRefused, PlainLine, register_expander
from .iso_lines import BLOCK, HEADER_LINE, MACRO, TAPE, Source, read_sources
from .iso_macro_flow import MacroRun
from .iso_modes import Modes
from .iso_moves import take_block

if TYPE_CHECKING:
    from ...machines.records import Machine

END_CODES = (30, 2)


@register_expander("iso")
def expand_iso(lines: list[str], machine: Machine) -> list[PlainLine]:
    sources = read_sources(lines)
    return Run(sources, machine).run()


class Run:
    """The program's lines, its labels and subprograms, and the walk through them."""

    def __init__(self, sources: list[Source], machine: Machine) -> None:
        self.sources, self.machine = sources, machine
        self.modes = Modes(machine)
        self.plain: list[PlainLine] = []
        self.labels: dict[int, int] = {}
        self.programs: dict[int, int] = {}
        for index, source in enumerate(sources):
            if source.label is not None:
                self.labels.setdefault(source.label, index)
            if source.kind == HEADER_LINE and source.program is not None:
                self.programs.setdefault(source.program, index)
        self.macro = MacroRun(sources, self.labels)
        self.in_program = iso_labels.Labels(sources)     # N numbers program by program: G70–G73 P/Q, M97 P

    def run(self) -> list[PlainLine]:
        start = self._start()
        self._power_on(start)
        self._walk(start)
        closing = next((s for s in reversed(self.sources) if s.kind != "nothing"), None)
        if closing is not None and closing.kind == TAPE and self.modes.ended:
            self.plain.append(PlainLine("%", closing.number, closing.text))
        return self.plain

    def _start(self) -> int:
        """The lines before the first block: `%` and the program number line pass on as they are."""
        for index, source in enumerate(self.sources):
            if source.kind == TAPE or source.kind == HEADER_LINE:
                if source.tape:
                    self.plain.append(PlainLine("%", source.number, source.text))
                self.plain.extend(PlainLine(text, source.number, source.text) for text in _header_texts(source))
                if source.kind == HEADER_LINE:
                    return index + 1
            elif source.kind in (BLOCK, MACRO):
                return index
        return len(self.sources)

    def _power_on(self, start: int) -> None:
        """The modes the record says the control is in at power-on (machine.power_on), stated as a
        plain block before the program's first, as if the program had written them."""
        codes = (getattr(self.machine, "power_on", None) or "").split()
        first = next((s for s in self.sources[start:] if s.kind in (BLOCK, MACRO)), None)
        if codes and first is not None:
            fault = iso_rules.power_on_fault(codes, getattr(self.machine, "gcode_system", None))
            if fault is not None:
                raise first.refuse(fault)
            words = [("G", code[1:]) for code in codes]
            take_block(Source(first.number, first.text, BLOCK, words), self.modes, self.sources, self.labels,
                       self.plain)

    def _walk(self, index: int) -> None:
        stack: list[tuple[int, int, int]] = []     # (return index, start index, passes left)
        steps = 0
        while not self.modes.ended:
            steps += 1
            if steps > expansion.MAX_STEPS:
                raise self.sources[min(index, len(self.sources) - 1)].refuse(
                    f"the program runs more than {expansion.MAX_STEPS:,} blocks (a loop that never ends?)")
            if index >= len(self.sources):
                last = self.sources[-1] if self.sources else Source(0, "", "nothing")
                raise last.refuse("the program does not end with M30 (or M02)")
            source = self.sources[index]
            index = self._take(source, index, stack)
        self._nothing_after(index, stack)

    def _nothing_after(self, index: int, stack: list[tuple[int, int, int]]) -> None:
        """After the main program's M30 only subprograms (O<n> … M99) and the closing % may follow."""
        if stack:
            return
        for source in self.sources[index:]:
            if source.kind == HEADER_LINE:
                return
            if source.kind in (BLOCK, MACRO):
                raise source.refuse("a line after M30: the program ends there, and the control reads nothing "
                                    "after it")

    def _take(self, source: Source, index: int, stack: list[tuple[int, int, int]]) -> int:
        if source.kind == TAPE:
            raise source.refuse("the tape mark % belongs only in the first or last line (it ends the program on a "
                                "read-in)")
        if source.kind == HEADER_LINE:
            raise source.refuse(f"a second program number O{source.program} before M30: the main program has no end")
        if source.kind == MACRO:
            taken = self.macro.take(source, index, 3 if self.modes.scale == 1.0 else 4)
            if isinstance(taken, int):
                return taken
            source = taken
        if source.kind != BLOCK:
            if source.comment is not None:
                self.plain.append(PlainLine(f"({source.comment})", source.number, source.text))
            return index + 1
        codes = {letter for letter, _ in source.words}
        m_codes = [_int(source, text) for letter, text in source.words if letter == "M"]
        if 98 in m_codes or 97 in m_codes:
            iso_rules.check_call(source, 97 if 97 in m_codes else 98)
            return self._call(source, index, stack, local=97 in m_codes)
        if 99 in m_codes:
            iso_rules.check_call(source, 99)
            return self._return(source, stack)
        jump = take_block(source, self.modes, self.sources, self.in_program.within(index, source), self.plain)
        if codes & {"M"} and any(code in END_CODES for code in m_codes):
            self.modes.ended = True
        return jump if jump is not None else index + 1

    def _call(self, source: Source, index: int, stack: list[tuple[int, int, int]], local: bool) -> int:
        words = dict(source.words)
        if "P" not in words:
            raise source.refuse("M98/M97 without its P (the subprogram or label to call)")
        number, repeats = _int(source, words["P"]), _int(source, words.get("L", "1"))
        if not local and len(words["P"]) > 4 and "L" not in words:
            repeats, number = divmod(number, 10000)     # Fanuc P<repeats><4-digit program>
        target = self.in_program.within(index, source).get(number) if local else self.programs.get(number)
        if target is None:
            what = f"label N{number}" if local else f"subprogram O{number:04d}"
            raise source.refuse(f"M9{'7' if local else '8'} P{words['P']} calls {what}, which is not in this file: "
                                "an external subprogram cannot be verified; put it in the file")
        if len(stack) >= 10:
            raise source.refuse("subprograms nested more than 10 deep")
        start = target if local else target + 1
        if repeats < 1:
            return index + 1
        stack.append((index + 1, start, repeats - 1))
        return start

    def _return(self, source: Source, stack: list[tuple[int, int, int]]) -> int:
        if not stack:
            raise source.refuse("M99 in the main program starts it again for ever; end it with M30")
        back, start, left = stack.pop()
        if left > 0:
            stack.append((back, start, left - 1))
            return start
        return back


def _header_texts(source: Source) -> list[str]:
    """`%`, or the program number with its name. On a Fanuc control the text after the O number is
    a comment the program list shows (the program is stored under its number): a text that is not
    a program name (`( FANUC 0T )`) is passed on as a comment line of its own, not as the name."""
    if source.kind == TAPE:
        return ["%"]
    number = f"O{source.program:04d}"
    name = source.name.strip() if source.name is not None else None
    if name is None:
        return [number]
    if is_safe("program", name):
        return [f"{number} ({name})"]
    return [number, f"({name})"]


def _int(source: Source, text: str) -> int:
    if not text.isdigit():
        raise source.refuse(f"{text} is not a whole number")
    return int(text)


__all__ = ["ExpansionRefused", "expand_iso"]
