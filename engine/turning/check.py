"""Checks an emitted lathe program against its machine before anything is stored or written:
X (a diameter) and Z within the travel, S within the spindle's maximum. The hobbing rules
(working area G25/G26 and WALIMON) do not apply: on an ISO lathe G25/G26 mean something
else, and a lathe program has no working-area limits to respect."""
from __future__ import annotations

from ..nc_check import LimitError, words
from ..records import Machine


def check_lathe_program(lines: list[str], machine: Machine, program_name: str = "program") -> None:
    for number, line in enumerate(lines, start=1):
        problem = line_problem(words(line), machine)
        if problem:
            raise LimitError(f"{program_name} line {number} {line.strip()!r}: {problem}; nothing stored")


def line_problem(found: list[tuple[str, float]], machine: Machine) -> str | None:
    for letter, value in found:
        if letter == "G" and value == 91:
            return "incremental G91 moves cannot be verified; program absolute positions (G90)"
        if letter == "S" and value > machine.spindle_max:
            return f"spindle speed S{value:g} exceeds {machine.name}'s {machine.spindle_max:g} r/min"
        if letter in "XYZ":
            low, high = getattr(machine, f"{letter.lower()}_min"), getattr(machine, f"{letter.lower()}_max")
            if not low <= value <= high:
                return f"{letter}{value:g} exceeds the travel of {machine.name} ({letter} {low:g}…{high:g})"
    return None
