"""The machine's own limits (design notes §6): travel per axis, the spindle's maximum, the
table's maximum speed. No program exceeding one is stored or written."""
from __future__ import annotations

from ...gears.records import Machine
from .refusals import LimitError, Refused


def outside_travel(axis: str, value: float, machine: Machine) -> str | None:
    low, high = getattr(machine, f"{axis.lower()}_min"), getattr(machine, f"{axis.lower()}_max")
    if not low <= value <= high:
        return f"{axis}{value:g} exceeds the travel of {machine.name} ({axis} {low:g}…{high:g})"
    return None


def check_travel(axis: str, value: float, machine: Machine, what: str = "") -> None:
    problem = outside_travel(axis, value, machine)
    if problem:
        raise Refused(what + problem)


def check_spindle(speed: float, machine: Machine) -> None:
    if speed > machine.spindle_max:
        raise Refused(f"spindle speed S{speed:g} exceeds {machine.name}'s {machine.spindle_max:g} r/min")


def check_table(speed: float, ratio: float, machine: Machine) -> None:
    """The table turns at n0·z0/z2 (reference §B4): the spindle speed times the EGON ratio."""
    table_speed = speed * ratio
    if machine.table_speed_max is not None and table_speed > machine.table_speed_max:
        raise Refused(f"the table turns at {table_speed:.1f} r/min (S{speed:g} × {ratio:g}), above "
                      f"{machine.name}'s {machine.table_speed_max:g} r/min")


def check_table_speed(gear_id, teeth: int, starts: int, hob_speed: float, machine: Machine) -> None:
    """Before the program is made: the table turns at n0·z0/z2 (§B4); few teeth turn it fastest."""
    table_speed = hob_speed * starts / teeth
    if machine.table_speed_max is not None and table_speed > machine.table_speed_max:
        raise LimitError(f"gear {gear_id}: table speed {table_speed:.1f} r/min ({teeth} teeth) exceeds "
                         f"{machine.name}'s {machine.table_speed_max:g} r/min; lower the hob speed; nothing stored")
