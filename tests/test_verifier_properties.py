"""Properties of the verifier (issue 13), with random blocks of each dialect: 840D hobbing, 840D
lathe, ISO lathe. The test chooses every value and renders it itself, plainly or as an address
expression, an R-parameter, an exponent, inf/nan, IC/AC, an indirect axis, with or without a
control character in the block or its comment; it knows what the block evaluates to. The
oracle is the test's own: a block is accepted exactly when it is plain (on ISO with its decimal
point), holds printable ASCII only, and its evaluated position (and feed, and speed) lies
within the machine. So no block whose position lies outside the machine is accepted, and a
plain block inside it is not refused: the test fails both ways.

And, after the review of issue 13: a cut is accepted exactly when the spindle turns, the table
is coupled, a tool offset is active, as the test's own reading of the events before it says;
the table's speed with a Z differential is bounded by the reference's formula
n_C = (z0/z2)·n_B + k·v/360 (§A5); an arc exactly when its radius reaches half its chord.

The machines' limits come from seed_templates/machines.csv, the working area from the
prelude written here."""
from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.machines.records import Machine
from engine.verifier import LimitError, verify_program

SEED = Path(__file__).resolve().parent.parent / "seed_templates" / "machines.csv"
MAX_FEED = 20000.0        # mm/min: the feed bound the lathe check has always had (about a rapid traverse)
MAX_DIFFERENTIAL = 360.0  # °/mm: one table turn per mm of travel
ARC_TOLERANCE = 0.002     # mm by which half an arc's chord may exceed its radius (three-decimal rounding)
AREA = {"X": (50.0, 250.0), "Y": (-30.0, 30.0), "Z": (-200.0, 100.0)}   # the hobbing prelude's G25/G26
NAME = "PROPERTY"


def machines() -> dict[str, Machine]:
    def number(text):
        return float(text) if text else None
    with SEED.open(newline="") as handle:
        return {row["name"]: Machine(row["name"], row["kind"], row["dialect"],
                                     *(number(row[column]) for column in ("x_min", "x_max", "y_min", "y_max",
                                                                          "z_min", "z_max", "spindle_max",
                                                                          "table_speed_max", "module_max")))
                for row in csv.DictReader(handle)}


MACHINES = machines()
DIALECTS = {   # name -> prelude (ready to cut: S·z0/z2 = 100/40 r/min of C), axes, motion codes, whether
               # 840D (`=` forms, `;` comments, no decimal point needed), speed block
    "hobber-840d": ([f"%_N_{NAME}_MPF", ";$PATH=/_N_MPF_DIR", "G90 G71 G94 G54",
                     "G25 X{X[0]:.3f} Y{Y[0]:.3f} Z{Z[0]:.3f}".format(**AREA),
                     "G26 X{X[1]:.3f} Y{Y[1]:.3f} Z{Z[1]:.3f}".format(**AREA), "WALIMON", "G0 Y0.000",
                     "EGDEF(C,B,1)", 'EGON(C,"FINE",B,-1,40)', "M3 S100"],
                    ("X", "Y", "Z"), ("G0", "G1"), True, "M3 S{}"),
    "lathe-840d": ([f"%_N_{NAME}_MPF", ";$PATH=/_N_MPF_DIR", "G18 G71 G90 G40 DIAMON", "T1 D1", "G97 S100 M3",
                    "G94 F100"],
                   ("X", "Z"), ("G0", "G1"), True, "G97 S{} M3"),
    "lathe-iso": (["%", f"O0001 ({NAME})", "G21 G18 G40 G90", "T0101", "G97 S100 M03", "G98 F100."],
                  ("X", "Z"), ("G00", "G01"), False, "G97 S{} M03"),
}
ENDINGS = {"hobber-840d": ["EGOFS(C)", "EGDEL(C)", "M30"], "lathe-840d": ["M30"], "lathe-iso": ["M30", "%"]}
PLAIN = ("plain", "plain one decimal", "plain whole", "plain trailing point", "equals")
NOT_PLAIN = ("expression", "r-parameter", "exponent", "inf/nan", "ic/ac", "indirect")
CONTROL = ["\n", "\r", "\x00", "\x7f", "\t", "\x1b", "é", "\u2028", "\x85"]


def inside(machine: Machine, axis: str, value: float, hobbing: bool) -> bool:
    low, high = getattr(machine, f"{axis.lower()}_min"), getattr(machine, f"{axis.lower()}_max")
    within_area = not hobbing or AREA[axis][0] <= value <= AREA[axis][1]
    return low <= value <= high and within_area


@st.composite
def rendered(draw, address: str, value: float, is_840d: bool, evaluates: bool = False):
    """(lines before the block, the word, its value as the control would evaluate it, plain?).
    `evaluates`: the 840D lathe expander evaluates an expression after `=`, an R-parameter the
    program set and AC(…) (issue 27); the plain block holds the value to six decimals."""
    kinds = [kind for kind in PLAIN + NOT_PLAIN if is_840d or kind not in ("equals", "r-parameter")]
    kind = draw(st.sampled_from(kinds))
    lines, word, number, plain = draw(_rendered(address, value, is_840d, kind))
    if evaluates and (kind in ("expression", "r-parameter") or word.startswith(f"{address}=AC(")):
        return lines, word, round(number, 6), True
    return lines, word, number, plain


@st.composite
def _rendered(draw, address: str, value: float, is_840d: bool, kind: str):
    if kind == "plain":
        return [], f"{address}{value:.3f}", float(f"{value:.3f}"), True
    if kind == "plain one decimal":
        return [], f"{address}{value:.1f}", float(f"{value:.1f}"), True
    if kind == "plain whole":
        return [], f"{address}{value:.0f}", float(f"{value:.0f}"), True
    if kind == "plain trailing point":
        return [], f"{address}{value:.0f}.", float(f"{value:.0f}"), True
    if kind == "equals":
        return [], f"{address}={value:.3f}", float(f"{value:.3f}"), True
    if kind == "expression":
        part = draw(st.floats(-1000, 1000))
        rest = value - part
        equals = "=" if is_840d else ""
        return [], f"{address}{equals}{part:.3f}+{rest:.3f}", float(f"{part:.3f}") + float(f"{rest:.3f}"), False
    if kind == "r-parameter":
        number = "XYZFS".index(address) + 1     # one parameter per address: X and Z in a block must not share R1
        return [f"R{number}={value:.3f}"], f"{address}=R{number}", float(f"{value:.3f}"), False
    if kind == "exponent":
        text = draw(st.sampled_from([f"{value:.3e}", f"{value:.2E}"]))
        return [], f"{address}{text}", float(text), False
    if kind == "inf/nan":
        text = draw(st.sampled_from(["inf", "-inf", "nan", "INF", "NaN", "Infinity"]))
        return [], f"{address}{text}", float(text), False
    if kind == "ic/ac":
        form = draw(st.sampled_from(["IC", "AC"]))
        return [], f"{address}={form}({value:.3f})", float(f"{value:.3f}"), False
    return [], f"AX[{address}]={value:.3f}", float(f"{value:.3f}"), False


def values_around(low: float, high: float):
    span = max(high - low, 1.0)
    return st.one_of(st.floats(low - span, high + span),
                     st.sampled_from([low, high, low - 0.001, high + 0.001, low - 0.1, high + 0.1, 0.0]))


@st.composite
def control_or_not(draw, text: str):
    """The text, or the text with a control or non-ASCII character inserted where the test chose."""
    if not draw(st.booleans()):
        return text, False
    at = draw(st.integers(0, len(text)))
    return text[:at] + draw(st.sampled_from(CONTROL)) + text[at:], True


@st.composite
def comment(draw, is_840d: bool, any_printable: bool = False):
    """A comment, perhaps with a control or non-ASCII character; `any_printable`: the 840D lathe
    reads printable non-ASCII text in a comment (issue 27), so only a control character breaks it."""
    text = draw(st.text(alphabet="ABCXYZ0123456789 =.-", max_size=12))
    if not draw(st.booleans()):
        return "", False
    text, broken = draw(control_or_not(text))
    broken = broken and not (any_printable and all(character.isprintable() for character in text))
    return (f" ; {text}" if is_840d else f" ({text})"), broken


@st.composite
def moves(draw):
    """(machine, lines, accepted by the oracle)."""
    name = draw(st.sampled_from(sorted(DIALECTS)))
    prelude, axes, motions, is_840d, _ = DIALECTS[name]
    machine, hobbing = MACHINES[name], name.startswith("hobber")
    evaluates = name == "lathe-840d"
    chosen = draw(st.lists(st.sampled_from(axes), min_size=1, max_size=len(axes), unique=True))
    before, words, fine = [], [draw(st.sampled_from(motions))], True
    for axis in chosen:
        low, high = (getattr(machine, f"{axis.lower()}_min"), getattr(machine, f"{axis.lower()}_max"))
        lines, word, position, plain = draw(rendered(axis, draw(values_around(low, high)), is_840d, evaluates))
        # ISO: X114 is 0.114 mm without its point; a zero (X0, Z0) is the same either way
        plain = plain and (is_840d or "." in word or position == 0)
        before, fine = before + lines, fine and plain and inside(machine, axis, position, hobbing)
        words.append(word)
    if words[0] in ("G1", "G01") and draw(st.booleans()):
        lines, word, feed, plain = draw(rendered("F", draw(values_around(0.0, MAX_FEED)), is_840d, evaluates))
        plain = plain and (is_840d or "." in word)
        before, fine = before + lines, fine and plain and 0 < feed <= MAX_FEED
        words.append(word)
    block, broken = draw(control_or_not(" ".join(words)))
    note, broken_note = draw(comment(is_840d, evaluates))
    accepted = fine and not broken and not broken_note
    return machine, prelude + before + [block + note] + ENDINGS[name], accepted


@st.composite
def speeds(draw):
    name = draw(st.sampled_from(sorted(DIALECTS)))
    prelude, _, _, is_840d, form = DIALECTS[name]
    machine = MACHINES[name]
    lines, word, speed, plain = draw(rendered("S", draw(values_around(0.0, machine.spindle_max)), is_840d,
                                              name == "lathe-840d"))
    block, broken = draw(control_or_not(form.format(word[1:])))
    return (machine, prelude + lines + [block] + ENDINGS[name],
            plain and not broken and 0 < speed <= machine.spindle_max)


def verdict(machine: Machine, lines: list[str]) -> bool:
    try:
        verify_program(lines, machine, NAME)
    except LimitError:
        return False
    return True


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=600, deadline=None)
@given(moves())
def test_a_move_is_accepted_exactly_when_it_is_plain_and_inside_the_machine(case):
    machine, lines, accepted = case
    assert verdict(machine, lines) == accepted, lines


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=300, deadline=None)
@given(speeds())
def test_a_spindle_speed_is_accepted_exactly_when_it_is_plain_above_0_and_within_the_spindle(case):
    machine, lines, accepted = case
    assert verdict(machine, lines) == accepted, lines


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=300, deadline=None)
@given(step=st.floats(0, 2), low=values_around(-80, 0), high=values_around(0, 80), reset=values_around(-80, 80))
def test_the_hob_shift_clamp_is_accepted_exactly_when_its_whole_interval_lies_inside(step, low, high, reset):
    machine = MACHINES["hobber-840d"]
    prelude = DIALECTS["hobber-840d"][0]
    clamp = [f"R11=R11+{step:.3f} ; HOB SHIFT PER PART", f"IF (R11<{low:.3f}) OR (R11>{high:.3f})",
             f"R11={reset:.3f}", "ENDIF", "G0 Y=R11"]
    lo, hi, back = (float(f"{value:.3f}") for value in (low, high, reset))
    accepted = (float(f"{step:.3f}") > 0 and lo <= back <= hi
                and inside(machine, "Y", lo, True) and inside(machine, "Y", hi, True))
    assert verdict(machine, prelude + clamp + ENDINGS["hobber-840d"]) == accepted, clamp


# ---------------------------------------------------------------- the state a cut needs

HOB_EVENTS = ("M3 S246", "M5", 'EGON(C,"FINE",B,-1,19)', "EGOFS(C)", "G0 X55.000", "M8", "M9")


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@settings(max_examples=300, deadline=None)
@given(events=st.lists(st.sampled_from(HOB_EVENTS), max_size=8))
def test_a_hob_cut_is_accepted_exactly_when_the_spindle_turns_and_the_table_is_coupled(events):
    """The test's own reading: the spindle turns after an M3 S with no M5 since; the table is
    coupled after an EGON with no EGOFS since."""
    prelude = DIALECTS["hobber-840d"][0][:7] + ["EGDEF(C,B,1)"]
    def last(*lines):
        return next((event for event in reversed(events) if event in lines), None)
    accepted = last("M3 S246", "M5") == "M3 S246" and last(HOB_EVENTS[2], "EGOFS(C)") == HOB_EVENTS[2]
    lines = prelude + events + ["G1 Z10.000 F100.0"] + ENDINGS["hobber-840d"]
    assert verdict(MACHINES["hobber-840d"], lines) == accepted, events


TOOL_EVENTS = {   # block -> the offset it leaves: None if the block does not touch it
    "lathe-840d": {"T1 D1": True, "T2": False, "D0": False, "D3": True, "T4 D0": False, "D1 T5": True,
                   "M8": None, "G97 S300 M3": None},
    "lathe-iso": {"T0101": True, "T0200": False, "T0305": True, "T1200": False, "M08": None,
                  "G97 S300 M03": None},
}


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_a_lathe_cut_is_accepted_exactly_when_a_tool_offset_is_active(data):
    """840D: a T activates the edge the machine data says, so only a D (0: none) says the
    offset; ISO T<tool><offset>: offset 00 cancels it (reference §E)."""
    name = data.draw(st.sampled_from(sorted(TOOL_EVENTS)))
    events = data.draw(st.lists(st.sampled_from(sorted(TOOL_EVENTS[name])), max_size=6))
    prelude = [line for line in DIALECTS[name][0] if line not in ("T1 D1", "T0101")]
    offsets = [TOOL_EVENTS[name][event] for event in events if TOOL_EVENTS[name][event] is not None]
    cut = "G01 X20.000 Z-10.000" if name == "lathe-iso" else "G1 X20.000 Z-10.000"
    lines = prelude + events + [cut] + ENDINGS[name]
    assert verdict(MACHINES[name], lines) == bool(offsets and offsets[-1]), events


# ---------------------------------------------------------------- the table with its Z differential

@settings(max_examples=400, deadline=None)
@given(teeth=st.integers(5, 120), speed=st.integers(1, 1000), factor=st.floats(0, 2 * MAX_DIFFERENTIAL),
       feed=st.floats(0.1, MAX_FEED))
@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_table_is_accepted_exactly_when_its_speed_with_the_z_term_is_within_the_machine(teeth, speed, factor,
                                                                                          feed):
    machine = MACHINES["hobber-840d"]
    k, v = float(f"{factor:.6f}"), float(f"{feed:.1f}")
    table = speed / teeth + k * v / 360.0                    # reference §A5, k in °/mm, v in mm/min
    assume(abs(table - machine.table_speed_max) > 1e-6 and abs(speed / teeth - machine.table_speed_max) > 1e-6)
    lines = (DIALECTS["hobber-840d"][0][:7] + ["EGDEF(C,B,1,Z,1)", f'EGON(C,"FINE",B,-1,{teeth},Z,{k:.6f},1)',
                                                f"M3 S{speed}", f"G1 Z10.000 F{v:.1f}"] + ENDINGS["hobber-840d"])
    accepted = 0 < v and k <= MAX_DIFFERENTIAL and table <= machine.table_speed_max
    assert verdict(machine, lines) == accepted, lines


# ---------------------------------------------------------------- arcs

@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=400, deadline=None)
@given(start_x=st.floats(150, 250), start_z=st.floats(-300, -100), end_x=st.floats(150, 250),
       end_z=st.floats(-300, -100), radius=st.floats(0.01, 30), longer=st.booleans(), ccw=st.booleans())
def test_an_arc_is_accepted_exactly_when_its_radius_reaches_half_its_chord(start_x, start_z, end_x, end_z, radius,
                                                                          longer, ccw):
    """X is a diameter: the chord runs over (ΔX/2, ΔZ). The arc stays inside lathe-iso's travel
    (X 0…400, Z −600…200) for any radius up to 30 from these points: its centre lies within one
    radius of its ends, its points within two (X as a radius 75 − 60 … 125 + 60)."""
    values = [float(f"{value:.3f}") for value in (start_x, start_z, end_x, end_z, radius)]
    sx, sz, ex, ez, r = values
    half_chord = math.hypot((ex - sx) / 2.0, ez - sz) / 2.0
    assume(abs(r + ARC_TOLERANCE - half_chord) > 1e-6)
    arc = f"G0{3 if ccw else 2} X{ex:.3f} Z{ez:.3f} R{-r if longer else r:.3f}"
    lines = DIALECTS["lathe-iso"][0] + [f"G00 X{sx:.3f} Z{sz:.3f}", arc] + ENDINGS["lathe-iso"]
    assert verdict(MACHINES["lathe-iso"], lines) == (r + ARC_TOLERANCE >= half_chord), lines
