"""Checks an emitted 840D hobbing program against its machine and its own working area,
before anything is stored or written (design notes §6, §7)."""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import EngineError
from ..gears.records import Machine

_COMMENT = re.compile(r";.*$")
_CALL = re.compile(r"\([^)]*\)")
_WORD = re.compile(r"(?<![A-Z_$])([XYZSG])\s*=?\s*([-+]?(?:\d+\.?\d*|\.\d+))")
AXES = ("X", "Y", "Z")


class LimitError(EngineError):
    """A program exceeds a machine or working-area limit; nothing is stored."""


@dataclass
class _State:
    lower: dict | None = None
    upper: dict | None = None
    limits_on: bool = False


def check_program(lines: list[str], machine: Machine, program_name: str = "program",
                  row_ids: list[int] | None = None, known_words: dict | None = None) -> None:
    """`known_words`: words of lines a template always emits the same (by row id), parsed once
    per template instead of once per program."""
    state = _State()
    for number, line in enumerate(lines, start=1):
        words = known_words.get(row_ids[number - 1]) if known_words else None
        problem = _check_line(line, _words(line) if words is None else words, machine, state)
        if problem:
            raise LimitError(f"{program_name} line {number} {line.strip()!r}: {problem}; nothing stored")


def check_table_speed(gear_id, teeth: int, starts: int, hob_speed: float, machine: Machine) -> None:
    """The table turns at n0·z0/z2 (§B4); a gear with few teeth turns it fastest."""
    table_speed = hob_speed * starts / teeth
    if machine.table_speed_max is not None and table_speed > machine.table_speed_max:
        raise LimitError(f"gear {gear_id}: table speed {table_speed:.1f} r/min ({teeth} teeth) exceeds "
                         f"{machine.name}'s {machine.table_speed_max:g} r/min; lower the hob speed; nothing stored")


def words(line: str) -> list[tuple[str, float]]:
    """The address words of a block that the check reads: (letter, value) for X, Y, Z, S, G."""
    return _words(line)


def _words(line: str) -> list[tuple[str, float]]:
    if line.startswith(("%", ";")):
        return []
    code = line.upper()
    if ";" in code:
        code = _COMMENT.sub("", code)
    if "(" in code:
        code = _CALL.sub("", code)
    return [(letter, float(value)) for letter, value in _WORD.findall(code)]


def _check_line(line: str, words: list, machine: Machine, state: _State) -> str | None:
    if not words:
        if "WALIMON" in line.upper():
            state.limits_on = True
        return None
    codes, axes = set(), {}
    for letter, value in words:
        if letter == "G":
            codes.add(value)
        elif letter == "S":
            if value > machine.spindle_max:
                return f"spindle speed S{value:g} exceeds the machine's {machine.spindle_max:g} r/min"
        else:
            axes[letter] = value
    if 91 in codes:
        return "incremental G91 moves cannot be verified; program absolute positions (G90)"
    if 25 in codes or 26 in codes:
        return _set_limit(25 in codes, axes, machine, state)
    return _check_move(axes, machine, state) if axes else None


def _set_limit(is_lower: bool, axes: dict, machine: Machine, state: _State) -> str | None:
    for axis, value in axes.items():
        problem = outside_travel(axis, value, machine)
        if problem:
            return "working-area limit " + problem
    if is_lower:
        state.lower = axes
    else:
        state.upper = axes
    return None


def _check_move(axes: dict, machine: Machine, state: _State) -> str | None:
    if not state.limits_on or state.lower is None or state.upper is None:
        return "motion before G25/G26 and WALIMON set the working area"
    for axis, value in axes.items():
        problem = outside_travel(axis, value, machine)
        if problem:
            return problem
        low, high = state.lower.get(axis), state.upper.get(axis)
        if (low is not None and value < low) or (high is not None and value > high):
            return f"{axis}{value:g} lies outside the working area G25/G26 {axis} {low:g}…{high:g}"
    return None


def outside_travel(axis: str, value: float, machine: Machine) -> str | None:
    low, high = getattr(machine, f"{axis.lower()}_min"), getattr(machine, f"{axis.lower()}_max")
    if value < low or value > high:
        return f"{axis}{value:g} exceeds the travel of {machine.name} ({axis} {low:g}…{high:g})"
    return None
