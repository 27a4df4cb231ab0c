"""A LinuxCNC motion as plain blocks (docs/reference/linuxcnc-lathe.md §4): G0/G1 to the
absolute position, an arc G2/G3 given by its centre offsets I/K (G91.1, LinuxCNC's default: from
the start; G90.1: absolute) or by R, written with the radius it has (negative: more than half a
turn), G33 with its lead K. X is written as a diameter, every length in mm.

LinuxCNC refuses an arc whose centre is farther from the end than from the start by more than
CENTER_ARC_RADIUS_TOLERANCE_MM = 2·0.01·√2 mm (src/emc/rs274ngc/interp_internal.hh); so does
this reading. I is not scaled by G7 (rs274ngc read_x scales X only). The lathe cycles G70–G72 and
G76 are engine.verifier.expanders.linuxcnc_cycles' (G70–G72: linuxcnc_g7x)."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..refusals import Refused
from .linuxcnc_modes import number

if TYPE_CHECKING:
    from .linuxcnc_modes import Executor
    from .linuxcnc_words import Words

ARC_TOLERANCE_MM = 2 * 0.01 * math.sqrt(2)


def target(executor: Executor, words: Words) -> tuple[float | None, float | None]:
    """The (x radius, z) the words move to, in mm and absolute."""
    modes = executor.modes
    x, z = modes.x, modes.z
    if "x" in words.values:
        if modes.diameter is None:
            raise Refused("an X before G7/G8: diameter or radius is whatever the last program left "
                          "(M2/M30 keep it; the INI's startup G8 holds for the first program only); "
                          "state G7 or G8 before the first X")
        value = executor.length(words.values["x"]) / (2.0 if modes.diameter else 1.0)
        x = _resolved(value, modes.x, modes.incremental, "X")
    if "z" in words.values:
        z = _resolved(executor.length(words.values["z"]), modes.z, modes.incremental, "Z")
    return x, z


def _resolved(value: float, held: float | None, incremental: bool, axis: str) -> float:
    if not incremental:
        return value
    if held is None:
        raise Refused(f"an incremental {axis} (G91) from a position not yet programmed")
    return held + value


def move(executor: Executor, words: Words, motion: str) -> None:
    x, z = target(executor, words)
    axes = _axes(words, x, z)
    if not axes:
        return
    if motion == "0":
        executor.out.append(f"G0 {axes}")
    elif motion == "1":
        executor.out.append(f"G1 {axes}{_feed(executor)}")
    elif motion in ("2", "3"):
        executor.out.append(f"G{motion} {axes} R{number(_arc_radius(executor, words, motion, x, z))}{_feed(executor)}")
    else:
        lead = words.values.get("k")
        if lead is None or lead <= 0:
            raise Refused("G33 without its lead K (distance per revolution)")
        executor.out.append(f"G33 {axes} K{number(executor.length(lead))}")
    executor.modes.x, executor.modes.z = x, z


def feed_words(executor: Executor) -> str:
    """The feed mode and F of a feed block (a canned cycle's feeds too)."""
    return _feed(executor)


def _axes(words: Words, x: float | None, z: float | None) -> str:
    shown = []
    if "x" in words.values and x is not None:
        shown.append(f"X{number(2 * x)}")
    if "z" in words.values and z is not None:
        shown.append(f"Z{number(z)}")
    return " ".join(shown)


def _feed(executor: Executor) -> str:
    modes = executor.modes
    if modes.feed is None or modes.feed <= 0:
        raise Refused("a feed move with no F in force: none yet (LinuxCNC would refuse it, or use the last "
                      "program's), or none since a G94/G95 (it sets the feed to 0) or a G20/G21 under G95 "
                      "(LinuxCNC then feeds the old number in the new units); state F")
    return f" G{'95' if modes.per_rev else '94'} F{number(modes.feed)}"


def _arc_radius(executor: Executor, words: Words, motion: str, x: float | None, z: float | None) -> float:
    """The signed radius of the arc from the held position to (x, z)."""
    modes = executor.modes
    if modes.plane != "18":
        raise Refused("an arc before G18: LinuxCNC starts in the XY plane (G17), a lathe turns in ZX")
    if modes.x is None or modes.z is None or x is None or z is None:
        raise Refused("an arc from a position not yet programmed: program X and Z before it")
    if "p" in words.values and words.values["p"] != 1:
        raise Refused("an arc of several turns (P) on a lathe")
    if "r" in words.values:
        return executor.length(words.values["r"])
    centre = _centre(executor, words, modes.x, modes.z)
    start, end = (math.hypot(px - centre[0], pz - centre[1]) for px, pz in ((modes.x, modes.z), (x, z)))
    if abs(start - end) > ARC_TOLERANCE_MM:
        raise Refused(f"the arc's centre lies {start:.4f} mm from its start but {end:.4f} mm from its end "
                      "(LinuxCNC allows 0.028 mm)")
    if math.isclose(modes.x, x, abs_tol=1e-9) and math.isclose(modes.z, z, abs_tol=1e-9):
        raise Refused("a full circle: a lathe tool cannot turn one")
    return signed_radius((start + end) / 2.0, (modes.z, modes.x), (z, x), (centre[1], centre[0]), motion == "3")


def _centre(executor: Executor, words: Words, x: float, z: float) -> tuple[float, float]:
    if "i" not in words.values and "k" not in words.values:
        raise Refused("an arc without its centre (I/K) or radius (R)")
    i, k = (executor.length(words.values.get(letter, 0.0)) for letter in ("i", "k"))
    if executor.modes.arc_absolute:
        return (i, k)
    return (x + i, z + k)


def signed_radius(radius: float, start: tuple[float, float], end: tuple[float, float], centre: tuple[float, float],
            ccw: bool) -> float:
    """R < 0 for an arc of more than half a turn (the convention of engine.verifier.arcs, in (z, r))."""
    a0, a1 = (math.atan2(p[1] - centre[1], p[0] - centre[0]) for p in (start, end))
    sweep = (a1 - a0) % math.tau if ccw else (a0 - a1) % math.tau
    return -radius if sweep > math.pi else radius

