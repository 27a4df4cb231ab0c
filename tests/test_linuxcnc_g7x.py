"""LinuxCNC's lathe profile cycles G70/G71/G72 expanded into the moves the control makes (issue 27,
docs/reference/linuxcnc-lathe.md §5). The numbers expected here come from LinuxCNC's own
reference: docs/src/gcode/g-code.adoc "G70 Lathe finishing cycle" and "G71 G72 Lathe roughing
cycles", and src/emc/rs274ngc/interp_g7x.cc (LinuxCNC/linuxcnc 5c41560e; `cc NNN` its line):

* G71 I R (cc 698-727, pocket cc 738-840): from the start X (a radius here), levels I apart
  (cc 753: x -= delta); each level rapids onto the lead-in line from the start to the profile's
  first point, feeds along Z to where the profile (or the closing line at the profile's last Z up
  to the start X, cc 718-724) is met, retracts R in X and R in Z at 45° (escape = R·(1+i)),
  rapids back to the entry Z − R and down to the entry (cc 825-837); at the profile's first X the
  profile itself is followed (climb, cc 766-781). D, I, R are not halved in G7 (cc 1188-1196).
* G70 D E P (cc 660-687, adoc "Multiple passes"): P passes, pass n at distance (n − 1)·(D − E)/P
  + E from the profile, positive towards the start; each rapids to the start and to the offset
  profile's first point and follows it; an outer corner becomes an arc of radius the distance
  about the corner (add_distance, cc 867-879).
* A segment whose Z grows is "Not monotonic" (cc 65, 611-619): LinuxCNC stops with "G7X error".

LinuxCNC's own test programs (tests/interp, in tests/data/nc/linuxcnc/interp_tests with their
expected interpreter output) expand to exactly the moves of that output, move by move to its
four decimals, once the radius mode rs274 starts in (G8) is stated."""
from __future__ import annotations

import re
from collections.abc import Callable

import pytest
from helpers.linuxcnc_programs import FOLDER, LATHE, refusal

import engine.verifier.expanders.cycles as iso_cycles
from engine.simulation.turning.run import simulate_turning
from engine.verifier.expanders.linuxcnc import Interpreter

START_X, START_Z, DEPTH, RETRACT = 20.0, 2.0, 2.0, 0.5          # radius, mm
FIRST = (10.0, 0.0)          # the profile's first point (X radius, Z); then Z-20, X16, Z-30
SHOULDER, END = (16.0, -20.0), (16.0, -30.0)
HEAD = ["G7 G18 G21 G90 G94 G40", "T1 M6", "G43", "S500 M3", "F100",
        "o100 sub", "G1 X20 Z0", "G1 Z-20", "G1 X32", "G1 Z-30", "o100 endsub", "G0 X40 Z2"]
ROUGH = "G71 Q100 X40 Z2 D0 I2 R0.5"
FINISH = "G70 Q100 X40 Z2 D1 E0 P2"
TAIL = ["M5", "M2"]


def moves(lines: list[str]) -> list[tuple[str, float, float, float | None]]:
    """(G code, X diameter, Z, R or None) of each move the expander writes."""
    found = []
    for plain in Interpreter(lines).run():
        words = plain.text.split()
        if words[0] in ("G0", "G1", "G2", "G3"):
            value = {word[0]: float(word[1:]) for word in words[1:] if word[0] in "XZR"}
            found.append((words[0], value["X"], value["Z"], value.get("R")))
    return found


def close(found: list, expected: list, tolerance: float = 1e-6) -> bool:
    return len(found) == len(expected) and all(
        a[0] == b[0] and all(abs(p - q) <= tolerance for p, q in zip(a[1:3], b[1:3])) for a, b in zip(found, expected))


def entry(x: float) -> float:
    """The Z where the level x meets the lead-in from the start to the profile's first point."""
    return START_Z + (FIRST[1] - START_Z) * (START_X - x) / (START_X - FIRST[0])


def roughing_expected() -> list[tuple[str, float, float]]:
    g0, g1 = "G0", "G1"
    expected = [(g0, 2 * START_X, START_Z)] * 3          # cc 1046, cc 717, the first dive (at the start)
    x, level = START_X, 0
    while x > FIRST[0] + 1e-9:
        z_in, z_end = entry(x), (END[1] if x > SHOULDER[0] else SHOULDER[1])
        if level:
            expected.append((g0, 2 * x, z_in))
        expected += [(g1, 2 * x, z_end), (g0, 2 * (x + RETRACT), z_end + RETRACT),
                     (g0, 2 * (x + RETRACT), z_in - RETRACT), (g0, 2 * x, z_in)]
        x, level = x - DEPTH, level + 1
    return expected + [(g0, 2 * FIRST[0], FIRST[1]), (g1, 2 * FIRST[0], SHOULDER[1]),
                       (g1, 2 * SHOULDER[0], SHOULDER[1]), (g1, 2 * END[0], END[1]), (g1, 2 * START_X, END[1])]


def test_g71_cuts_levels_i_apart_from_the_start_each_retracted_r_at_45_degrees():
    found = moves([*HEAD, ROUGH, *TAIL])[1:]           # after the program's own G0 X40 Z2
    expected = roughing_expected()
    assert close(found, expected), (found, expected)
    cuts = [move for move in found if move[0] == "G1"][:-4]
    assert [move[1] / 2 for move in cuts] == [START_X - n * DEPTH for n in range(5)]   # 20, 18 … 12 (radius)


def test_g70_makes_p_passes_from_d_down_to_e_each_from_the_start():
    found = moves([*HEAD, FINISH, *TAIL])[1:]
    d, e, passes = 1.0, 0.0, 2
    expected: list[tuple[str, float, float]] = [("G0", 2 * START_X, START_Z)]      # the cycle's rapid (cc 1046)
    for number in range(passes, 0, -1):
        k = (number - 1) * (d - e) / passes + e                 # adoc: (pass-1)*(D-E)/P+E
        expected += [("G0", 2 * START_X, START_Z), ("G0", 2 * (FIRST[0] + k), FIRST[1]),
                     ("G1", 2 * (FIRST[0] + k), SHOULDER[1] + k), ("G1", 2 * SHOULDER[0], SHOULDER[1] + k)]
        if k:                                                   # the outer corner at X16 Z-20: an arc of radius k
            expected.append(("G3", 2 * (SHOULDER[0] + k), SHOULDER[1]))
        expected.append(("G1", 2 * (END[0] + k), END[1]))
    assert close(found, expected), (found, expected)
    assert [move[3] for move in found if move[0] == "G3"] == [pytest.approx(0.5)]


def test_the_cycles_program_is_verified_and_the_turning_simulation_follows_every_move():
    """On a Ø40 bar (the start X): each level cuts the bar, each retract and return stays in air."""
    program = [*HEAD, ROUGH, FINISH, *TAIL]
    assert refusal(program) is None
    bar = {"stock_diameter": 2 * START_X, "stock_z_front": 0.0, "stock_z_back": -100.0}
    report = simulate_turning(program, bar, {}, LATHE, "g7x")
    made = moves(program)
    assert report.findings == []
    assert (report.rapids, report.cut_moves) == (sum(m[0] == "G0" for m in made), sum(m[0] != "G0" for m in made))


def back_in_z(code: str) -> list[str]:
    """A profile whose third segment goes back 5 mm in Z (X only grows: 10, 10, 13, 13 radius)."""
    return [*HEAD[:5], "o200 sub", "G1 X20 Z0", "G1 Z-20", "G1 X26 Z-15", "G1 Z-30", "o200 endsub", "G0 X40 Z2",
            f"{code} Q200 X40 Z2 I2 R0.5", *TAIL]


@pytest.mark.parametrize("code", ["G71", "G71.1", "G71.2"])
def test_a_profile_whose_z_goes_back_is_refused_as_linuxcnc_refuses_it(code):
    message = refusal(back_in_z(code))
    assert message is not None and 'G7X error: Not monotonic' in message and f"'{code} Q200" in message, message


@pytest.mark.parametrize("code", ["G70", "G72"])
def test_the_same_profile_monotone_in_x_is_followed_by_g70_and_g72(code):
    """G72 turns the profile 90° (cc 733); G70 does when it is not monotone in Z (cc 631, 666)."""
    assert refusal(back_in_z(code)) is None


def test_the_expansion_is_bounded():
    levels = round(2 * (START_X - FIRST[0]) / 0.001)            # I0.001 over 10 mm of radius
    assert levels > iso_cycles.MAX_PASSES
    message = refusal([*HEAD, "G71 Q100 X40 Z2 I0.001", *TAIL])
    assert message is not None and f"more than {iso_cycles.MAX_PASSES:,} levels" in message, message
    message = refusal([*HEAD, f"G70 Q100 X40 Z2 P{iso_cycles.MAX_PASSES + 1}", *TAIL])
    assert message is not None and "finishing passes" in message, message


@pytest.mark.parametrize("line, reason", [
    ("G71 Q100 X40 Z2 I0", "I must be greater than zero"), ("G71 X40 Z2", "requires a Q word"),
    ("G71 Q7 X40 Z2", "no o7 sub in this program"), ("G71 Q100 X40 Z2 A1", "the lathe has no A axis")])
def test_linuxcnc_s_errors_are_refusals(line, reason):
    message = refusal([*HEAD, line, *TAIL])
    assert message is not None and reason in message, message


# --- LinuxCNC's own tests: the moves of their expected output -------------------------------------------

CANON = re.compile(r"\s*N\.+\s+(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED)\((.*)\)")
# test program -> the lines stated before it (rs274's start: G8, mm) and a line it drops; the
# g72 programs open with `G54 G18 G21 F400`, whose F LinuxCNC reads in the units before the G21
GOLDEN = {"g71-with-g70": (["G8"], None), "g72-iterations-present": (["G21 G8"], None),
          "g72-iterations-missing": (["G21 G8"], None), "g71-endless-loop2": (["G21 G8"], None),
          # G92.1 clears offsets nothing set; the verifier refuses every G92 code, so it is left out here
          "g71-endless-loop": ([], "G90 G92.1 (G90 abs dist mode, G92.1 Reset coord sys offset)")}


def canon(name: str) -> list[tuple[str, float, float]]:
    """LinuxCNC's moves: STRAIGHT_TRAVERSE/FEED(x, y, z, …), ARC_FEED(z, x, cz, cx, turn, …) in XZ."""
    found = []
    for line in (FOLDER / "interp_tests" / f"{name}.expected").read_text().splitlines():
        match = CANON.match(line)
        if match:
            numbers = [float(v) for v in match.group(2).replace(" ", ",").split(",") if v]
            if match.group(1) == "ARC_FEED":
                found.append(("G3" if numbers[4] > 0 else "G2", 2 * numbers[1], numbers[0]))
            else:
                found.append(("G0" if match.group(1) == "STRAIGHT_TRAVERSE" else "G1", 2 * numbers[0], numbers[2]))
    return found


@pytest.mark.parametrize("name", sorted(GOLDEN))
def test_linuxcnc_s_own_g7x_tests_expand_to_their_expected_moves(name):
    before, dropped = GOLDEN[name]
    program = [line for line in (FOLDER / "interp_tests" / f"{name}.ngc").read_text().splitlines() if line != dropped]
    expected = canon(name)
    found = [move[:3] for move in moves([*before, *program])]
    assert len(expected) > 5 and close(found, expected, tolerance=1.2e-4), (found, expected)


def test_the_demo_s_profile_with_g8_and_a_tool_is_verified():
    program = (FOLDER / "interp_tests" / "g71-with-g70.ngc").read_text().splitlines()
    assert refusal(["G8", "T1 M6", "G43", "S500 M3", *program]) is None


@pytest.mark.parametrize("name, x", [("lathe_g7x_quadrants.ngc", "X-2 "), ("lathe_g7x_face_boring.ngc", "X-0.0487")])
def test_the_quadrant_files_with_g8_and_a_tool_cross_the_machine_s_x0(name, x):
    """Their profiles reach X-1 (radius) and a G72 retract below X0: the seeded lathe's X travel is 0 … 400."""
    program = (FOLDER / name).read_text().splitlines()
    message = refusal(["G8", "T1 M6", "G43", "S500 M3", *program])
    assert message is not None and f"{x}" in message and "exceeds the travel of lathe-linuxcnc (X 0…400)" in message


# --- the other quadrants: the same cut, mirrored -----------------------------------------------------------

MIDDLE = 25.0      # radius, mm: X mirrored about it keeps every X above 0


def mirrored(z_sense: int, x_sense: int) -> tuple[list[str], Callable[[tuple], tuple]]:
    """The program of HEAD, ROUGH and FINISH mirrored in Z and/or in X, and the maps of a move."""
    def x(radius: float) -> float:
        return 2 * (MIDDLE + x_sense * (radius - MIDDLE))

    points = [(10, 0), (10, -20), (16, -20), (16, -30)]
    lines = [*HEAD[:5], "o100 sub", *(f"G1 X{x(r):g} Z{z_sense * z:g}" for r, z in points), "o100 endsub",
             f"G0 X{x(20):g} Z{z_sense * 2:g}", f"G71 Q100 X{x(20):g} Z{z_sense * 2:g} D0 I2 R0.5",
             f"G70 Q100 X{x(20):g} Z{z_sense * 2:g} D1 E0 P2", *TAIL]
    arcs = {"G2": "G3", "G3": "G2"} if z_sense * x_sense < 0 else {}
    return lines, lambda move: (arcs.get(move[0], move[0]), x(move[1] / 2), z_sense * move[2])


@pytest.mark.parametrize("z_sense, x_sense", [(-1, 1), (1, -1), (-1, -1)])
def test_a_profile_in_another_quadrant_is_cut_as_its_mirror_image(z_sense, x_sense):
    """swap() turns the profile so X grows and Z falls along it and the moves go out mirrored back
    (cc 582-609, swapped_motion cc 517-561): an arc changes its sense under one mirror."""
    original = moves(mirrored(1, 1)[0])
    lines, image = mirrored(z_sense, x_sense)
    expected = [image(move) for move in original]
    assert close(moves(lines), expected, tolerance=1e-6)


# --- types: pockets cut (G71), left (G71.1), only they (G71.2) -----------------------------------------------

POCKET = ["o300 sub", "G1 X32 Z0", "G1 Z-10", "G1 X20", "G1 Z-20", "G1 X32", "G1 Z-30", "o300 endsub"]
TOP, FLOOR = 16.0, 10.0          # radius: the pocket between Z-10 and Z-20 goes down from X16 to X10


def levels(code: str) -> tuple[list[float], list[float]]:
    """(the radii of the cuts along Z over the whole length to the Z-30 closing line, the radii of the
    feeds along the pocket from Z-10 to its wall at Z-20 below its top X16)."""
    made = moves([*HEAD[:5], *POCKET, "G0 X40 Z2", f"{code} Q300 X40 Z2 D0 I2 R0.5", *TAIL])
    along = [(a[2], b[2], b[1] / 2) for a, b in zip(made, made[1:]) if b[0] == "G1" and a[1] == b[1] and a[2] != b[2]]
    return ([x for z0, z1, x in along if z1 == -30 and x > TOP],
            [x for z0, z1, x in along if (z0, z1) == (-10, -20) and x < TOP - 1e-9])


@pytest.mark.parametrize("code, roughs, cuts_pocket", [("G71", True, True), ("G71.1", True, False),
                                                      ("G71.2", False, True)])
def test_type_1_leaves_the_pocket_and_type_2_cuts_only_it(code, roughs, cuts_pocket):
    """adoc: "The G7x.1 cycles do not cut pockets. The G7x.2 cycles only cut after the first pocket";
    cc 743-750 (type 2 skips the first roughing), 756-761 (type 1 follows the profile, climb_only)."""
    over, pocket = levels(code)
    above = [START_X - n * DEPTH for n in range(10) if START_X - n * DEPTH > TOP + 1e-9]           # 20, 18
    inside = [START_X - n * DEPTH for n in range(10) if FLOOR < START_X - n * DEPTH < TOP - 1e-9] + [FLOOR]  # 14 12 10
    assert over == (above if roughs else [])
    assert pocket == (inside if cuts_pocket else [])
