"""A shop's own lathe program (a class job: `engine import-nc`, `engine instantiate --class`) is
proved by the turning simulation without a drawing record (issue 27): against the blank the job
states, or the one its program implies (marked assumed); a rapid through material not cut yet, a
cut with the spindle stopped, a tool change in a moving block or inside the blank's envelope are
refused naming the line; what needs a drawing (cuts into the part, operations, tools, cutting
data) is reported as not checked, never claimed. Expected lengths are computed here from the
blank and the moves written in the test."""
from __future__ import annotations

import math

import pytest
from helpers.class_jobs import SHAFT_PROGRAM
from msgspec.structs import replace

from engine.errors import EngineError
from engine.machines.records import Machine
from engine.programs.class_jobs import job_params
from engine.simulation.hobbing.report import SimulationError
from engine.simulation.turning.follow import ProgramState
from engine.simulation.turning.reading import read_lathe_program
from engine.simulation.turning.report import TurningReport
from engine.simulation.turning.run import simulate_turning
from engine.simulation.turning.work import turning_records

LATHE = Machine("lathe-iso", "lathe", "iso", 0.0, 400.0, 0.0, 0.0, -600.0, 200.0, 4000.0, None, None)
SHAFT = SHAFT_PROGRAM.splitlines()
APPROACH = SHAFT.index("G00 X44.000 Z2.000")
CUT = SHAFT.index("G01 X36.000 Z-40.000")
AIR_TOLERANCE_MM = 0.01     # engine.simulation.turning.material: a rapid may graze the surface by this


def report(lines: list[str], params: dict | None = None):
    return simulate_turning(lines, params or {}, {}, LATHE, "SHAFT")


def inserted(after: int, line: str, lines: list[str] = SHAFT) -> list[str]:
    return [*lines[:after + 1], line, *lines[after + 1:]]


def refusal(lines: list[str], params: dict | None = None) -> str:
    """Why the program is refused: by the simulation's report, or already by the dialect's reading
    of it (the ISO reading refuses a tool change within the cuts so far, engine.verifier.expanders)."""
    try:
        found = report(lines, params)
    except SimulationError as refused:
        return str(refused)
    assert found.refused, found.lines()
    return str(found.error())


def test_a_class_job_s_program_is_clean_against_the_blank_it_implies_and_says_what_it_did_not_check():
    found = report(SHAFT)
    assert not found.refused, found.lines()
    assert found.blank == f"Ø{2 * 22.0:.3f} Z{-40.0:.3f}…{2.0:.3f} (assumed)"
    said = found.lines()
    assert any(line.startswith("not checked: a cut into the finished part") for line in said)
    assert any(line.startswith("not checked: feeds and cutting speeds") for line in said)
    assert found.as_dict()["not_checked"] == [line.removeprefix("not checked: ") for line in said
                                              if line.startswith("not checked: ")]


def test_the_adversary_s_rapid_through_the_blank_is_refused_naming_its_line():
    """G00 X0 Z-15 from the approach point (Z2, r22); the feed after it now starts on the axis, so
    the largest feed radius is the cut's 18 and the blank assumed Ø36 Z-40…2: the move runs in it
    from r 18 (4/22 of its way √(17² + 22²)) to its end, less the tolerance at the surface."""
    lines = inserted(APPROACH, "G00 X0.000 Z-15.000")
    message = refusal(lines)
    assert f"line {APPROACH + 2} 'G00 X0.000 Z-15.000'" in message and "rapid through material" in message
    inside = 18 / 22 * math.hypot(17, 22)
    through = float(message.split("rapid through material for ")[1].split(" mm")[0])
    assert inside - 4 * AIR_TOLERANCE_MM < through <= inside + 0.001


def test_a_refusal_against_an_assumed_blank_says_it_was_assumed_and_how_to_state_the_bar():
    """The new user's proven program refused against a blank the engine guessed: the message names
    that blank (Ø36 Z-40…2, as above) and the params that state the real bar; a stated blank's
    refusal does not say so."""
    message = refusal(inserted(APPROACH, "G00 X0.000 Z-15.000"))
    assert f"the blank Ø{36.0:.3f} Z{-40.0:.3f}…{2.0:.3f} is assumed" in message
    assert "stock_diameter, stock_z_front and stock_z_back" in message
    stated = refusal(SHAFT, {"stock_diameter": 60.0, "stock_z_front": 5.0, "stock_z_back": -80.0})
    assert "assumed" not in stated and "engine simulate" not in stated


def test_a_stated_blank_is_the_one_proved_against():
    """The job states a blank Ø60 whose face is at Z5: the approach G00 X44 Z2 from (Z50, r62) enters
    it at Z5 (t = 45/48 of the way) and runs the rest, 3/48 of √(48² + 40²), through it."""
    stock = {"stock_diameter": 60.0, "stock_z_front": 5.0, "stock_z_back": -80.0}
    message = refusal(SHAFT, stock)
    assert f"line {APPROACH + 1} 'G00 X44.000 Z2.000'" in message
    through = float(message.split("rapid through material for ")[1].split(" mm")[0])
    assert abs(through - 3 / 48 * math.hypot(48, 40)) < 0.05
    assert report(SHAFT, {**stock, "stock_z_front": 2.0}).blank == f"Ø{60.0:.3f} Z{-80.0:.3f}…{2.0:.3f}"


def test_a_tool_change_inside_the_blank_s_envelope_is_refused():
    """T0202 with the tool at X36 Z-40, at the bottom of its cut: r 18 < 22 behind the face Z2."""
    message = refusal(inserted(CUT, "T0202"))
    assert f"line {CUT + 2} 'T0202'" in message
    assert "inside the blank's envelope" in message or "within the cuts so far (up to X36 Z2)" in message


def test_a_tool_change_clear_of_the_blank_passes_and_one_in_a_moving_block_is_refused():
    clear = inserted(SHAFT.index("G00 X44.000 Z-40.000") + 1, "T0202")   # at X44 Z2: on the face, r 22
    assert refusal(clear)   # on the envelope's edge is not clear of it
    outside = inserted(len(SHAFT) - 4, "T0202")   # after G00 X124 Z50
    assert not report(outside).refused
    moving = [line.replace("G00 X124.000 Z50.000", "G00 X124.000 Z50.000 T0202") if n == len(SHAFT) - 4 else line
              for n, line in enumerate(SHAFT)]
    assert "a tool change in a block that moves" in refusal(moving)


def test_a_cut_with_the_spindle_stopped_is_refused():
    message = refusal(inserted(APPROACH, "M05"))
    assert f"line {APPROACH + 3} 'G01 X36.000 Z2.000'" in message and "spindle stopped" in message



def test_a_class_job_cuts_with_the_spindle_turning_either_way():
    """Which way a tool cuts (M03 or M04) is an operation record's: without one, turning is enough.
    (The ISO grammar reads M04 once the dialect work widens it: the reader's steps are given M4 here.)"""
    steps = [replace(step, m_codes=frozenset({4})) if step.m_codes == {3} else step
             for step in read_lathe_program(SHAFT, LATHE, "SHAFT")]
    state = ProgramState(turning_records({}, {}), TurningReport("SHAFT"), "iso", (124.0, 50.0))
    for step in steps:
        state.take(step)
    assert state.spindle is None and not state.report.findings and len(state.moves) == 7


def test_operations_without_a_drawing_s_profile_are_refused_not_proved_as_a_class_job():
    with pytest.raises(EngineError, match="no params.profile"):
        simulate_turning(SHAFT, {}, {"cutmotion:1": {"kind": "ROUGH"}}, LATHE, "SHAFT")


@pytest.mark.parametrize("given", [{"stock_diameter": 50}, {"stock_diameter": 50, "stock_z_front": 0}])
def test_a_class_job_s_blank_is_given_whole_or_not_at_all(given):
    with pytest.raises(EngineError, match="stock_z_back"):
        job_params("emco_neg", {"speed": 600}, given, "P.json")
    params, _ = job_params("emco_neg", {"speed": 600}, {**given, "stock_z_front": 0, "stock_z_back": -60},
                           "P.json")
    assert params["stock_z_back"] == -60


def test_a_tool_change_after_a_reference_return_is_clear_of_the_blank():
    """A reference return (ISO G28 U0. W0.: straight from where the tool stands to the record's
    reference point, reference_x/_z) runs at rapid to X400 Z200, far outside the Ø44 blank: a tool
    change there is clear, as it is not at the bottom of the cut it came from."""
    homed = replace(LATHE, reference_x=400.0, reference_z=200.0)
    at_cut = inserted(CUT, "G00 X36.000 Z-40.000")
    back = inserted(CUT + 1, "G28 U0. W0.", at_cut)
    found = simulate_turning(inserted(CUT + 2, "T0202", back), {}, {}, homed, "SHAFT")
    assert not found.refused, found.lines()
    with pytest.raises(SimulationError, match="T0202"):
        simulate_turning(inserted(CUT + 1, "T0202", at_cut), {}, {}, homed, "SHAFT")


def test_a_cut_behind_a_stated_blank_s_back_end_is_refused_a_class_job_has_no_parting_operation():
    """The blank Ø50 from Z2 to Z-30: the pass to Z-40 runs 10 mm behind its back end, into the bar
    the chuck holds (more than the 2 mm run-out); stated to Z-45, the same program is clean."""
    stock = {"stock_diameter": 50.0, "stock_z_front": 2.0, "stock_z_back": -30.0}
    message = refusal(SHAFT, stock)
    assert f"line {CUT + 1} 'G01 X36.000 Z-40.000'" in message and f"a cut {10.0:.3f} mm behind" in message
    assert not report(SHAFT, {**stock, "stock_z_back": -45.0}).refused
