"""The machine's own limits (design notes §6): travel per axis, the spindle's maximum, the
table's maximum speed, the feed a thread's lead and spindle speed make. No program exceeding
one is stored or written."""
from __future__ import annotations

from ...gears.records import Machine
from .refusals import LimitError, Refused
from .words import MAX_FEED


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


def check_table(speed: float, ratio: float, machine: Machine, differential: tuple = ()) -> None:
    """The table turns at n0·z0/z2 (reference §B4) plus, for each differential axis moving at v
    mm/min with k degrees of C per mm, k·v/360 r/min (reference §A5: n_C = (z0/z2)·n_B ±
    k_Y·v_Y ± k_Z·v_Z). `differential`: (axis, k, v) of each moving leading axis; the terms
    are added as if their signs agreed, the most the table can turn."""
    table_speed = speed * ratio + sum(factor * velocity / 360.0 for _, factor, velocity in differential)
    if machine.table_speed_max is not None and table_speed > machine.table_speed_max:
        terms = "".join(f" + {axis} {factor:g}°/mm × {velocity:g} mm/min" for axis, factor, velocity in differential)
        raise Refused(f"the table turns at {table_speed:.1f} r/min (S{speed:g} × {ratio:g}{terms}), above "
                      f"{machine.name}'s {machine.table_speed_max:g} r/min")


def check_thread(lead: float, speed: float, word: str) -> None:
    """A thread's tool travels lead × S mm/min along Z: at most the feed the verifier allows."""
    if lead * speed > MAX_FEED:
        raise Refused(f"the thread's lead {word}{lead:g} at S{speed:g} feeds {lead * speed:g} mm/min along Z, "
                      f"above {MAX_FEED:g} (mm/min, about a rapid traverse)")


def check_table_speed(gear_id, teeth: int, starts: int, hob_speed: float, machine: Machine) -> None:
    """Before the program is made: the table turns at n0·z0/z2 (§B4); few teeth turn it fastest."""
    table_speed = hob_speed * starts / teeth
    if machine.table_speed_max is not None and table_speed > machine.table_speed_max:
        raise LimitError(f"gear {gear_id}: table speed {table_speed:.1f} r/min ({teeth} teeth) exceeds "
                         f"{machine.name}'s {machine.table_speed_max:g} r/min; lower the hob speed; nothing stored")
