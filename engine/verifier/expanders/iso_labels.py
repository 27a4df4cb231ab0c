"""The sequence numbers N of an ISO lathe file, program by program (issue 27, adversary 27b H6):
a G70–G73 P/Q and an M97 P find their N in the program they run in (the main program, or the
subprogram O<n> … M99 being run), never in another program of the file; an N a reference names
that stands twice in that program is refused (which one the control's search finds is its own).
Source: Haas 96-8000, M97 "must match a line number within the same program"."""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .iso_lines import Source

HEADER_LINE, BLOCK = "header", "block"     # the kinds of engine.verifier.expanders.iso_lines
LABEL_CYCLES = frozenset({70, 71, 72, 73})   # the cycles whose P/Q are sequence numbers


class Labels:
    """Each line's program (a count of the O lines before it) and each program's N numbers."""

    def __init__(self, sources: list[Source]) -> None:
        self.program_of: list[int] = []
        self.found: dict[int, dict[int, list[int]]] = {}
        program = 0
        for index, source in enumerate(sources):
            if source.kind == HEADER_LINE:
                program += 1
            self.program_of.append(program)
            if source.label is not None:
                self.found.setdefault(program, {}).setdefault(source.label, []).append(index)
        self.first = {program: {number: at[0] for number, at in found.items()}
                      for program, found in self.found.items()}

    def within(self, index: int, source: Source) -> dict[int, int]:
        """The N numbers of the program line `index` is in; a reference of its block to an N that
        stands twice there is refused naming it."""
        program = self.program_of[index] if index < len(self.program_of) else -1
        found = self.found.get(program, {})
        for number in _references(source):
            if len(found.get(number, [])) > 1:
                raise source.refuse(f"N{number} stands {len(found[number])} times in this program: which one the "
                                    "control's search finds is not proved; number the blocks once")
        return self.first.get(program, {})


def _references(source: Source) -> list[int]:
    """The sequence numbers the block refers to: G70–G73 P and Q, M97 P."""
    codes = {(letter, text.lstrip("0") or "0") for letter, text in source.words if letter in ("G", "M")}
    refers = any(("G", str(code)) in codes for code in LABEL_CYCLES) or ("M", "97") in codes
    if source.kind != BLOCK or not refers:
        return []
    return [int(text) for letter, text in source.words if letter in ("P", "Q") and text.isdigit()]
