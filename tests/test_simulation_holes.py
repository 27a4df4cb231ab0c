"""Wrong hobbing programs the simulation used to let through (issue 14's adversary), each
hand-written for gear 43 (helical m3 z41 β15 R) and hob H-M3-AA-R1 (R, Ø80, L120) in the style
of tests/helpers/simulation_programs.py, with every expected number from the reference
(docs/reference/hobbing.md §B8, §B15, §C): each is refused on the line that makes it."""
from __future__ import annotations

import math
from dataclasses import replace as replace_hand  # Hand, the tests' own dataclass

import pytest
from helpers.simulation_programs import Hand, k_z, least_run_out, number_of, swivel
from msgspec.structs import replace

from engine.gears.records import GearUnit, load_gear, load_hobs
from engine.machines.records import load_machine
from engine.simulation import simulate_program

MACHINE = "hobber-840d"
SPEED = 338.0                  # n0 of gear 43's seeded program: table n0·z0/z2 = 8.244 r/min (§B4)
ROUGH_MAX_M3 = 3.5             # §C: roughing f_a at m3, mm per workpiece revolution
# One pass at 3.0 mm/rev leaves feed marks f_a²·sin α_n/(4·d_a0) ≈ 9.6 µm (§B6): within the share of
# the helix form tolerance a grade-9 gear 43 allows, not the seeded grade 7's. Read as grade 9 so
# these tests prove what they are about; the feed marks have their own (tests/test_feed_marks.py).
COARSE_GRADE = 9


@pytest.fixture
def records(conn):
    return {"machine": load_machine(conn, MACHINE), "gear": replace(load_gear(conn, 43), quality_grade=COARSE_GRADE),
            "hob": {hob.id: hob for hob in load_hobs(conn)}["H-M3-AA-R1"]}


@pytest.fixture
def helical(records):
    """A right program for gear 43: a climb pass at 24.7 mm/min (3.0 mm/rev, within §C)."""
    return Hand(records["gear"], records["hob"], speed=SPEED, axial_feed=24.7, radial_feed=8.2)


def refusals(lines, helical, machine, hob=None) -> dict:
    """line number -> the messages refusing it."""
    report = simulate_program(lines, helical.gear, hob or helical.hob, machine, "TEST")
    found: dict = {}
    for finding in report.refusals:
        found.setdefault(finding.number, []).append(finding.message)
    return found


def generating_length(module: float, pressure_angle: float) -> float:
    """§B15: L_gen = 2·h/tan α_n + π·m_n, h = 2.25·m_n."""
    return 2 * 2.25 * module / math.tan(math.radians(pressure_angle)) + math.pi * module


def test_the_right_program_for_gear_43_is_clean(records, helical):
    assert not refusals(helical.lines(), helical, records["machine"])


# 1 --------------------------------------------------------------------------------------------

def test_a_hob_shift_while_coupled_is_refused_unless_y_leads(records, helical):
    """§B15: a 5 mm shift at m3 moves the thread 5/(π·3) = 0.53 of a pitch along the teeth while
    the table keeps its phase: the rest of the pass cuts beside the gaps already cut."""
    assert 5 / (math.pi * 3) == pytest.approx(0.53, abs=0.005)
    cut = helical.cut()
    lines = helical.lines(cut[:1] + ["G1 Y5.000 F100.0"] + cut[1:])
    found = refusals(lines, helical, records["machine"])
    assert any("hob shift Y moves while the table is coupled" in m for m in found[number_of(lines, "G1 Y5.000 F100.0")])
    standing = helical.lines(cut[:1] + ["G0 Y0.000"] + cut[1:])      # written where it stands: no motion
    assert not refusals(standing, helical, records["machine"])


# 2 --------------------------------------------------------------------------------------------

def test_a_swivel_while_coupled_is_refused(records, helical):
    lines = helical.lines(helical.cut() + ["G0 A=0.000"])
    found = refusals(lines, helical, records["machine"])
    assert any("swivel A moves while the table is coupled" in m for m in found[number_of(lines, "G0 A=0.000")])


# 3 --------------------------------------------------------------------------------------------

def coupling(helical) -> list[str]:
    return ["EGDEF(C,B,1,Z,1)", f'EGON(C,"FINE",B,-1,{helical.gear.teeth},Z,{k_z(helical.gear, 41):.6f},1)']


def test_re_coupling_between_rough_and_finish_of_one_unit_is_refused(records, helical):
    """EGON "FINE" does not synchronise: after EGOFS/EGDEL and a new EGON the finish cut lands at
    an arbitrary phase against the rough gaps."""
    rough = replace_hand(helical, stock=0.5)
    finish = [f"G0 Z{helical.z_start:.3f}", *helical.cut()]
    lines = helical.lines(rough.cut() + ["EGOFS(C)", "EGDEL(C)", *coupling(helical), *finish])
    found = refusals(lines, helical, records["machine"])
    finish_pass = len(lines) - lines[::-1].index(helical.cut()[1])     # the infeed stops above the blank (§B7)
    assert any("which an earlier coupling already cut" in m for m in found[finish_pass])
    one_coupling = helical.lines(rough.cut() + finish)
    assert not refusals(one_coupling, helical, records["machine"])


def test_a_duplex_re_coupling_for_its_other_unit_of_the_same_teeth_is_allowed(records, helical):
    """Unit 2 has 41 teeth too and lies 150 mm below unit 1: its own coupling cuts only its own
    material, which no coupling cut before."""
    width = helical.gear.face_width
    top = -width - 150.0
    gear = replace(helical.gear, units=(GearUnit(2, 41, width, helical.gear.tip_diameter,
                                                 helical.gear.root_diameter, top),))
    second = replace_hand(helical, gear=gear)
    z_run_out = helical.z_end + width           # the pass's end below the unit's bottom face
    unit_2 = [f"G0 Z{top + helical.z_start:.3f}", f"G1 X{helical.x_cut:.3f} F8.2",
              f"G1 Z{top - width + z_run_out:.3f} F24.7", f"G0 X{helical.x_retract:.3f}"]
    lines = second.lines(helical.cut() + ["EGOFS(C)", "EGDEL(C)", *coupling(helical), *unit_2])
    assert not refusals(lines, second, records["machine"])


# 4 --------------------------------------------------------------------------------------------

def test_a_shift_that_puts_the_generating_zone_off_the_hob_is_refused(records, helical):
    """|Y| + L_gen/2 ≤ L/2: at m3 α 20° L_gen = 46.5 mm, so the 120 mm hob shifts at most 36.7 mm."""
    most = (helical.hob.length - generating_length(3.0, 20.0)) / 2
    assert most == pytest.approx(36.74, abs=0.01)
    machine = records["machine"]
    for shift, refused in ((most - 0.01, False), (most + 0.01, True), (-most - 0.01, True), (50.0, True)):
        lines = [line.replace("G0 Y0.000", f"G0 Y{shift:.3f}") for line in helical.lines()]
        found = refusals(lines, helical, machine)
        zone = any("generating zone" in m for m in found.get(number_of(lines, helical.cut()[0]), []))
        assert zone == refused, shift


def test_a_hob_shorter_than_the_generating_zone_is_refused(records, helical):
    short = replace(helical.hob, length=40.0)               # < L_gen 46.5
    lines = helical.lines()
    found = refusals(lines, helical, records["machine"], short)
    assert any("generating zone" in m for m in found[number_of(lines, helical.cut()[0])])


def test_a_shift_per_part_interval_whose_end_leaves_the_hob_is_refused(records, helical):
    lines = helical.lines()
    at = lines.index("G0 Y0.000")
    lines = lines[:at] + ["R11=R11+0.500", "IF (R11<-10.000) OR (R11>40.000)", "R11=-10.000", "ENDIF",
                          "G0 Y=R11"] + lines[at + 1:]
    found = refusals(lines, helical, records["machine"])
    assert any("generating zone" in m and "Y40" in m for m in found[number_of(lines, helical.cut()[0])])


# 5 --------------------------------------------------------------------------------------------

HEADERS = ("; GEAR 43 CLASS helical m=3 z=41 beta=15", "; HOB H-M3-AA-R1 z0=1 da0=80 hand=R", "; MACHINE hobber-840d")


def with_records(helical, headers=HEADERS, offset="G54", tool="T1 D1") -> list[str]:
    lines = helical.lines()
    at = lines.index("G90 G71 G94")
    return lines[:at] + list(headers) + [lines[at], offset] + lines[at + 1:at + 4] + [tool] + lines[at + 4:]


@pytest.mark.parametrize("edit, wanted", [
    ({"offset": "G55"}, "work offset G55"), ({"tool": "T2 D1"}, "tool T2"),
    ({"headers": ("; GEAR 42 CLASS spur",) + HEADERS[1:]}, "gear 42"),
    ({"headers": (HEADERS[0], "; HOB H-M2-AA-R1 z0=1 da0=70 hand=R", HEADERS[2])}, "hob H-M2-AA-R1"),
    ({"headers": (HEADERS[0], "; HOB H-M3-AA-R1 z0=1 da0=80 hand=L", HEADERS[2])}, "hand L"),
    ({"headers": HEADERS[:2] + ("; MACHINE hobber-other",)}, "machine hobber-other")])
def test_a_program_naming_or_selecting_other_records_is_refused(records, helical, edit, wanted):
    assert not refusals(with_records(helical), helical, records["machine"])
    lines = with_records(helical, **edit)
    changed = next(line for line in lines if line not in with_records(helical))
    found = refusals(lines, helical, records["machine"])
    assert any(wanted in m for m in found[number_of(lines, changed)]), found


# 6 --------------------------------------------------------------------------------------------

def test_a_pass_feed_above_the_roughing_maximum_is_refused_and_one_at_it_is_not(records, helical):
    """F247 at n2 = 338/41 r/min is 30 mm per workpiece revolution, 8.6× §C's 3.5 at m3."""
    table = SPEED / 41
    assert 247 / table == pytest.approx(29.96, abs=0.01)
    at_bound = math.floor(ROUGH_MAX_M3 * table * 10) / 10        # written at or below the bound
    for feed, refused in ((247.0, True), (at_bound, False), (at_bound + 0.2, True)):
        program = replace_hand(helical, axial_feed=feed)
        found = refusals(program.lines(), helical, records["machine"])
        feeds = any("roughing maximum" in m for m in found.get(number_of(program.lines(), program.cut()[1]), []))
        assert feeds == refused, feed


# 7 --------------------------------------------------------------------------------------------

def test_a_run_out_short_of_the_generating_zone_is_refused(records, helical):
    """§B8: the zone reaches (h/tan α_n)·sin|η| = 18.55·sin 12.63° = 4.05 mm past the centre."""
    least = least_run_out(helical.gear, helical.hob)
    assert abs(swivel(helical.gear, helical.hob)) == pytest.approx(12.628, abs=0.001)
    assert least == pytest.approx(4.054, abs=0.001)
    for run_out, refused in ((0.1, True), (least - 0.01, True), (least + 0.01, False)):
        program = replace_hand(helical, run_out=run_out)
        found = refusals(program.lines(), helical, records["machine"])
        short = any("beyond the face" in m for m in found.get(number_of(program.lines(), program.cut()[0]), []))
        assert short == refused, run_out


# 8 --------------------------------------------------------------------------------------------

def test_a_machine_part_too_big_for_the_gear_says_what_to_do(records, helical):
    root = helical.gear.root_diameter
    tailstock = replace(records["machine"], tailstock_diameter=root + 10, tailstock_gap=0.0)
    found = refusals(helical.lines(), helical, tailstock)
    messages = [m for ms in found.values() for m in ms if "into the tailstock" in m]
    assert messages and all("--no-tailstock" in m and "smaller tailstock/fixture" in m for m in messages)
    fixture = replace(records["machine"], fixture_diameter=root + 10, fixture_gap=0.0)
    found = refusals(helical.lines(), helical, fixture)
    messages = [m for ms in found.values() for m in ms if "into the fixture" in m]
    assert messages and all("smaller fixture" in m for m in messages)


# second review ---------------------------------------------------------------------------------

def split_pass(helical, *between: str) -> list[str]:
    """The axial pass cut in two at Z-15 with `between` written in the cut."""
    x_cut, z_cut, retract = helical.cut()
    return helical.lines([x_cut, "G1 Z-15.000 F24.7", *between, z_cut, retract])


@pytest.mark.parametrize("change", ["S100", "M3 S100"])
def test_a_spindle_speed_change_in_the_cut_counts_for_the_feed(records, helical, change):
    """§C: at S100 the table turns 100·1/41 r/min, so 24.7 mm/min is 10.1 mm per workpiece revolution."""
    feed = 24.7 / (100 * helical.hob.starts / helical.gear.teeth)
    assert feed > ROUGH_MAX_M3
    lines = split_pass(helical, change)
    found = refusals(lines, helical, records["machine"])
    assert any(f"{feed:.3f} mm per workpiece revolution" in m for m in found[number_of(lines, change) + 1])
    assert not refusals(split_pass(helical, f"S{SPEED:g}"), helical, records["machine"])


def test_spos_in_the_cut_stops_the_spindle(records, helical):
    lines = split_pass(helical, "SPOS=0")
    found = refusals(lines, helical, records["machine"])
    assert any("spindle stopped" in m for m in found[number_of(lines, "SPOS=0") + 1])


@pytest.mark.parametrize("word", ["D0", "D1", "T1 D1"])
def test_a_tool_or_offset_word_in_the_coupling_is_refused(records, helical, word):
    lines = split_pass(helical, word)
    found = refusals(lines, helical, records["machine"])
    assert any("while the table is coupled" in m for m in found[number_of(lines, word)])


def test_an_offset_other_than_d1_is_refused(records, helical):
    lines = helical.lines()
    lines.insert(number_of(lines, "WALIMON"), "T1 D2")
    found = refusals(lines, helical, records["machine"])
    assert any("tool offset D2" in m for m in found[number_of(lines, "T1 D2")])
    lines[number_of(lines, "T1 D2") - 1] = "T1 D1"
    assert not refusals(lines, helical, records["machine"])


def with_comment(helical, comment: str, at: str = "G90 G71 G94") -> list[str]:
    lines = helical.lines()
    lines.insert(number_of(lines, at) - 1, comment)
    return lines


@pytest.mark.parametrize("comment", ["; gear 44 CLASS helical", "; GEAR44 CLASS helical", "; GEAR=44",
                                     "; hob H-M3-A-L1", "; machine lathe-840d", "; cycle time 0.5 min",
                                     "; CYCLE TIME 30 S", "; Allowance 0.3 mm"])
def test_a_header_fact_not_in_its_canonical_form_is_refused(records, helical, comment):
    lines = with_comment(helical, comment)
    found = refusals(lines, helical, records["machine"])
    assert any("canonical" in m for m in found[number_of(lines, comment)])


def test_a_header_fact_in_a_trailing_comment_is_refused(records, helical):
    lines = helical.lines()
    at = number_of(lines, "G0 Y0.000")
    lines[at - 1] = "G0 Y0.000 ; GEAR 44"
    assert any("canonical" in m for m in refusals(lines, helical, records["machine"])[at])


@pytest.mark.parametrize("comment", ["; TEMPLATE helical v1", "; CUT SINGLE X=99.919 CLIMB", "; TAILSTOCK CLAMP",
                                     "; n0=338 r/min table=8.244 r/min cuts=1 climb", "; GEAR 43 CLASS helical",
                                     "; HOB H-M3-AA-R1 z0=1 da0=80 hand=R", "; MACHINE hobber-840d"])
def test_the_templates_other_comments_and_right_headers_are_accepted(records, helical, comment):
    assert not refusals(with_comment(helical, comment), helical, records["machine"])


def test_the_allowance_is_stated_once_before_the_first_motion(records, helical):
    stated = "; ALLOWANCE 0.000 MM LEFT FOR FINISHING"
    assert not refusals(with_comment(helical, stated), helical, records["machine"])
    twice = with_comment(helical, stated)
    twice.insert(number_of(twice, "G90 G71 G94") - 1, "; ALLOWANCE 0.000 MM")
    found = refusals(twice, helical, records["machine"])
    assert any("second" in m for m in found[number_of(twice, "; ALLOWANCE 0.000 MM")])
    late = with_comment(helical, stated, at="G0 Y0.000")
    found = refusals(late, helical, records["machine"])
    assert any("after the first motion" in m for m in found[number_of(late, stated)])


def test_a_program_without_its_cycle_time_header_is_refused(records, helical):
    helical.header = None
    lines = helical.lines()
    assert any("no `; CYCLE TIME" in m for m in refusals(lines, helical, records["machine"])[len(lines)])


def test_a_radial_infeed_above_the_roughing_maximum_is_refused(records, helical):
    """§C bounds the infeed too: 40 mm/min at a table of 338·1/41 r/min is 4.852 mm/rev > 3.5."""
    table = SPEED * helical.hob.starts / helical.gear.teeth
    feed = 40.0 / table
    assert feed > ROUGH_MAX_M3
    helical.radial_feed = 40.0
    lines = helical.lines()
    infeed = number_of(lines, f"G1 X{helical.x_cut:.3f} F40.0")
    assert any(f"radial infeed feeds {feed:.3f} mm" in m for m in refusals(lines, helical, records["machine"])[infeed])
    helical.radial_feed = 0.999 * ROUGH_MAX_M3 * table
    assert not refusals(helical.lines(), helical, records["machine"])
