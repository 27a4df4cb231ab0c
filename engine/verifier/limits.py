"""The machine's own limits (design notes §6): travel per axis, the spindle's maximum, the
table's maximum speed, the feed a thread's lead and spindle speed make. No program exceeding
one is stored or written."""
from __future__ import annotations

from ..machines.records import Machine
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


def check_speed_limit(limit: float, machine: Machine) -> None:
    """LIMS clamps the r/min of constant cutting speed G96: a clamp above the spindle's maximum
    bounds nothing the machine can do (reference sinumerik-lathe §S6)."""
    if limit > machine.spindle_max:
        raise Refused(f"spindle clamp LIMS={limit:g} exceeds {machine.name}'s {machine.spindle_max:g} r/min")


def check_table(speed: float, ratio: float, machine: Machine, differential: tuple[tuple[str, float, float], ...] = (),
                motion: str = "") -> None:
    """The table turns at n0·z0/z2 (reference §B4) plus, for each differential axis moving at v
    mm/min with k degrees of C per mm, k·v/360 r/min (reference §A5: n_C = (z0/z2)·n_B ±
    k_Y·v_Y ± k_Z·v_Z). `differential`: (axis, k, v) of each moving leading axis; the terms
    are added as if their signs agreed, the most the table can turn. `motion`: "G0 " for a rapid
    move, so the message says which traverse drives the table."""
    table_speed = abs(speed * ratio) + sum(abs(factor * velocity) / 360.0 for _, factor, velocity in differential)
    if machine.table_speed_max is not None and table_speed > machine.table_speed_max:
        terms = "".join(f" + {motion}{axis} {abs(factor):g}°/mm × {velocity:g} mm/min"
                        for axis, factor, velocity in differential)
        raise Refused(f"the table turns at {table_speed:.1f} r/min (S{speed:g} × {ratio:g}{terms}), above "
                      f"{machine.name}'s {machine.table_speed_max:g} r/min{_slower(motion)}")


def _slower(motion: str) -> str:
    return "; move Z with G1 at a bounded feed while coupled" if motion else ""


def leading_velocity(rapid: bool, feed: float | None, machine: Machine) -> float:
    """How fast a leading axis moves in a block: G0 at the machine's rapid rate (each axis of
    a G0 block traverses at it), G1 at the modal feed (G94 mm/min; MAX_FEED when none is set,
    the most a feed word may say)."""
    if rapid:
        return float(machine.rapid_rate)
    return feed or MAX_FEED


def check_coupled_move(rapid: bool, feed: float | None, positions: dict[str, float],
                       coupling: tuple[float | None, float, dict[str, float]], machine: Machine,
                       held: dict[str, float] | None = None) -> None:
    """A leading axis of the EG coupling that moves turns the table by its factor k (degrees of
    C per mm) on top of the generating ratio (reference §A5): a G0 Z on a helical coupling adds
    k_Z·rapid_rate/360 r/min. `coupling`: (hob speed, B→C ratio, {axis: factor}). `held`: the
    positions the axes hold before the block; an axis written at the position it holds does not
    move and adds no term."""
    speed, ratio, factors = coupling
    velocity = leading_velocity(rapid, feed, machine)
    moving = tuple((axis, factor, velocity) for axis, factor in factors.items()
                   if axis in positions and not _holds(axis, positions[axis], held or {}))
    if moving:
        check_table(speed or 0.0, ratio, machine, moving, "G0 " if rapid else "")


def _holds(axis: str, value: float, held: dict[str, float]) -> bool:
    return axis in held and abs(held[axis] - value) <= 1e-9


def check_thread(lead: float, speed: float, word: str) -> None:
    """A thread's tool travels lead × S mm/min along Z: at most the feed the verifier allows."""
    if lead * speed > MAX_FEED:
        raise Refused(f"the thread's lead {word}{lead:g} at S{speed:g} feeds {lead * speed:g} mm/min along Z, "
                      f"above {MAX_FEED:g} (mm/min, about a rapid traverse)")


def check_table_speed(gear_id: int | None, teeth: int, starts: int, hob_speed: float, machine: Machine) -> None:
    """Before the program is made: the table turns at n0·z0/z2 (§B4); few teeth turn it fastest."""
    table_speed = hob_speed * starts / teeth
    if machine.table_speed_max is not None and table_speed > machine.table_speed_max:
        raise LimitError(f"gear {gear_id}: table speed {table_speed:.1f} r/min ({teeth} teeth) exceeds "
                         f"{machine.name}'s {machine.table_speed_max:g} r/min; lower the hob speed; nothing stored")
