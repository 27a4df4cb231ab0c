"""The real LinuxCNC lathe programs (issue 27, tests/data/nc/linuxcnc): each is verified on the
seeded LinuxCNC lathe, or refused naming the construct that is really there; a subroutine file
is verified as its screen calls it (ngcgui, the lathe macros), and alone it is refused because
nothing of it runs. The attack forms of issue 26 inserted into a real program are refused.

Each verified program is also followed by the turning simulation of a class job (i27-classsim,
merged here) on the bar it is called on."""
from __future__ import annotations

import pytest
from helpers.linuxcnc_programs import LATHE, PLASMA, PROGRAMS, file_lines, program_of, refusal

import engine.verifier.expanders.linuxcnc as interpreter
from engine.simulation.turning.run import simulate_turning

VERIFIED = sorted(name for name, (_, construct) in PROGRAMS.items() if construct is None)
CALLED = sorted(name for name, (how, _) in PROGRAMS.items() if how)


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_each_real_lathe_program_is_verified_or_refused_naming_its_construct(name):
    how, construct = PROGRAMS[name]
    message = refusal(program_of(name))
    if construct is None:
        assert message is None, message
    else:
        assert message is not None and construct in message, message
        assert message.count("\n") == 0 and "nothing stored" in message


@pytest.mark.parametrize("name", CALLED)
@pytest.mark.parametrize("path_mode, reason", [
    ("g64 p0.002", "G64 P0.002 blends corners up to 0.0508 mm"),          # 0.002 in × 25.4
    ("g64", "G64 without P blends corners without a bound"),
])
def test_a_preamble_that_blends_more_than_a_thousandth_of_an_inch_is_refused(name, path_mode, reason):
    """The screens' preamble blends within #<tol> = 0.001 in (0.0254 mm), which the turning simulation
    allows for; twice that, or a bare G64 (no bound at all), is refused before the file runs."""
    lines = [path_mode if line.startswith("g64 p#<tol>") else line for line in program_of(name)]
    assert lines != program_of(name)
    message = refusal(lines)
    assert message is not None and reason in message, message


@pytest.mark.parametrize("name", sorted(set(VERIFIED) - {"lathe_macros/threading.ngc"}))
def test_a_cut_after_a_macro_s_call_meets_the_spindle_its_m73_restored(name):
    """The macros save the modes with M73 before they start the spindle and stop it (M5) at the end:
    the return restores the caller's stopped spindle and its S, never set: 0 (LinuxCNC writes
    " S%.0f"). A cut appended after the call is refused for the stopped spindle, an M3 for S0."""
    lines = program_of(name)
    assert lines[-1] == "m2"
    message = refusal([*lines[:-1], "g1 x1.3 f1", "m2"])
    assert message is not None and "a cut with the spindle stopped" in message, message
    message = refusal([*lines[:-1], "m3", "m2"])
    assert message is not None and "M3 with S0 in force" in message, message
    assert refusal([*lines[:-1], "s500 m3", "m5", "m2"]) is None


def test_the_verified_programs_are_the_macros_that_turn_face_bore_chamfer_drill_and_thread():
    assert VERIFIED == ["lathe_macros/boring.ngc", "lathe_macros/chamfer.ngc", "lathe_macros/drill.ngc",
                        "lathe_macros/facing.ngc",
                        "lathe_macros/threading.ngc", "lathe_macros/turning.ngc"]


@pytest.mark.parametrize("name", sorted(name for name, (how, _) in PROGRAMS.items() if how))
def test_a_subroutine_file_alone_runs_nothing_and_is_refused_so(name):
    message = refusal(file_lines(name))
    assert message is not None and "sub is never called" in message and "verify the program that calls it" in message


@pytest.mark.parametrize("name", sorted(PLASMA))
def test_a_plasma_mill_program_is_refused_for_what_it_drives(name):
    message = refusal(file_lines(name))
    assert message is not None and PLASMA[name] in message, message


# --- attack forms inserted into a real program (the turning macro as called) ------------------------------

TURNING = "lathe_macros/turning.ngc"


def turning_with(old: str, *new: str) -> list[str]:
    """The turning macro as called, the line starting `old` replaced by `new` (several lines: inserted)."""
    lines = program_of(TURNING)
    at = next(n for n, line in enumerate(lines) if line.strip().startswith(old))
    return [*lines[:at], *new, *lines[at + 1:]]


ATTACKS = {
    "a feed past the travel": (("G1 Z #23 X[#14 + #24]", "G1 Z #23 X[#14 + #24]", "G1 X400.5"),
                               "X801 exceeds the travel of lathe-linuxcnc"),
    "a G96 without a speed clamp": (("G96 D#9 S#2", "G96 S#2"), "G96 without a speed clamp D"),
    "a tool change at the cut": (("m3 ;Start Spindle", "m3", "M6 T2 G43"), "a tool change with the spindle turning"),
    "a subprogram not in the file": (("m3 ;Start Spindle", "m3", "o<roughing> call [1]"),
                                     "the file roughing.ngc is not in this program"),
    "a cut with the spindle stopped": (("m3 ;Start Spindle", "m5"), "a cut with the spindle stopped"),
    "a thread faster than the feed bound": (("G1 Z #23 X[#14 + #24]", "G33 Z-10 K20"), "feeds 30000 mm/min along Z"),
    "a radius compensation": (("g0 X #14", "G42 g0 X #14"), "the tool path under compensation"),
}


@pytest.mark.parametrize("attack", sorted(ATTACKS))
def test_an_attack_inserted_into_a_real_program_is_refused_with_its_reason(attack):
    (old, *new), reason = ATTACKS[attack]
    assert refusal(program_of(TURNING)) is None
    message = refusal(turning_with(old, *new))
    assert message is not None and reason in message, message


def test_a_spindle_clamp_over_the_machine_s_maximum_is_refused():
    """The macro's ninth value is the G96 clamp D: the most the spindle turns near the axis."""
    values = program_of(TURNING)[-2]
    assert values.endswith("[1][1500]")
    lines = program_of(TURNING)
    lines[-2] = values.replace("[1500]", f"[{LATHE.spindle_max + 1:g}]")
    message = refusal(lines)
    assert message is not None and f"S{LATHE.spindle_max + 1:g} exceeds" in message, message


def test_a_loop_that_never_ends_is_refused_at_the_step_bound(monkeypatch):
    monkeypatch.setattr(interpreter, "MAX_STEPS", 5_000)
    message = refusal(turning_with("m3 ;Start Spindle", "m3", "o900 while [1]", "o900 endwhile"))
    assert message is not None and "more than 5,000 lines run" in message and "o900 " in message, message


# --- the turning simulation of a program without a drawing (i27-classsim) ----------------------------------

# The bar the macros are called on (params of a class job, mm): Ø1.2 in, its front face at Z0,
# the tool starting 0.1 in in front of it (MACRO_START), so tool changes there are clear of it.
BAR = {"stock_diameter": 1.2 * 25.4, "stock_z_front": 0.0, "stock_z_back": -100.0}
SIMULATED = {
    "lathe_macros/turning.ngc": None, "lathe_macros/chamfer.ngc": None, "lathe_macros/threading.ngc": None,
    "lathe_macros/drill.ngc": None,       # G83 on the axis: pecks into the bar's solid centre
    # the stock's fault: after its finish pass the macro backs off inward (X[#1 - #3]) and rapids out
    # along Z (G0 Z #13), right in a bored blank; a class job's blank is solid (its params hold no
    # bore) and the walk clears only the column above a cut, so the retract runs through the core
    "lathe_macros/boring.ngc": "a rapid through material",
    # the walk's chip, not the stock: each pass feeds in to #1 at Z#13, then G0 Z[#13+#3] along the
    # shoulder; a facing tool removes the slab #13…#13+#3, the walk only the radial feed's own line
    # (tests/test_real_programs_made.py holds each program's outcome on the stock it is written for)
    "lathe_macros/facing.ngc": "a rapid through material",
}


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("name", VERIFIED)
def test_each_verified_program_is_simulated_on_its_bar(name):
    findings = [finding.message for finding in simulate_turning(program_of(name), BAR, {}, LATHE, name).findings]
    expected = SIMULATED[name]
    assert (findings == []) if expected is None else any(expected in found for found in findings), findings


def test_a_rapid_into_the_part_inserted_into_a_real_program_is_refused_by_the_simulation():
    lines = turning_with("G1 Z #23 X[#14 + #24]", "G1 Z #23 X[#14 + #24]", "G0 X0")
    assert refusal(lines) is None          # the verifier alone lets it pass: the travel holds X0
    findings = simulate_turning(lines, BAR, {}, LATHE, "turning").findings
    assert findings and "a rapid through material" in findings[0].message and findings[0].line == "G0 X0"
