"""The numbers an operator checks a hobbing set-up against (issue 27), read from the program's
lines as the simulation follows them (engine.simulation.hobbing.recorded), never from the job or
the model that made it: the swivel A as the program writes it (in the DIN frame A = h_hob·γ −
h_gear·β, §A7, times the machine's a_direction), and per cut the centre distance X it reaches
and the depth below the tip it cuts (§B3), its radial infeed and its pass (axial, or along Y for
a tangential worm wheel, §B10) with the F the program writes (mm/min: the hobbing grammar has
G94 only) and the feed per workpiece revolution the simulation takes from it (§B5), then the Y
the hob cuts at (the shift range, §B15). Every value is a program value: DIN positions are
turned back by the machine's senses (engine.simulation.hobbing.frame)."""
from __future__ import annotations

import math

import msgspec

from ..simulation.hobbing.frame import Senses
from .plot_geometry import Pass, cut_pass

FEED_UNIT = "mm/min"          # G94: the hobbing grammar refuses G95 (engine.verifier.grammar)
PASS_WORDS = {"Z": "axial pass", "Y": "tangential pass"}
NO_PASS = Pass("", {}, {})


class Number(msgspec.Struct, frozen=True):
    gid: str       # the artist's name in the SVG (what the tests read)
    text: str


def setup_numbers(scene) -> list[Number]:
    """The card's lines: the swivel, every cut's numbers, the shift range."""
    senses = Senses.of(scene.machine)
    numbers = [swivel_number(scene.recording, senses)]
    for index, cut in enumerate(scene.recording.cuts, start=1):
        numbers += cut_numbers(scene.recording, cut, index, senses)
    numbers.append(shift_number(scene.recording, senses))
    return numbers


def swivel_number(recording, senses: Senses) -> Number:
    """The last A the program writes before its first cut, as written (`A=` or `A`, the program's
    form), and the line that writes it."""
    words = recording.swivel_words
    if not words:
        return Number("number swivel", "swivel: the program writes no A")
    first = next((move.number for move in recording.moves if move.cutting), math.inf)
    line, written = max((word for word in words if word[0] < first), default=words[-1])
    din = senses.swivel(written)
    return Number("number swivel", f"swivel {recording.swivel_address}{written:.3f}° (line {line}, as written; "
                                   f"DIN {din:+.3f}°, "
                                   f"a_direction {senses.a:+d})")


def cut_numbers(recording, cut, index: int, senses: Senses) -> list[Number]:
    """Per unit the cut enters: X and depth; then its radial infeed and its pass with their F."""
    summaries = [done for done in recording.report.cuts if done.number == cut.moves[0].number]
    numbers = [Number(f"number cut {index} {done.unit}",
                      f"{cut.label} on {done.unit}: {centre_words(cut, done)}, depth {done.depth:.3f} mm")
               for done in summaries]
    first = summaries[0] if summaries else None
    infeed = [move for move in cut.moves if moved_axes(move) == {"X"}]
    if infeed:
        numbers.append(Number(f"number cut {index} infeed", "  radial infeed " + span(infeed, "X", senses) +
                              feed_words(infeed, first.radial_feed if first else None)))
    feed = cut_pass(cut)
    if feed is not None and feed.axis in PASS_WORDS:
        moves = [move for move in cut.moves if feed.axis in moved_axes(move)]
        numbers.append(Number(f"number cut {index} pass", f"  {PASS_WORDS[feed.axis]} " + span(moves, feed.axis, senses)
                              + feed_words(moves, first.pass_feed if first else None)))
    return numbers


def centre_words(cut, done) -> str:
    """The centre distance the cut reaches; a taper's or crowned pass changes it along Z (§B11,
    §B12): then from least to most along the pass."""
    xs = [pose["X"] for move in cut.moves if "Z" in moved_axes(move) for pose in (move.start, move.end)]
    if xs and max(xs) - min(xs) > 1e-6:
        return f"centre distance X{min(xs):.3f} … X{max(xs):.3f} mm along the pass"
    return f"centre distance X{done.centre_distance:.3f} mm"


def moved_axes(move) -> set[str]:
    return {axis for axis in ("X", "Y", "Z") if axis in move.start and axis in move.end
            and abs(move.end[axis] - move.start[axis]) > 1e-9}


def span(moves, axis: str, senses: Senses) -> str:
    """Where the moves along `axis` begin and end, as the program writes the axis."""
    start, end = (senses.position(axis, pose[axis]) for pose in (moves[0].start, moves[-1].end))
    return f"{axis}{start:.3f} → {axis}{end:.3f}"


def feed_words(moves, per_revolution: float | None) -> str:
    """The F the program writes for the moves (every value, if it changes), and the simulation's
    feed per workpiece revolution f = v_f/n2 (§B5)."""
    feeds = sorted({move.feed for move in moves if move.feed is not None})
    written = "/".join(f"F{feed:g}" for feed in feeds) if feeds else "no F"
    work = f" ({per_revolution:.3f} mm/rev of the work)" if per_revolution is not None else ""
    return f" at {written} {FEED_UNIT}{work}"


def shift_number(recording, senses: Senses) -> Number:
    """The Y the hob cuts at; a tangential worm wheel's Y is its feed, not a shift."""
    if any((cut_pass(cut) or NO_PASS).axis == "Y" for cut in recording.cuts):
        return Number("number shift", "shift: none (Y is the tangential feed)")
    low, high = sorted(senses.position("Y", value) for value in recording.cutting_y)
    if low == high:
        return Number("number shift", f"shift: Y{low:.3f} mm for every part (no shift from part to part)")
    return Number("number shift", f"shift range: Y{low:.3f} … Y{high:.3f} mm (from part to part, §B15)")
