"""gmoccapy's lathe macros (issue 27, LinuxCNC configs/sim/gmoccapy/lathe_configs) verified on the
seeded LinuxCNC lathe as gmoccapy's Cycles tab runs them: the INI's startup code, the tool where the
sim homes it, the tab's MDI call with the values the sim restores (docs/reference/linuxcnc-lathe.md
§7). Each is verified or refused naming the fault of those values; an attack inserted into a
verified one is refused. Also the two axis lathe macros go_to_position and probe-hole."""
from __future__ import annotations

import math

import pytest
from helpers.gmoccapy_programs import AXIS_MACROS, GMOCCAPY, axis_macro, gmoccapy_lines, gmoccapy_program
from helpers.linuxcnc_programs import LATHE, refusal

from engine.verifier.expanders.linuxcnc_gmoccapy import mdi_call
from engine.verifier.refusals import Refused


def assert_outcome(lines: list[str], construct: str | None) -> None:
    message = refusal(lines)
    if construct is None:
        assert message is None, message
    else:
        assert message is not None and construct in message and "nothing stored" in message, message
        assert message.count("\n") == 0


@pytest.mark.parametrize("name", sorted(GMOCCAPY))
def test_each_gmoccapy_macro_as_the_shipped_sim_runs_it_is_verified_or_refused_naming_its_fault(name):
    assert_outcome(gmoccapy_program(name), GMOCCAPY[name][0])


@pytest.mark.parametrize("name", sorted(GMOCCAPY))
def test_each_gmoccapy_macro_with_the_ui_s_own_values(name):
    expected = GMOCCAPY[name][1]
    if expected and "lathe.tbl" in expected:      # no start position: the caller refuses before verifying
        with pytest.raises(Refused, match=expected):
            gmoccapy_program(name, ui=True)
    else:
        assert_outcome(gmoccapy_program(name, ui=True), expected)


def test_the_verified_ones_are_grooving_radius_and_threading():
    assert sorted(name for name, (saved, _) in GMOCCAPY.items() if saved is None) == [
        "grooving", "radius", "threading"]


# the X (a diameter) each refused pass reaches, from the macro's own formulas and the values it is called with
TAN4, SIN4 = math.tan(math.radians(4)), math.sin(math.radians(4))
PAST_THE_AXIS = {
    # turning.ngc in G8 from Z15: #23 = z + rad - rad·sin(angle), #24 = (Z15 - #23)·tan(angle), X = 2·(x/2 + #24)
    ("turning", False): 2 * (15 / 2 + (15 - (120 + 3 - 3 * SIN4)) * TAN4),
    ("boring", False): 2 * (0 / 2 + 0 - 1),       # G1 X[#1 + #24 - #3], #24 = 0 at angle 0
    ("chamfer", False): 2 * (0 / 2 - 0.5),        # back outside: g0 x[#1 - #20], #20 = the step 0.5
    ("threading", True): 0 - 0.108 * 1,           # G7: #<OD> = x - 0.108·pitch
}


@pytest.mark.parametrize("case", sorted(PAST_THE_AXIS))
def test_a_refused_pass_is_named_with_the_x_the_macro_computes(case):
    name, ui = case
    message = refusal(gmoccapy_program(name, ui=ui))
    assert message is not None and f"X{round(PAST_THE_AXIS[case], 4):g} exceeds the travel" in message, message


def test_the_tab_sends_its_command_with_each_pin_as_percent_f():
    """chamfer.go of lathemacro.ui, savestate.sav's values: spin boxes as %f, the tool's -s pin
    as int(), the radio buttons as 1/0; the literal [0.5] [0] stay as written."""
    assert mdi_call("chamfer") == ("O<chamfer>call [0.000000] [100.000000] [0.5] [0] [0.000000] [1.000000] [0] "
                                   "[1.000000]  [0.000000] [0.000000] [1.000000] [0.000000]")


@pytest.mark.parametrize("name, tool_x, tool_z", [("turning", -12.0, -25.0), ("threading", 5.737, 12.2399),
                                                  ("drilling", 1.123, 25.456), ("grooving", 0.0, 0.0)])
def test_the_tool_starts_at_the_sim_s_home_through_its_offsets(name, tool_x, tool_z):
    """lathe_macros.ini homes X to 10 mm (a radius) and Z to -10 mm; the macro reads the position
    after its G43 with the tool's lathe.tbl offsets; G8 (the startup code's) reads X as a radius."""
    startup, start = gmoccapy_program(name)[:2]
    assert "G8" in startup.split() and "G21" in startup.split()
    assert start == f"G0 X{10 - tool_x:g} Z{-10 - tool_z:g}"


def test_each_file_alone_runs_only_its_own_test_call():
    """Seven only define their sub: refused as never called. drilling.ngc calls itself after its
    endsub with tool 0 (the tailstock): that branch only starts the spindle, and is verified."""
    for name in GMOCCAPY:
        message = refusal(gmoccapy_lines(name))
        if name == "drilling":
            assert message is None, message
        else:
            assert message is not None and "sub is never called" in message, message


@pytest.mark.parametrize("name", sorted(name for name, (saved, _) in GMOCCAPY.items() if saved is None))
def test_a_cut_past_the_z_travel_inserted_into_a_verified_macro_is_refused(name):
    lines = gmoccapy_program(name)
    at = next(n for n, line in enumerate(lines) if line.strip().upper().startswith("M5 M9"))
    beyond = LATHE.z_min - 1
    message = refusal([*lines[:at], f"G1 Z{beyond:g}", *lines[at:]])
    assert message is not None and f"Z{beyond:g} exceeds the travel of lathe-linuxcnc" in message, message


@pytest.mark.parametrize("name", sorted(AXIS_MACROS))
def test_each_axis_lathe_macro_as_called_is_verified_or_refused_naming_its_construct(name):
    assert_outcome(axis_macro(name), AXIS_MACROS[name])
