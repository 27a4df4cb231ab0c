"""Adversarial programs against the collision claim of 86be530: no program the simulation accepts
brings the hob more than 0.002 mm (contact_records.COLLISION_TOLERANCE) into the fixture, the
tailstock or a unit outside its cut. The simulation measures the hob's least distance from the
work axis at the solid's heights (0.5 mm apart) and allows step²/(8·r0) between two of them.

Each test writes a program a hand could write (tests/helpers/simulation_programs.Hand, plus a few
rapids), lets the simulation follow it, and measures the true depth independently: the hob's
surface (its tip cylinder's mantle and both end faces, swivelled by A about X, Y along its own
axis, reference §A6) sampled in the DIN frame, the grid refined around its deepest point down to
well under 1e-4 mm. Every sampled point is a point of the hob, so the sampled depth is a lower
bound of the true one: a program the simulation accepts is wrong if that bound is above 0.002 mm."""
from __future__ import annotations

import functools
import math

import pytest
from helpers.collision_truth import ALLOWED, PATHS, after_coupling, messages, seeded_records, true_depth
from helpers.simulation_programs import LOAD, RAPID_RATE, Hand, program_minutes, swivel
from msgspec.structs import replace

from engine.simulation import simulate_program
from engine.simulation.hobbing import contact

ALONG = 0.002   # mm of a move the search for its deepest pose narrows down to


@pytest.fixture
def records(conn):
    return seeded_records(conn)


@PATHS
def test_the_hob_end_beside_the_fixture_dips_between_two_heights(records, monkeypatch, sections):
    """The reference spur program (gear 42, hob H-M2-AA-R1: d_a0 70, L 100, A = γ = 1.763°) on
    the seeded machine (fixture Ø20 right under the bottom face), then a rapid that parks the
    hob beside the fixture, 80 mm below the work: X20 (the G25 limit), shifted Y60.885 so its
    end face stands 10 mm off the work axis in Y. The hob's nearest point to the axis is then on
    the edge of that end face, where the edge's circle crosses the X = 0 plane at a slope
    dx/dz = √(r0² − X²)/X ≈ 1.44: the least distance from the axis goes as
    √(f₀² + (1.44·δz)²) ≈ f₀ + 1.04·δz²/f₀, a curvature of about 0.2/mm against the 1/r0 =
    0.029/mm the threshold allows for. At the fixture's heights (multiples of 0.5 mm) the hob
    is at most 0.0009 mm inside (below the 0.0011 mm threshold for r0 35); between two of them
    it is 0.006 mm inside, 50 mm below the fixture's top face."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"])
    machine = records["machine"]
    assert (machine.fixture_diameter, machine.fixture_gap) == (20.0, 0.0)
    park = (20.0, 60.885, -99.948)
    extra = [f"G0 Z{park[2]:.3f}", f"G0 Y{park[1]:.3f}", f"G0 X{park[0]:.3f}",
             f"G0 X{spur.x_retract:.3f}", "G0 Y0.000"]
    report = simulate_program(after_coupling(spur, extra), spur.gear, spur.hob, machine, "TEST")
    a_written = round(swivel(spur.gear, spur.hob), 3)
    depth = true_depth(35.0, 100.0, a_written, park, 10.0, -math.inf, -spur.gear.face_width)
    assert depth == pytest.approx(0.0061, abs=0.0002)
    assert any("into the fixture" in m for m in messages(report)), (depth, messages(report))


@PATHS
def test_a_small_hob_dips_between_two_heights_by_more_than_its_threshold_allows(records, monkeypatch, sections):
    """For r0 < 0.5²/(8·0.002) = 15.6 mm the sampling can hide more than COLLISION_TOLERANCE, and
    the threshold is held at 0 rather than below it: an r0 10 hob's tip circle between two of
    the fixture's heights (0.25 mm from each) is r0 − √(r0² − 0.25²) = 0.0031 mm deeper than at
    them (cos²A of that for a swivelled one). The reference spur program with a Ø20 hob
    (A = γ = asin(2/15) = 7.662°) on a Ø29.9999 fixture (its run-out tip at d_f/2 = 16.5 mm
    clears it); then a rapid to Z −60.25 (midway between the fixture's heights, multiples of
    0.5 mm) and in to X24.997: at the heights the tip stays outside (by 4e-5 mm), at the
    centre's height it is 14.99995 − (24.997 − 10) = 0.00295 mm in."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    hob = replace(records["hobs"]["H-M2-AA-R1"], tip_diameter=20.0)
    spur = Hand(records["gear"](42), hob)
    machine = replace(records["machine"], fixture_diameter=29.9999, fixture_gap=0.0)
    a_written = round(swivel(spur.gear, spur.hob), 3)
    park = (24.997, 0.0, -60.25)
    extra = [f"G0 Z{park[2]:.3f}", f"G0 X{park[0]:.3f}", f"G0 X{spur.x_retract:.3f}"]
    report = simulate_program(after_coupling(spur, extra), spur.gear, spur.hob, machine, "TEST")
    depth = true_depth(10.0, 100.0, a_written, park, machine.fixture_diameter / 2, -math.inf, -spur.gear.face_width)
    assert depth == pytest.approx(machine.fixture_diameter / 2 - (park[0] - 10.0), abs=1e-6)   # the tip, X − r0
    assert depth > ALLOWED
    assert any("into the fixture" in m for m in messages(report)), (depth, messages(report))



@functools.cache   # the same truth for both paths of the contacts
def deepest_along(r0, length, swivel_deg, start, end, radius, z_low, z_high) -> float:
    """true_depth at the deepest pose of a straight move from start to end (X, Y, Z): the depth
    along a straight move of a convex hob against a convex solid has one peak, so a golden-section
    search on the share of the move, to ALONG mm of the move, then the depth there (near the peak
    the depth is flat: ALONG mm off the peak it differs by (ALONG/2)²/(2·radius), 1e-7 mm here)."""
    def at(share: float) -> float:
        pose = tuple(a + share * (b - a) for a, b in zip(start, end))
        return true_depth(r0, length, swivel_deg, pose, radius, z_low, z_high)
    shrink = (math.sqrt(5) - 1) / 2
    low, high = 0.0, 1.0
    one, two = high - shrink, low + shrink
    depth_one, depth_two = at(one), at(two)
    while (high - low) * math.dist(start, end) > ALONG:
        if depth_one >= depth_two:
            high, two, depth_two = two, one, depth_one
            one = high - shrink * (high - low)
            depth_one = at(one)
        else:
            low, one, depth_one = one, two, depth_two
            two = low + shrink * (high - low)
            depth_two = at(two)
    return at((low + high) / 2)


@pytest.mark.slow   # a golden-section truth over random moves: 0.6 s a set
@PATHS
def test_a_move_past_the_fixture_dips_between_two_poses(records, monkeypatch, sections):
    """The poses along a move lie at most 0.5 mm apart (paths.POSE_STEP) and nothing is allowed
    for the hob coming nearer between two of them. The reference spur program, then at Z −99.948
    (80 mm below the work, beside the Ø20 fixture) a G1 diagonally in X and Y, ΔX = −ΔY = 28.28
    (81 poses, 0.5 mm apart): the hob's near end corner (X − r0, Y·cos A − L/2 in the XY plane)
    passes the work axis at 10 mm in a straight line, its distance √(d² + s²) bending at 1/d =
    0.1/mm, so between two poses it comes 0.5²/(8·10) = 0.003 mm nearer than at them. At the
    poses the hob is at most 0.0005 mm inside the fixture; between them 0.0036 mm."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"])
    machine = records["machine"]
    z, start, end = -99.948, (28.089, 71.068), (56.369, 42.788)
    extra = [f"G0 Z{z:.3f}", f"G0 Y{start[1]:.3f}", f"G0 X{start[0]:.3f}",
             f"G1 X{end[0]:.3f} Y{end[1]:.3f} F1000.0", f"G0 X{spur.x_retract:.3f}", "G0 Y0.000"]
    report = simulate_program(after_coupling(spur, extra), spur.gear, spur.hob, machine, "TEST")
    a_written = round(swivel(spur.gear, spur.hob), 3)
    depth = deepest_along(35.0, 100.0, a_written, (*start, z), (*end, z), 10.0, -math.inf, -spur.gear.face_width)
    assert depth == pytest.approx(0.0036, abs=0.0002)
    assert any("into the fixture" in m for m in messages(report)), (depth, messages(report))


@PATHS
def test_the_hob_end_beside_the_tailstock_dips_between_two_heights(records, monkeypatch, sections):
    """The first test's geometry above the work: the seeded Ø20 tailstock (clamped by M20 from the
    top face, Z 0, up; its heights multiples of 0.5 mm), the hob parked at X20 Y60.885 Z100.078
    before M21. At the tailstock's heights the hob is 0.0001 mm inside it; 30 mm above their
    centre and 100 mm above the top face, between two of them, 0.0061 mm."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"])
    machine = records["machine"]
    assert (machine.tailstock_diameter, machine.tailstock_gap) == (20.0, 0.0)
    park = (20.0, 60.885, 100.078)
    extra = [f"G0 Z{park[2]:.3f}", f"G0 Y{park[1]:.3f}", f"G0 X{park[0]:.3f}",
             f"G0 X{spur.x_retract:.3f}", "G0 Y0.000"]
    lines = after_coupling(spur, extra)
    assert lines.index("M20") < lines.index(extra[2]) < lines.index("M21")
    report = simulate_program(lines, spur.gear, spur.hob, machine, "TEST")
    a_written = round(swivel(spur.gear, spur.hob), 3)
    depth = true_depth(35.0, 100.0, a_written, park, 10.0, 0.0, math.inf)
    assert depth == pytest.approx(0.0061, abs=0.0002)
    assert any("into the tailstock" in m for m in messages(report)), (depth, messages(report))


@pytest.mark.parametrize(("park", "solid"), [((20.0, 60.880, -99.948), "the fixture"),
                                             ((20.0, 60.880, 100.078), "the tailstock")])
def test_the_same_park_5_micrometres_nearer_is_refused(records, park, solid):
    """The control of the end-face tests: the same rapids with Y 0.005 mm less put the hob about
    0.005 mm inside at the solid's own heights too (the end face moves 0.005·cos A toward the
    axis), and the simulation names the solid, so what those tests ask of it can be had."""
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"])
    extra = [f"G0 Z{park[2]:.3f}", f"G0 Y{park[1]:.3f}", f"G0 X{park[0]:.3f}",
             f"G0 X{spur.x_retract:.3f}", "G0 Y0.000"]
    lines = after_coupling(spur, extra)
    report = simulate_program(lines, spur.gear, spur.hob, records["machine"], "TEST")
    found = [f.message for f in report.refusals if f.number == lines.index(extra[2]) + 1]
    assert any(f"into {solid}" in m for m in found), messages(report)


def duplex_program(gear, hob, extra: list[str]) -> list[str]:
    """Gear 54 (unit 1: z30, d_a 64, d_f 55, Z 0 … −20; unit 2: z19, d_a 42, d_f 33, Z −75 … −90)
    hobbed by one spur hob in two couplings (§A5, §B3: full depth a = (d_f + d_a0)/2; §B7's run-in,
    3 mm run-out; the feeds per table revolution of the Hand's z19 program), then `extra` after
    the spindle stops, before M21."""
    unit = gear.units[0]
    a_value = round(swivel(gear, hob), 3)
    lines = ["%_N_TEST_MPF", ";$PATH=/_N_MPF_DIR", "G90 G71 G94", "G25 X20.000 Y-80.000 Z-350.000",
             "G26 X320.000 Y80.000 Z150.000", "WALIMON", "M20"]
    for teeth, tip, root, top, width in [(gear.teeth, gear.tip_diameter, gear.root_diameter, 0.0, gear.face_width),
                                          (unit.teeth, unit.tip_diameter, unit.root_diameter, unit.z_top,
                                           unit.face_width)]:
        retract = (tip + hob.tip_diameter) / 2 + 5.0
        h = (tip - root) / 2
        lean = math.tan(math.radians(a_value)) * math.sqrt(h * (tip - h))
        run_in = math.sqrt(h * (hob.tip_diameter - h)) + 2.0 + lean
        lines += [f"G0 Z{top + run_in:.3f}", f"G0 X{retract:.3f}", f"G0 A={a_value:.3f}", "G0 Y0.000", "EGDEF(C,B,1)",
                  f'EGON(C,"FINE",B,-1,{teeth})', "M3 S246",
                  f"G1 X{(root + hob.tip_diameter) / 2:.3f} F{36.0 * 19 / teeth:.1f}",
                  f"G1 Z{top - width - 3.0:.3f} F{38.0 * 19 / teeth:.1f}",
                  f"G0 X{retract:.3f}", "EGOFS(C)", "EGDEL(C)"]
    lines += ["M5", *extra, "M21", "M30"]
    return lines[:2] + [f"; CYCLE TIME {program_minutes(lines, RAPID_RATE, LOAD):.1f} MIN"] + lines[2:]


@PATHS
def test_the_hob_end_beside_the_other_unit_dips_between_two_heights(records, monkeypatch, sections):
    """The end-face dip against a neighbouring unit: the duplex gear 54 hobbed whole, then the hob
    parked at X20 Y71.895 Z−109.928, its end face beside unit 2 (Ø42, Z −75 … −90, finished
    work) 5 mm below its top face. At the unit's heights (0.5 mm apart) it is 0.0003 mm inside
    the tip cylinder; between two of them 0.0037 mm."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    gear, hob = records["gear"](54), records["hobs"]["H-M2-AA-R1"]
    assert not simulate_program(duplex_program(gear, hob, []), gear, hob, records["machine"], "TEST").refused
    park = (20.0, 71.895, -109.928)
    retract = (gear.tip_diameter + hob.tip_diameter) / 2 + 5.0
    extra = [f"G0 X{retract:.3f}", f"G0 Z{park[2]:.3f}", f"G0 Y{park[1]:.3f}", f"G0 X{park[0]:.3f}",
             f"G0 X{retract:.3f}", "G0 Y0.000"]
    report = simulate_program(duplex_program(gear, hob, extra), gear, hob, records["machine"], "TEST")
    unit = gear.units[0]
    depth = true_depth(35.0, 100.0, round(swivel(gear, hob), 3), park, unit.tip_diameter / 2,
                       unit.z_top - unit.face_width, unit.z_top)
    assert depth == pytest.approx(0.0037, abs=0.0002)
    assert any("into unit 2" in m for m in messages(report)), (depth, messages(report))


def test_the_duplex_park_5_micrometres_nearer_is_refused(records):
    """The control of the other-unit test: Y 0.005 mm less, and unit 2 is named."""
    gear, hob = records["gear"](54), records["hobs"]["H-M2-AA-R1"]
    retract = (gear.tip_diameter + hob.tip_diameter) / 2 + 5.0
    extra = [f"G0 X{retract:.3f}", "G0 Z-109.928", "G0 Y71.890", "G0 X20.000", f"G0 X{retract:.3f}", "G0 Y0.000"]
    report = simulate_program(duplex_program(gear, hob, extra), gear, hob, records["machine"], "TEST")
    assert any("into unit 2" in f.message and f.line == "G0 X20.000" for f in report.refusals), messages(report)
