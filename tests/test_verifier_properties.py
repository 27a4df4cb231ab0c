"""Properties of the verifier (issue 13), with random blocks of each dialect: 840D hobbing, 840D
lathe, ISO lathe. The test chooses every value and renders it itself, plainly or as an address
expression, an R-parameter, an exponent, inf/nan, IC/AC, an indirect axis, with or without a
control character in the block or its comment; it knows what the block evaluates to. The
oracle is the test's own: a block is accepted exactly when it is plain, holds printable ASCII
only, and its evaluated position (and feed, and speed) lies within the machine. So no block
whose position lies outside the machine is accepted, and a plain block inside it is not refused:
the test fails both ways.

The machines' limits come from seed_templates/machines.csv, the working area from the
prelude written here."""
from __future__ import annotations

import csv
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from engine.gears.records import Machine
from engine.programs.verifier import LimitError, verify_program

SEED = Path(__file__).resolve().parent.parent / "seed_templates" / "machines.csv"
MAX_FEED = 20000.0        # mm/min: the feed bound the lathe check has always had (about a rapid traverse)
AREA = {"X": (50.0, 250.0), "Y": (-30.0, 30.0), "Z": (-200.0, 100.0)}   # the hobbing prelude's G25/G26


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
DIALECTS = {   # name -> prelude, axes, motion codes, whether 840D (`=` forms, `;` comments), speed block
    "hobber-840d": (["%_N_P_MPF", ";$PATH=/_N_MPF_DIR", "G90 G71 G94",
                     "G25 X{X[0]:.3f} Y{Y[0]:.3f} Z{Z[0]:.3f}".format(**AREA),
                     "G26 X{X[1]:.3f} Y{Y[1]:.3f} Z{Z[1]:.3f}".format(**AREA), "WALIMON"],
                    ("X", "Y", "Z"), ("G0", "G1"), True, "M3 S{}"),
    "lathe-840d": (["%_N_P_MPF", ";$PATH=/_N_MPF_DIR", "G18 G71 G90 G40 DIAMON"],
                   ("X", "Z"), ("G0", "G1"), True, "G97 S{} M3"),
    "lathe-iso": (["%", "O0001 (P)", "G21 G18 G40 G90"], ("X", "Z"), ("G00", "G01"), False, "G97 S{} M03"),
}
PLAIN = ("plain", "plain one decimal", "plain whole", "plain trailing point", "equals")
NOT_PLAIN = ("expression", "r-parameter", "exponent", "inf/nan", "ic/ac", "indirect")
CONTROL = ["\n", "\r", "\x00", "\x7f", "\t", "\x1b", "é", "\u2028", "\x85"]


def inside(machine: Machine, axis: str, value: float, hobbing: bool) -> bool:
    low, high = getattr(machine, f"{axis.lower()}_min"), getattr(machine, f"{axis.lower()}_max")
    within_area = not hobbing or AREA[axis][0] <= value <= AREA[axis][1]
    return low <= value <= high and within_area


@st.composite
def rendered(draw, address: str, value: float, is_840d: bool):
    """(lines before the block, the word, its value as the control would evaluate it, plain?)."""
    kinds = [kind for kind in PLAIN + NOT_PLAIN if is_840d or kind not in ("equals", "r-parameter")]
    kind = draw(st.sampled_from(kinds))
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
        return [f"R1={value:.3f}"], f"{address}=R1", float(f"{value:.3f}"), False
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
def comment(draw, is_840d: bool):
    text = draw(st.text(alphabet="ABCXYZ0123456789 =.-", max_size=12))
    if not draw(st.booleans()):
        return "", False
    text, broken = draw(control_or_not(text))
    return (f" ; {text}" if is_840d else f" ({text})"), broken


@st.composite
def moves(draw):
    """(machine, lines, accepted by the oracle)."""
    name = draw(st.sampled_from(sorted(DIALECTS)))
    prelude, axes, motions, is_840d, _ = DIALECTS[name]
    machine, hobbing = MACHINES[name], name.startswith("hobber")
    chosen = draw(st.lists(st.sampled_from(axes), min_size=1, max_size=len(axes), unique=True))
    before, words, fine = [], [draw(st.sampled_from(motions))], True
    for axis in chosen:
        low, high = (getattr(machine, f"{axis.lower()}_min"), getattr(machine, f"{axis.lower()}_max"))
        lines, word, position, plain = draw(rendered(axis, draw(values_around(low, high)), is_840d))
        before, fine = before + lines, fine and plain and inside(machine, axis, position, hobbing)
        words.append(word)
    if words[0] in ("G1", "G01") and draw(st.booleans()):
        lines, word, feed, plain = draw(rendered("F", draw(values_around(0.0, MAX_FEED)), is_840d))
        before, fine = before + lines, fine and plain and 0 < feed <= MAX_FEED
        words.append(word)
    block, broken = draw(control_or_not(" ".join(words)))
    note, broken_note = draw(comment(is_840d))
    accepted = fine and not broken and not broken_note
    return machine, prelude + before + [block + note], accepted


@st.composite
def speeds(draw):
    name = draw(st.sampled_from(sorted(DIALECTS)))
    prelude, _, _, is_840d, form = DIALECTS[name]
    machine = MACHINES[name]
    lines, word, speed, plain = draw(rendered("S", draw(values_around(0.0, machine.spindle_max)), is_840d))
    block, broken = draw(control_or_not(form.format(word[1:])))
    return machine, prelude + lines + [block], plain and not broken and 0 < speed <= machine.spindle_max


def verdict(machine: Machine, lines: list[str]) -> bool:
    try:
        verify_program(lines, machine, "PROPERTY")
    except LimitError:
        return False
    return True


@settings(max_examples=600, deadline=None)
@given(moves())
def test_a_move_is_accepted_exactly_when_it_is_plain_and_inside_the_machine(case):
    machine, lines, accepted = case
    assert verdict(machine, lines) == accepted, lines


@settings(max_examples=300, deadline=None)
@given(speeds())
def test_a_spindle_speed_is_accepted_exactly_when_it_is_plain_above_0_and_within_the_spindle(case):
    machine, lines, accepted = case
    assert verdict(machine, lines) == accepted, lines


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
    assert verdict(machine, prelude + clamp) == accepted, clamp
