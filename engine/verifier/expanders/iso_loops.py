"""The WHILE [...] DO m … END m loops of an ISO lathe program paired before it runs (issue 27),
with the structure rules of Fanuc custom macro B ("Repetition (WHILE statement)"): loops are
numbered 1 to 3; a loop may hold another (three deep at most) but DO ranges may not overlap, and a
loop held inside another uses a different number; a jump may leave a loop but not enter one from
outside. A Fanuc stops with an alarm on each of these, so the verifier refuses them naming the line
(the alarm numbers were not confirmed: docs/reference/iso-lathe.md). Each program of the file
(main program, O<n> subprograms) is paired on its own."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

import engine.verifier.expanders.iso_lines as iso_lines
from engine.verifier.expanders.iso_macro import MacroError

if TYPE_CHECKING:
    from engine.verifier.expanders.iso_lines import Source

WHILE_DO = re.compile(r"WHILE\s*\[.*\]\s*DO\s*(?P<id>\d+)", re.DOTALL)
END = re.compile(r"END\s*(?P<id>\d+)")


class Loops:
    """pairs: WHILE line -> its END line and back; inside: line -> the WHILE lines of the loops
    around it (the WHILE line itself is outside its own loop, its END inside)."""

    def __init__(self, sources: list[Source]) -> None:
        self.pairs: dict[int, int] = {}
        self.inside: dict[int, frozenset[int]] = {}
        self.sources = sources
        open_loops: list[tuple[int, int]] = []          # (loop number, WHILE line index)
        for index, source in enumerate(sources):
            if source.kind == iso_lines.HEADER_LINE:
                self._closed(open_loops)
            self.inside[index] = frozenset(start for _, start in open_loops)
            self._take(index, source, open_loops)
        self._closed(open_loops)

    def _take(self, index: int, source: Source, open_loops: list[tuple[int, int]]) -> None:
        code = (source.macro or "") if source.kind == iso_lines.MACRO else ""
        loop, end = WHILE_DO.fullmatch(code), END.fullmatch(code)
        if loop is not None:
            number = int(loop["id"])
            if any(number == open_number for open_number, _ in open_loops):
                raise source.refuse(f"DO {number} inside a loop DO {number}: a loop inside another needs a "
                                    "different number (an alarm on the control)")
            open_loops.append((number, index))
        elif end is not None:
            self._end(index, source, int(end["id"]), open_loops)

    def _end(self, index: int, source: Source, number: int, open_loops: list[tuple[int, int]]) -> None:
        if not any(number == open_number for open_number, _ in open_loops):
            raise source.refuse(f"END {number} without its WHILE [...] DO {number} before it")
        if open_loops[-1][0] != number:
            raise source.refuse(f"END {number} while DO {open_loops[-1][0]} inside it is still open: the DO "
                                "ranges overlap (an alarm on the control)")
        _, start = open_loops.pop()
        self.pairs[start], self.pairs[index] = index, start

    def _closed(self, open_loops: list[tuple[int, int]]) -> None:
        if open_loops:
            number, start = open_loops[-1]
            raise self.sources[start].refuse(f"DO {number} without its END {number}")

    def check_jump(self, here: int, target: int, label: int) -> None:
        """A GOTO may leave loops but not enter one it is not already in."""
        entered = self.inside.get(target, frozenset()) - self.inside.get(here, frozenset())
        if entered:
            start = min(entered)
            raise MacroError(f"GOTO {label} jumps into the loop of line {self.sources[start].number} "
                                f"({self.sources[start].macro}) from outside it (an alarm on the control)")
