"""One block of an ISO lathe program followed (issue 27): its G codes taken as the table says
(passed on, converted, consumed, or refused naming them), its move made absolute mm with the
motion in the block, and the plain line the grammar reads emitted. The cycles G70–G76 are
engine.verifier.expanders.iso_cycles."""
from __future__ import annotations

from typing import TYPE_CHECKING

from msgspec.structs import replace

import engine.verifier.expanders.iso_rules as iso_rules

from ..expansion import ExpansionRefused, PlainLine
from ..grammar import REFUSED_G_CODES
from .iso_cycles import CYCLE_CODES, take_cycle
from .iso_modes import INCH, arc_radius, check_points

if TYPE_CHECKING:
    from .iso_lines import Source
    from .iso_modes import Modes

MOTIONS = (0, 1, 2, 3, 32)
PASSED = {18: "G18", 40: "G40"}                       # stated as they are
IGNORED = frozenset({80})                             # G80 cancels a drilling cycle: none is followed
WORK_OFFSET_CODES = frozenset({54, 55, 56, 57, 58, 59})
REFUSED = {
    **REFUSED_G_CODES,
    41: "G41 tool-nose radius compensation moves the path by the insert's radius, which the verifier cannot see",
    42: "G42 tool-nose radius compensation moves the path by the insert's radius, which the verifier cannot see",
    53: "G53 moves in machine coordinates, which the record's travel is not stated in",
    92: "G92 (threading cycle, G-code system A) is not expanded; program the thread with G76 or G32",
    94: "G94 (facing cycle, G-code system A) is not expanded; program the passes or use G72",
    65: "G65 calls a macro program with arguments, which the expander does not follow",
    66: "G66 calls a macro program after every move, which the expander does not follow",
    90: "G90 with X/Z is the turning cycle (G-code system A), which is not expanded; use G71",
}
OTHER_WORDS = frozenset({"X", "Z", "U", "W", "R", "I", "K", "F", "S", "T", "M", "G", "P", "Q", "L", "D", "A", "E"})


def take_block(source: Source, modes: Modes, sources: list[Source], labels: dict[int, int],
               plain: list[PlainLine]) -> int | None:
    """Follows the block; returns the index to go on at if the block jumps (a cycle's P…Q)."""
    try:
        source = replace(source, words=check_points(source.words, modes.machine.decimal_point_input))
    except ValueError as error:
        raise source.refuse(str(error)) from None
    g_codes = [_code(source, text) for letter, text in source.words if letter == "G"]
    words: dict[str, str] = {}
    for letter, text in source.words:
        if letter not in ("G", "M"):
            if letter in words:
                raise source.refuse(f"{letter} twice in one block")
            words[letter] = text
    cycle = next((code for code in g_codes if code in CYCLE_CODES), None)
    if cycle is not None:
        iso_rules.check_cycle(source, cycle, g_codes, words, modes)
        return take_cycle(cycle, source, words, modes, sources, labels, plain)
    iso_rules.check_block(source, g_codes, words, modes)
    out = Emitted(source, plain)
    for code in g_codes:
        _take_code(code, source, words, modes, out)
    _take_words(source, words, modes, out, g_codes)
    out.flush()
    return None


class Emitted:
    """The plain tokens of one block, written as one line (moves may write lines of their own)."""

    def __init__(self, source: Source, plain: list[PlainLine]) -> None:
        self.source, self.plain = source, plain
        self.tokens: list[str] = []

    def line(self, text: str) -> None:
        self.plain.append(PlainLine(text, self.source.number, self.source.text))

    def flush(self) -> None:
        if self.tokens:
            said = f" ({self.source.comment})" if self.source.comment is not None else ""
            self.line(" ".join(self.tokens) + said)
            self.tokens = []


def _code(source: Source, text: str) -> int:
    if not text.isdigit():
        raise source.refuse(f"G{text}: a G code with a fraction is not one the ISO expander follows")
    return int(text)


def _take_code(code: int, source: Source, words: dict[str, str], modes: Modes, out: Emitted) -> None:
    axes = {"X", "Z", "U", "W"} & words.keys()
    if code in MOTIONS:
        modes.motion = code
    elif code == 33 and _system_b(modes):
        modes.motion = 32          # G-code systems B and C write thread cutting G33 (system A's G32)
    elif code in PASSED:
        out.tokens.append(PASSED[code])
    elif code == 90 and not axes:
        modes.absolute_stated = True
        out.tokens.append("G90")
    elif code in (20, 21):
        modes.scale = INCH if code == 20 else 1.0
        out.tokens.append("G21")
    elif code in (98, 99) or (code in (94, 95) and _system_b(modes)):
        modes.per_rev = code in (99, 95)
        out.tokens.append("G98")
    elif code in (96, 97):
        _spindle_mode(code, source, modes, out)
    elif code == 50 or (code == 92 and _system_b(modes)):
        _g50(source, words, modes)
    elif code in WORK_OFFSET_CODES:
        if f"G{code}" != modes.machine.work_offset:
            raise source.refuse(f"G{code} selects another work offset than the record's {modes.machine.work_offset}: "
                                "the travel is stated in that frame")
    elif code == 28:
        _reference_return(source, words, modes, out)
    elif code == 4:
        _dwell(source, words, modes, out)
    elif code not in IGNORED:
        raise source.refuse(REFUSED.get(code, f"G{code} is not a G code the ISO lathe expander follows"))


def _system_b(modes: Modes) -> bool:
    """G-code system B or C (machine.gcode_system, NULL read as B): G94/G95 are the feed per minute
    and per revolution, G92 the coordinate setting and spindle clamp (system A's G98/G99 and G50)."""
    return getattr(modes.machine, "gcode_system", None) != "A"


def _spindle_mode(code: int, source: Source, modes: Modes, out: Emitted) -> None:
    modes.css = code == 96
    if modes.css and modes.clamp is None:
        raise source.refuse("G96 constant surface speed without a spindle clamp G50 S… before it: the spindle "
                            "would speed up without bound as X nears 0")
    out.tokens.append("G97")


def _g50(source: Source, words: dict[str, str], modes: Modes) -> None:
    """G50 S: the spindle clamp (r/min), never a speed; G50 X/Z: the present position is given these
    coordinates, so the frame shifts (the position must be known: after G28); G50 U/W: by increments."""
    if "S" in words:
        modes.clamp = float(words.pop("S"))
    if "X" in words or "Z" in words:
        if modes.x is None or modes.z is None:
            raise source.refuse("G50 X/Z sets the coordinates of a position the verifier does not know; "
                                "return to the reference point (G28) before it")
        for axis in ("X", "Z"):
            if axis in words:
                here = modes.x if axis == "X" else modes.z
                shift = here - float(words.pop(axis)) * modes.scale
                setattr(modes, f"shift_{axis.lower()}", shift)
    _g50_increment(words, modes)


def _g50_increment(words: dict[str, str], modes: Modes) -> None:
    """G50 U/W: the present position's coordinates grow by U (diameter) / W, nothing moves; a later
    X/Z therefore lands U / W lower in the travel's frame (adversary 27b H7)."""
    for axis, word in (("x", "U"), ("z", "W")):
        if word in words:
            setattr(modes, f"shift_{axis}", getattr(modes, f"shift_{axis}") - modes.length(words.pop(word)))


def _reference_return(source: Source, words: dict[str, str], modes: Modes, out: Emitted) -> None:
    """G28: at rapid by the intermediate point the words give, then to the reference point on each
    axis named (every axis when none is), which the machine record states."""
    machine = modes.machine
    ref_x, ref_z = getattr(machine, "reference_x", None), getattr(machine, "reference_z", None)
    if ref_x is None or ref_z is None:
        raise source.refuse(f"G28 returns to the reference point, which machine {machine.name} does not state "
                            "(machine.reference_x, reference_z)")
    named = {axis for axis in ("X", "Z") if axis in words or {"X": "U", "Z": "W"}[axis] in words} or {"X", "Z"}
    moving = {key: text for key, text in words.items()
              if key in ("X", "Z") or (key in ("U", "W") and float(text) != 0)}   # U0/W0: from where it is
    middle = _target(source, moving, modes)
    out.flush()
    _state_absolute(modes, out)
    if middle != (modes.x, modes.z) and None not in middle:
        out.line(f"G0 X{middle[0]:.4f} Z{middle[1]:.4f}")
    end_x = ref_x if "X" in named else middle[0]
    end_z = ref_z if "Z" in named else middle[1]
    parts = [f"X{end_x:.4f}" if end_x is not None else "", f"Z{end_z:.4f}" if end_z is not None else ""]
    out.line("G0 " + " ".join(part for part in parts if part))
    modes.x, modes.z = end_x, end_z
    for key in ("X", "Z", "U", "W"):
        words.pop(key, None)


def _dwell(source: Source, words: dict[str, str], modes: Modes, out: Emitted) -> None:
    """G4 P<ms> or X/U<s>: the plain dwell G4 F<s>."""
    if "P" in words:
        seconds = float(words.pop("P")) / 1000
    elif "X" in words or "U" in words:
        seconds = float(words.pop("X") if "X" in words else words.pop("U"))
    else:
        raise source.refuse("G4 without its time (P milliseconds, or X/U seconds)")
    out.flush()
    if seconds > 0:
        out.line(f"G4 F{seconds:.3f}")


def _state_absolute(modes: Modes, out: Emitted) -> None:
    """X and Z are absolute on an ISO lathe of G-code system A (U/W are the increments); the plain
    lines are absolute by construction, so they state G90 before the first move if the program
    did not (machine.gcode_system 'A'); on system B the program must state it itself."""
    if not modes.absolute_stated and getattr(modes.machine, "gcode_system", "B") == "A":
        out.line("G90")
        modes.absolute_stated = True


def _target(source: Source, words: dict[str, str], modes: Modes) -> tuple[float | None, float | None]:
    x, z = modes.x, modes.z
    if "X" in words and "U" in words or "Z" in words and "W" in words:
        raise source.refuse("an axis given twice (X with U, or Z with W)")
    if "X" in words:
        x = modes.absolute("X", words["X"])
    if "Z" in words:
        z = modes.absolute("Z", words["Z"])
    for axis, word, now in (("X", "U", x), ("Z", "W", z)):
        if word in words:
            if now is None:
                raise source.refuse(f"{word}{words[word]} moves by an increment from a position not yet known; "
                                    f"program {axis} first")
            if axis == "X":
                x = now + modes.length(words[word])
            else:
                z = now + modes.length(words[word])
    return x, z


def _take_words(source: Source, words: dict[str, str], modes: Modes, out: Emitted, g_codes: list[int]) -> None:
    unknown = words.keys() - OTHER_WORDS
    if unknown:
        raise source.refuse(f"{sorted(unknown)[0]}{words[sorted(unknown)[0]]}: not a word of the ISO lathe grammar")
    if "F" in words:
        modes.feed = float(words["F"])
    moves = bool({"X", "Z", "U", "W"} & words.keys())
    if moves:
        _move(source, words, modes, out)
    elif modes.feed is not None and "F" in words and not modes.per_rev and modes.scale == 1.0:
        out.tokens.append(f"F{words['F']}")
    _spindle_words(source, words, modes, out)
    for letter, text in source.words:
        if letter == "M" and text.lstrip("0") not in ("98", "99", "97"):
            out.tokens.append(f"M{text}")
    arc_words = {"R", "I", "K"} & words.keys()
    if arc_words and not (moves and modes.motion in (2, 3)):
        word = sorted(arc_words)[0]
        raise source.refuse(f"{word}{words[word]} belongs to an arc G2/G3 that moves (a corner R or chamfer is "
                            "not followed)")
    leftover = words.keys() - {"X", "Z", "U", "W", "R", "I", "K", "F", "S", "T"}
    if leftover:
        word = sorted(leftover)[0]
        raise source.refuse(f"{word}{words[word]} means nothing in this block to the ISO lathe expander")


def _spindle_words(source: Source, words: dict[str, str], modes: Modes, out: Emitted) -> None:
    if "S" in words:
        if float(words["S"]) <= 0:
            raise source.refuse(f"S{words['S']} must be above 0: a spindle speed of 0 (under G96 a surface speed "
                                "of 0, 0 r/min at any X) stops the spindle and the cut after it meets a standing bar")
        if modes.css:
            assert modes.clamp is not None
            out.tokens.append(f"S{modes.clamp:.0f}")
        else:
            modes.speed = float(words["S"])
            out.tokens.append(f"S{words['S']}")
    if "T" in words:
        out.tokens.append(_tool(source, words["T"], modes))


def _tool(source: Source, text: str, modes: Modes) -> str:
    """T0101 and T101: tool 01, offset 01; T0100 cancels the offset. A turret indexing while the
    tool stands within the box of the cuts so far, or on its edge (still at the cut), swings the
    other tools through the part."""
    if not text.isdigit() or len(text) not in (3, 4):
        return f"T{text}"      # the grammar refuses it with its reason (T<tool><offset>, two digits each)
    tool = int(text) // 100
    box = modes.cut_box
    if tool != modes.tool and box is not None and modes.x is not None and modes.z is not None \
            and modes.x <= box[0] + 1e-6 and modes.z <= box[1] + 1e-6:
        raise source.refuse(f"T{text} changes the tool at X{modes.x:g} Z{modes.z:g}, within the cuts so far "
                            f"(up to X{box[0]:g} Z{box[1]:g}): index the turret clear of the part")
    modes.tool = tool
    return f"T{int(text):04d}"


def _move(source: Source, words: dict[str, str], modes: Modes, out: Emitted) -> None:
    motion = modes.motion
    if motion is None:
        raise source.refuse("a move before any G0/G1/G2/G3: the control would move by whatever motion the last "
                            "program left")
    x, z = _target(source, words, modes)
    _state_absolute(modes, out)
    tokens = [f"G{motion}"]
    if x is not None and ("X" in words or "U" in words):
        tokens.append(f"X{x:.4f}")
    if z is not None and ("Z" in words or "W" in words):
        tokens.append(f"Z{z:.4f}")
    if motion in (2, 3):
        tokens.append(f"R{_radius(source, words, modes, (x, z)):.4f}")
    if motion in (1, 2, 3):
        tokens.append(_feed(source, modes))
        tokens = [token for token in tokens if token]
    elif motion == 32:
        if modes.feed is None:
            raise source.refuse("G32 without its lead F")
        tokens.append(f"F{modes.feed * modes.scale:.4f}")
    out.tokens[:0] = tokens
    if x is not None and z is not None and motion != 0:
        modes.cut(x, z)
    modes.x, modes.z = x, z


def _feed(source: Source, modes: Modes) -> str:
    if modes.feed is None and modes.per_rev is None:
        return ""      # the grammar refuses the cut: no G98/G99 stated
    if modes.feed is None:
        raise source.refuse("a cut before any feed F (after a G70 whose contour states F, which F the control "
                            "keeps is not known: state F)")
    if modes.per_rev is None:
        return f"F{modes.feed * modes.scale:.4f}"    # the grammar refuses the cut: no G98/G99 stated
    value = modes.feed_per_minute(modes.feed)
    if value is None:
        raise source.refuse("a feed per revolution (G99) before any spindle speed S: the feed in mm/min is unknown")
    return f"F{value:.4f}"


def _radius(source: Source, words: dict[str, str], modes: Modes, end: tuple[float | None, float | None]) -> float:
    """R as programmed, or from the centre I/K (engine.verifier.expanders.iso_modes.arc_radius)."""
    if "R" in words:
        return modes.length(words["R"])
    if "I" not in words and "K" not in words:
        raise source.refuse(f"G{modes.motion} without its R (or its centre I/K)")
    if modes.x is None or modes.z is None or end[0] is None or end[1] is None:
        raise source.refuse("an arc from an unknown start point: program X and Z before it")
    centre = (modes.length(words.get("I", "0")), modes.length(words.get("K", "0")))
    iso_rules.check_centre(source, centre, (modes.x, modes.z), (end[0], end[1]))
    return arc_radius(centre, (modes.x, modes.z), (end[0], end[1]), modes.motion == 2)


__all__ = ["ExpansionRefused", "take_block"]
