"""The ISO lathe cycles G70–G76 read from their words (Fanuc two-block forms and the Haas one-block
forms) and expanded into plain moves by engine.verifier.expanders.cycles (issue 27). Word meanings:
docs/reference/iso-lathe.md. A cycle's contour is the blocks N<P> … N<Q> of the file; after a
roughing cycle the control goes on after N<Q>, after G70 after the G70 block."""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import engine.verifier.expanders.cycles as cycles
import engine.verifier.expanders.iso_rules as iso_rules

from .cycles import CycleError, Move, Thread
from .iso_modes import arc_radius

if TYPE_CHECKING:
    from ..expansion import PlainLine
    from .iso_lines import Source
    from .iso_modes import Modes

Where = tuple[list["Source"], dict[int, int]]          # the program's lines and its labels
Result = tuple[list[Move], "int | None", "float | list[float]"]   # the moves, where to go on, the feed
                                                                 # (or lead): one, or one a move (G70)
Reader = Callable[["Source", dict[str, str], "Modes", tuple[float, float], Where], Result]
CYCLE_CODES = frozenset({70, 71, 72, 73, 74, 75, 76})
# F in the contour is ignored by G71–G73 and effective in G70 (_g70); S and T are refused in it
# (adversary 27b H3): G70 would change the speed or index the turret mid-contour.
CONTOUR_WORDS = frozenset({"X", "Z", "U", "W", "R", "I", "K", "F"})


def take_cycle(code: int, source: Source, words: dict[str, str], modes: Modes, sources: list[Source],
               labels: dict[int, int], plain: list[PlainLine]) -> int | None:
    if modes.x is None or modes.z is None:
        raise source.refuse(f"G{code} from a start point not yet known: position X and Z before the cycle")
    start = (modes.x, modes.z)
    try:
        moves, jump, feed = CYCLE_READERS[code](source, words, modes, start, (sources, labels))
    except CycleError as error:
        raise source.refuse(f"G{code}: {error}") from None
    if moves:
        _emit(moves, feed, source, modes, plain)
    return jump


def _word(source: Source, words: dict[str, str], letter: str, default: float | None = None) -> float:
    if letter in words:
        return float(words[letter])
    if default is None:
        raise source.refuse(f"the cycle block lacks its {letter} word")
    return default


def _increment(modes: Modes) -> float:
    """The least input increment the integer words P/Q of G74–G76 count in: 0.001 mm, 0.0001 in."""
    return 0.001 if modes.scale == 1.0 else 0.0001 * modes.scale


def _contour(source: Source, words: dict[str, str], modes: Modes, where: Where,
             feeds: list[float | None] | None = None) -> tuple[list[Move], int]:
    """The blocks N<P> … N<Q> as absolute moves from the cycle's start; and the index after N<Q>.
    `feeds` (if given) gets the F of the contour in effect at each move (None before any)."""
    sources, labels = where
    first, last = (int(_word(source, words, letter)) for letter in ("P", "Q"))
    if first not in labels or last not in labels or labels[last] < labels[first]:
        raise source.refuse(f"the contour N{first} … N{last} is not in this program (in that order)")
    x, z, motion = modes.x, modes.z, modes.motion
    assert x is not None and z is not None
    moves: list[Move] = []
    feed = None
    for block in sources[labels[first]:labels[last] + 1]:
        if block.kind != "block":
            continue
        x, z, motion, move = _contour_move(block, modes, (x, z), motion)
        feed = next((float(text) for letter, text in block.words if letter == "F"), feed)
        if move is not None:
            moves.append(move)
            if feeds is not None:
                feeds.append(feed)
    return moves, labels[last] + 1


def _contour_move(block: Source, modes: Modes, at: tuple[float, float], motion: int | None
                  ) -> tuple[float, float, int | None, Move | None]:
    words = {}
    iso_rules.check_contour_points(block, modes)
    for letter, text in block.words:
        if letter == "G":
            code = int(float(text))
            if code in (0, 1, 2, 3):
                motion = code
            elif code != 40:
                raise block.refuse(f"G{code} inside a cycle's contour is not followed (only G0–G3 and G40)")
        elif letter == "M" or letter not in CONTOUR_WORDS:
            raise block.refuse(f"{letter}{text} inside a cycle's contour is not followed (G70 executes it, "
                               "G71–G73 ignore it): state it before the cycle")
        else:
            words[letter] = text
    x, z = at
    if "X" in words:
        x = modes.absolute("X", words["X"])
    if "Z" in words:
        z = modes.absolute("Z", words["Z"])
    x += modes.length(words.get("U", "0"))
    z += modes.length(words.get("W", "0"))
    if (x, z) == at:
        return x, z, motion, None
    if motion is None:
        raise block.refuse("a contour move before any G0/G1/G2/G3")
    radius = None
    if motion in (2, 3) and "R" in words:
        radius = modes.length(words["R"])
    elif motion in (2, 3):
        centre = (modes.length(words.get("I", "0")), modes.length(words.get("K", "0")))
        iso_rules.check_centre(block, centre, at, (x, z))
        radius = arc_radius(centre, at, (x, z), motion == 2)
    return x, z, motion, Move(motion, x, z, radius)


def _g70(source: Source, words: dict[str, str], modes: Modes, start: tuple[float, float], where: Where) -> Result:
    """G70 finishes at the F its contour blocks state, from the block that states it on ("F and S
    specified in the finishing shape program are effective in the finishing cycle", Yaskawa LX3
    §2.8.25.5); before the first, at the G70's F or the modal feed. Which F the control keeps after
    such a G70 is not stated: the feed becomes unknown, and the next cut must state its F."""
    feeds: list[float | None] = []
    contour, _ = _contour(source, words, modes, where, feeds)
    base = _word(source, words, "F", modes.feed or 0.0)
    moves = cycles.finish(start, contour)
    if all(feed is None for feed in feeds):
        return moves, None, base
    modes.feed = None
    return moves, None, [base if feed is None else feed for feed in feeds] + [base]


def _rough(code: int) -> Reader:
    def read(source: Source, words: dict[str, str], modes: Modes, start: tuple[float, float], where: Where) -> Result:
        letter = "U" if code == 71 else "W"
        if "P" not in words:     # Fanuc's first block: Δd (radius) and e
            modes.cycle[f"{code}depth"] = modes.length(words[letter]) if letter in words else 0.0
            modes.cycle[f"{code}retract"] = modes.length(words.get("R", "0"))
            return [], None, 0.0
        contour, after = _contour(source, words, modes, where)
        iso_rules.check_type_one(source, code, where, contour)
        depth = modes.length(words["D"]) if "D" in words else modes.cycle.get(f"{code}depth", 0.0)
        retract = modes.cycle.get(f"{code}retract", depth / 2)
        allowance = (modes.length(words.get("U", "0")), modes.length(words.get("W", "0")))
        moves = cycles.rough(start, contour, depth, retract, allowance, facing=code == 72)
        return moves, after, _word(source, words, "F", modes.feed or 0.0)
    return read


def _g73(source: Source, words: dict[str, str], modes: Modes, start: tuple[float, float], where: Where) -> Result:
    if "P" not in words:         # Fanuc's first block: the relief Δi, Δk and the passes d
        modes.cycle["73i"], modes.cycle["73k"] = (modes.length(words.get(w, "0")) for w in ("U", "W"))
        modes.cycle["73d"] = _word(source, words, "R")
        return [], None, 0.0
    contour, after = _contour(source, words, modes, where)
    relief = (modes.length(words["I"]) if "I" in words else modes.cycle.get("73i", 0.0),
              modes.length(words["K"]) if "K" in words else modes.cycle.get("73k", 0.0))
    passes = int(_word(source, words, "D", modes.cycle.get("73d")))
    allowance = (modes.length(words.get("U", "0")), modes.length(words.get("W", "0")))
    moves = cycles.pattern(start, contour, relief, passes, allowance)
    return moves, after, _word(source, words, "F", modes.feed or 0.0)


def _peck(code: int) -> Reader:
    def read(source: Source, words: dict[str, str], modes: Modes, start: tuple[float, float], where: Where) -> Result:
        if not {"X", "Z", "U", "W"} & words.keys():     # Fanuc's first block: the retract e
            modes.cycle[f"{code}retract"] = modes.length(words.get("R", "0"))
            return [], None, 0.0
        x = modes.absolute("X", words["X"]) if "X" in words else start[0] + modes.length(words.get("U", "0"))
        z = modes.absolute("Z", words["Z"]) if "Z" in words else start[1] + modes.length(words.get("W", "0"))
        unit = _increment(modes)
        steps = (modes.length(words["I"]) if "I" in words else float(words.get("P", "0")) * unit,
                 modes.length(words["K"]) if "K" in words else float(words.get("Q", "0")) * unit)
        if code == 74:
            steps = (steps[0], steps[1]) if "K" in words or "Q" in words else (steps[0], steps[0])
        retract = modes.cycle.get(f"{code}retract", 0.0)
        moves = cycles.peck(start, (x, z), steps, retract, grooving=code == 75)
        return moves, None, _word(source, words, "F", modes.feed or 0.0)
    return read


def _g76(source: Source, words: dict[str, str], modes: Modes, start: tuple[float, float], where: Where) -> Result:
    unit = _increment(modes)
    if "K" in words or "D" in words:             # Haas: one block, K height, D first depth, A angle
        thread = Thread(modes.absolute("X", words["X"]), modes.absolute("Z", words["Z"]),
                        modes.length(words["K"]), modes.length(words["D"]), modes.length(words["F"]),
                        angle=_word(source, words, "A", 60.0), taper=modes.length(words.get("I", "0")))
        return cycles.threading(start, thread), None, thread.lead
    if not {"X", "Z", "U", "W"} & words.keys():   # Fanuc's first block: P mmrraa, Q Δdmin, R d
        p = words.get("P", "010060").zfill(6)
        modes.cycle.update({"76m": int(p[:2]), "76a": int(p[4:6]),
                            "76min": float(words.get("Q", "0")) * unit,
                            "76d": modes.length(words.get("R", "0"))})
        return [], None, 0.0
    x = modes.absolute("X", words["X"]) if "X" in words else start[0] + modes.length(words.get("U", "0"))
    z = modes.absolute("Z", words["Z"]) if "Z" in words else start[1] + modes.length(words.get("W", "0"))
    thread = Thread(x, z, _word(source, words, "P") * unit, _word(source, words, "Q") * unit,
                    modes.length(words["F"]) if "F" in words else _word(source, words, "F"),
                    minimum=modes.cycle.get("76min", 0.0), allowance=modes.cycle.get("76d", 0.0),
                    finish_passes=int(modes.cycle.get("76m", 1)), angle=modes.cycle.get("76a", 60.0),
                    taper=modes.length(words.get("R", "0")))
    return cycles.threading(start, thread), None, thread.lead


CYCLE_READERS: dict[int, Reader] = {70: _g70, 71: _rough(71), 72: _rough(72), 73: _g73, 74: _peck(74),
                                    75: _peck(75), 76: _g76}


def _emit(moves: list[Move], feed: float | list[float], source: Source, modes: Modes,
          plain: list[PlainLine]) -> None:
    for move, each in zip(moves, feed if isinstance(feed, list) else [feed] * len(moves), strict=True):
        _emit_move(move, each, source, modes, plain)
    modes.x, modes.z = moves[-1].x, moves[-1].z
    modes.motion = moves[-1].motion if moves[-1].motion != cycles.THREAD else modes.motion


def _emit_move(move: Move, feed: float, source: Source, modes: Modes, plain: list[PlainLine]) -> None:
    from ..expansion import PlainLine
    text = f"G{move.motion} X{move.x:.4f} Z{move.z:.4f}"
    if move.radius is not None:
        text += f" R{move.radius:.4f}"
    if move.motion in (1, 2, 3):
        per_minute = modes.feed_per_minute(feed) if feed else None
        if per_minute is None:
            raise source.refuse("the cycle cuts without a feed (F) the verifier can bound: give F, and S "
                                "before a feed per revolution")
        text += f" F{per_minute:.4f}"
        modes.cut(move.x, move.z)
    elif move.motion == cycles.THREAD:
        text += f" F{feed:.4f}"     # the lead, mm/rev
    plain.append(PlainLine(text, source.number, source.text))
