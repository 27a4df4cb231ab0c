"""Hob shift per part on the Fanuc hobber (issue 30): the 840D keeps the shift in R11 between
parts; the Fanuc program keeps it in the common variable #500, which Custom Macro B holds through
power-off (docs/reference/fanuc-egb.md §F9), and clamps it with two IF … THEN lines:

    #500=#500+<step> (HOB SHIFT PER PART)
    IF [#500 LT lo] THEN #500=lo
    IF [#500 GT hi] THEN #500=lo
    G0 Y#500

lo … hi is the hob's usable half-length either side of its middle (§B15):
hi = −lo = (L_hob − L_gen − 2·5 mm) / 2, L_gen = 2·2.25·m/tan α + π·m, computed here. The verifier
reads exactly these lines and refuses any other macro statement in one line; the simulation
follows the program with Y at both ends of lo … hi, as it does for the 840D's R11."""
from __future__ import annotations

import math
import re

import pytest

from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.hobbing.program_plot import load_scene, program_figure
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear
from engine.simulation import simulate_program
from engine.verifier import LimitError, verify_program

FANUC, SIEMENS = "hobber-fanuc", "hobber-840d"
STEP = 0.5                      # mm of shift per part
SHIFT = Choices(tailstock=False, shift_per_part=STEP)
SHIFT_MARGIN = 5.0              # mm kept free at each end of the hob (§B15)
MOVE = re.compile(r"G[01] ")
SHIFT_MOVES = ("G0 Y=R11", "G0 Y#500")
R11_TEST = re.compile(r"IF \(R11<(-?[\d.]+)\) OR \(R11>(-?[\d.]+)\)")
# Seeded gears by class (seed_templates/gears.csv): the classes whose templates shift per part
# (duplex takes the spur rows; the worm wheel does not shift per part on either control).
GEARS = [pytest.param(42, id="spur"), pytest.param(43, id="helical R"), pytest.param(44, id="helical L"),
         pytest.param(50, id="taper"), pytest.param(51, id="crowned"), pytest.param(54, id="duplex")]


def job_hob(conn, program):
    hob_id = conn.execute("SELECT hob_id FROM job WHERE id = %s", (program.job_id,)).fetchone()[0]
    return next(hob for hob in load_hobs(conn) if hob.id == hob_id)


def clamp_half(gear, hob) -> float:
    """(L_hob − L_gen − 2·margin)/2, L_gen = 2·2.25·m/tan α + π·m (§B15), mm."""
    generating = 2 * 2.25 * gear.module / math.tan(math.radians(gear.pressure_angle)) + math.pi * gear.module
    return (hob.length - generating - 2 * SHIFT_MARGIN) / 2


def fanuc_clamp(low: float, high: float, step: float = STEP) -> list[str]:
    return [f"#500=#500+{step:.3f} (HOB SHIFT PER PART)", f"IF [#500 LT {low:.3f}] THEN #500={low:.3f}",
            f"IF [#500 GT {high:.3f}] THEN #500={low:.3f}", "G0 Y#500"]


def moves(lines: list[str]) -> list[str]:
    """The motion blocks but the shift's, 840D's `A=` written as Fanuc's `A`."""
    return [line.replace("A=", "A") for line in lines if MOVE.match(line) and line not in SHIFT_MOVES]


def with_clamp(lines: list[str], clamp: list[str]) -> list[str]:
    at = next(number for number, line in enumerate(lines) if line.startswith("#500=#500+"))
    return lines[:at] + clamp + lines[at + 4:]


@pytest.fixture
def made(conn):
    program = instantiate_gear(conn, 43, machine=FANUC, choices=SHIFT)
    gear, hob = load_gear(conn, 43), job_hob(conn, program)
    return program, gear, hob, load_machine(conn, FANUC)


@pytest.mark.parametrize("gear_id", GEARS)
def test_the_fanuc_program_shifting_per_part_is_stored_verified_simulated_and_the_840d_twins_moves(conn, gear_id):
    fanuc = instantiate_gear(conn, gear_id, machine=FANUC, choices=SHIFT)
    siemens = instantiate_gear(conn, gear_id, machine=SIEMENS, choices=SHIFT)
    machine, gear, hob = load_machine(conn, FANUC), load_gear(conn, gear_id), job_hob(conn, fanuc)
    assert conn.execute("SELECT lines FROM program WHERE id = %s", (fanuc.program_id,)).fetchone()[0] == fanuc.lines
    verify_program(fanuc.lines, machine, fanuc.name)
    assert simulate_program(fanuc.lines, gear, hob, machine, fanuc.name).refusals == []
    half = clamp_half(gear, hob)
    at = fanuc.lines.index(f"#500=#500+{STEP:.3f} (HOB SHIFT PER PART)")
    assert fanuc.lines[at:at + 4] == fanuc_clamp(-half, half)
    low, high = (float(value) for value in R11_TEST.search("\n".join(siemens.lines)).groups())
    assert (low, high) == (pytest.approx(-half, abs=5e-4), pytest.approx(half, abs=5e-4))
    assert moves(fanuc.lines) == moves(siemens.lines) and moves(fanuc.lines)
    assert not any("R11" in line for line in fanuc.lines) and not any("#500" in line for line in siemens.lines)


def test_the_simulation_follows_the_fanuc_shift_at_both_ends_of_its_interval(made):
    """With lo or hi beyond the hob's usable half-length the generating zone leaves the hob at
    that end (§B15): |Y| + L_gen/2 > L_hob/2, so each end is reached only if it is followed."""
    program, gear, hob, machine = made
    generating = 2 * 2.25 * gear.module / math.tan(math.radians(gear.pressure_angle)) + math.pi * gear.module
    beyond = round(hob.length / 2 - generating / 2 + 2.0)       # 2 mm past the last whole-zone shift
    half = clamp_half(gear, hob)
    for low, high, end in ((-half, beyond, beyond), (-beyond, half, -beyond)):
        report = simulate_program(with_clamp(program.lines, fanuc_clamp(low, high)), gear, hob, machine, program.name)
        zone = [finding.message for finding in report.refusals if "generating zone" in finding.message]
        assert zone and all(f"Y{end:g}" in message for message in zone), (low, high, zone)


def refusal(lines: list[str], machine, name: str) -> str:
    with pytest.raises(LimitError) as raised:
        verify_program(lines, machine, name)
    message = str(raised.value)
    assert "\n" not in message and message.endswith("nothing stored")
    return message


MACRO_REFUSED = "a macro statement other than the hob-shift clamp"
LOW_END = "the low end, #500={lo}"
# (the clamp as written, its lo and hi put in from the gear's computed half-length; words of the
# one-line reason)
MALFORMED = [
    pytest.param(["{step}", "IF [#500 LT {lo} THEN #500={lo}", "{above}", "{move}"], MACRO_REFUSED,
                 id="missing bracket"),
    pytest.param(["{step}", "{below}", "{above}", "G0 Y#501"], MACRO_REFUSED, id="another variable in G0 Y"),
    pytest.param(["{step}", "{below}", "IF [#500 GT {hi}] THEN #500=0.000", "{move}"], LOW_END,
                 id="a clamp to another value"),
    pytest.param(["{step}", "IF [#500 LT {lo}] THEN #500=0.000", "{above}", "{move}"], LOW_END,
                 id="a low clamp to another value"),
    pytest.param(["#100=#100+0.500 (HOB SHIFT PER PART)", "{below}", "{above}", "{move}"], MACRO_REFUSED,
                 id="#100 local variable"),
    pytest.param(["{step}", "{below}", "IF [#500 GT {hi}] GOTO 10", "{move}"], MACRO_REFUSED, id="GOTO"),
    pytest.param(["{step}", "{below}", "WHILE [#500 GT {hi}] DO1", "{move}"], MACRO_REFUSED, id="WHILE"),
    pytest.param(["{step}", "{above}", "{below}", "{move}"], "must read exactly", id="out of order"),
    pytest.param(["{step}", "{below}", "{above}", "G0 X120.000", "{move}"], "incomplete", id="a line between"),
    pytest.param(["#500=#500-0.500 (HOB SHIFT PER PART)", "{below}", "{above}", "{move}"], MACRO_REFUSED,
                 id="a step down"),
    pytest.param(["{step}", "{below}", "{above}", "G1 Y#500 F100."], MACRO_REFUSED, id="a cut to the variable"),
]


@pytest.mark.parametrize("clamp, words", MALFORMED)
def test_each_malformed_macro_line_is_refused_in_one_line(made, clamp, words):
    program, gear, hob, machine = made
    half = clamp_half(gear, hob)
    step, below, above, move = fanuc_clamp(-half, half)
    numbers = {"lo": f"{-half:.3f}", "hi": f"{half:.3f}"}
    lines = [line.format(step=step, below=below, above=above, move=move, **numbers) for line in clamp]
    message = refusal(with_clamp(program.lines, lines), machine, program.name)
    assert words.format(lo=f"{float(numbers['lo']):g}") in message


def test_a_clamp_end_beyond_the_travel_is_refused_by_the_verifier(made):
    program, gear, hob, machine = made
    lines = with_clamp(program.lines, fanuc_clamp(-clamp_half(gear, hob), machine.y_max + 1.0))
    message = refusal(lines, machine, program.name)
    assert f"Y{machine.y_max + 1.0:g}" in message


def test_the_plot_draws_the_fanuc_shift_range_as_the_840d_ones(conn):
    """`engine plot`'s hob panel says the shift range: Y−half … Y+half on both controls."""
    said = {}
    for machine in (FANUC, SIEMENS):
        program = instantiate_gear(conn, 42, machine=machine, choices=SHIFT)
        half = clamp_half(load_gear(conn, 42), job_hob(conn, program))
        lines = program_figure(load_scene(conn, program.program_id))[1]
        said[machine] = [line for line in lines if line.startswith("shift range on the hob")]
        assert said[machine] and said[machine][0].startswith(f"shift range on the hob: Y{-half:.3f} … Y{half:.3f}")
    assert said[FANUC] == said[SIEMENS]
