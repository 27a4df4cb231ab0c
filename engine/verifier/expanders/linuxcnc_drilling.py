"""G83 peck drilling on the axis of a lathe (docs/reference/linuxcnc-lathe.md §5), as LinuxCNC
makes its moves (src/emc/rs274ngc/interp_cycles.cc convert_cycle_xy, convert_cycle_g83 and
CYCLE_MACRO in interp_internal.hh):

In the XY plane (G17) the cycle drills along Z at the block's X/Y. The initial level is the Z the
tool stood at when the cycle mode began; below R it first rapids up to R. The clear level is R
(G99) or the initial level (G98). From R it feeds Q deeper, rapids back to R, rapids down to
`peck clearance` above the bottom just drilled, feeds Q deeper again, …, feeds to the bottom Z
and rapids to the clear level. The peck clearance is the block's D, else the INI's
G83_PECK_CLEARANCE whose default is 1 mm on a metric machine (0.050 in on an inch one,
rs274ngc_pre.cc); the record does not state it, so 1 mm is taken: the rapid ends inside the hole
already drilled either way (air), above its bottom.

On a lathe the part turns and the drill stands still, so only a hole on the axis is drilled:
X must be 0 (a drill off the axis would cut a ring, not a hole). G83 in G18 drills along Y (no Y
on a lathe), G91 cycles, repeats L and a Y word are refused: not modelled."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..refusals import Refused
from .linuxcnc_modes import number
from .linuxcnc_motion import feed_words

if TYPE_CHECKING:
    from .linuxcnc_modes import Executor
    from .linuxcnc_words import Words

DEFAULT_PECK_CLEARANCE_MM = 1.0       # rs274ngc_pre.cc: G83_PECK_CLEARANCE default on a metric machine


def drilling(executor: Executor, words: Words) -> None:
    modes = executor.modes
    _check(executor, words)
    assert modes.x is not None and modes.z is not None
    bottom, r, delta = (executor.length(words.values[c]) if c in words.values else None for c in ("z", "r", "q"))
    if bottom is None or r is None or delta is None or delta <= 0:
        raise Refused("G83 needs its Z (bottom), R (retract level) and Q (peck, above 0)")
    if r < bottom:
        raise Refused("G83 with R below the bottom Z (LinuxCNC: R less than Z in cycle)")
    clearance = executor.length(words.values["d"]) if "d" in words.values else DEFAULT_PECK_CLEARANCE_MM
    if clearance < 0:
        raise Refused("G83 with a negative peck clearance D: the rapid back in would enter the material")
    initial, current = modes.extra.setdefault("cycle_il", modes.z), modes.z
    moves: list[tuple[str, float]] = []
    if initial < r:                                    # below R: straight up to R first
        moves.append(("G0", r))
        initial = current = r
    clear = r if modes.extra["retract"] == 99 else initial
    moves += [("G0", r)] if current > r else [("G0", clear), *([("G0", r)] if clear > r else [])]
    moves += _pecks(r, bottom, delta, clearance, clear)
    feed = feed_words(executor)
    held = modes.z
    for code, z in moves:
        if code == "G1" or z != held:
            executor.out.append(f"{code} Z{number(z)}{feed if code == 'G1' else ''}")
        held = z
    modes.z = clear


def _check(executor: Executor, words: Words) -> None:
    modes = executor.modes
    if modes.plane != "17":
        raise Refused("G83 outside G17: in G18 LinuxCNC drills along Y, an axis a lathe does not have")
    if modes.incremental:
        raise Refused("G83 in G91 (incremental) is not modelled; program it in G90")
    if "y" in words.values or words.values.get("l", 1) != 1:
        raise Refused("G83 with Y or a repeat L is not modelled")
    if "retract" not in modes.extra:
        raise Refused("G83 before G98/G99: the retract level is whatever the last program left")
    if "x" in words.values and not (words.values["x"] == 0 and modes.x == 0):
        # an X0 where the tool already stands on the axis moves nothing; any other X is the cycle's
        # first rapid, at the current Z, which the verifier does not follow
        raise Refused("G83 with an X the tool is not at: drill from the axis, G0 X0 before the cycle")
    if modes.x is None or modes.z is None or abs(modes.x) > 1e-9:
        raise Refused("G83 off the lathe's axis (X not 0): the part turns, a drill off the axis cuts a ring; "
                      "G0 X0 before the cycle")


def _pecks(r: float, bottom: float, delta: float, clearance: float, clear: float) -> list[tuple[str, float]]:
    """convert_cycle_g83: feed to r − n·Q while above the bottom, each followed by a rapid to R and a
    rapid back down to the clearance above that depth; then the bottom, then the clear level."""
    moves: list[tuple[str, float]] = []
    depth = r - delta
    while depth > bottom:
        moves += [("G1", depth), ("G0", r), ("G0", depth + clearance)]
        depth -= delta
        if len(moves) > 300_000:
            raise Refused("G83 makes more than 100,000 pecks")
    return [*moves, ("G1", bottom), ("G0", clear)]
