"""Adversarial programs against the collision claim of 615bfc9 (issue 28): no program the
simulation accepts brings the hob more than 0.002 mm (contact_records.COLLISION_TOLERANCE) into
the fixture, the tailstock, a unit outside its cut, or material in a rapid, now that the depth
between the sampled heights and poses is bounded by convexity and searched exactly.

The true depths are worked out here, never by the engine's geometry: test_collision_adversary's
sampled hob surface (every sampled point is a point of the hob, so the sampled depth is a lower
bound of the true one) with its grid refined around the deepest point. (The same adversary's
other findings, still open, are in the issue notes: a coupled rapid may plunge 0.01 mm into its
own gaps; short blocks near a fixture cost an exact search each.)"""
from __future__ import annotations

import math

import pytest
from helpers.collision_truth import PATHS, after_coupling, messages, seeded_records, true_depth
from helpers.simulation_programs import Hand, swivel

from engine.simulation import simulate_program
from engine.simulation.hobbing import contact


@pytest.fixture
def records(conn):
    return seeded_records(conn)


@PATHS
@pytest.mark.parametrize(("a_value", "park", "expected"), [(181.763, (24.0, 65.0, 34.0), 0.333),
                                                           (210.0, (48.0, 70.0, 22.0), 1.750)],
                         ids=["A181.763", "A210"])
def test_a_hob_swivelled_past_90_degrees_is_shifted_the_wrong_way(records, monkeypatch, sections, a_value, park,
                                                                  expected):
    """A cylinder turned by 180° is the same cylinder (walk._contacts takes A modulo 180°), but the
    shift Y rides on the swivel head (reference §A6: the hob centre is (X, Y·cos A, Z + Y·sin A)),
    so the head turned half a turn carries the hob the other way along its axis: the simulation
    puts the centre at (X, Y·cos A′, Z + Y·sin A′) with A′ = A − 180°, mirrored through the
    swivel's pivot. The reference spur program (gear 42: Ø42 over Z 0 … −20), then with the
    spindle stopped: up to Z150, A turned to 181.763° (the reference swivel and half a turn) or
    210°, shifted Y65/Y70, down and in to a park the simulation sees clear of the work (its centre
    2·Y·sin A′ too high and mirrored in Y), its tip cylinder 0.33 mm (1.75 mm) inside
    the finished gear: accepted."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"])
    gear = spur.gear
    a_written = round(swivel(gear, spur.hob), 3)
    x, y, z = park
    extra = ["G0 Z150.000", f"G0 A={a_value:.3f}", f"G0 Y{y:.3f}", f"G0 Z{z:.3f}", f"G0 X{x:.3f}",
             f"G0 X{spur.x_retract:.3f}", "G0 Z150.000", "G0 Y0.000", f"G0 A={a_written:.3f}"]
    report = simulate_program(after_coupling(spur, extra), gear, spur.hob, records["machine"], "TEST")
    depth = true_depth(35.0, 100.0, a_value, park, gear.tip_diameter / 2, -gear.face_width, 0.0)
    assert depth == pytest.approx(expected, abs=0.002)
    assert any("into unit 1" in m for m in messages(report)), (depth, messages(report))


@PATHS
def test_a_rapid_that_also_swivels_the_hob_dips_between_two_heights(records, monkeypatch, sections):
    """A move that changes A is checked at its sampled heights and poses only (contact_records.exact:
    not a translation). test_collision_adversary's first park (X20 Y60.885 Z−99.948 beside the Ø20
    fixture, the end face's rim dipping 0.006 mm into it between two of its heights) reached by a
    G0 X20 that also writes A one thousandth of a degree on (1.763° → 1.764°, the finest the
    program's three decimals can write), and left by a G0 X that writes A back: the hob stands at
    A = 1.764° where the true depth is 0.0066 mm, and the program is accepted (a later move that
    does not swivel, starting at the park, would find it exactly). Now refused: a move that swivels
    is proved only where the hob clears the work in X or in Z (engine.simulation.hobbing.swivel_sweep)."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"])
    machine = records["machine"]
    a_written = round(swivel(spur.gear, spur.hob), 3)
    a_new = a_written + 0.001
    park = (20.0, 60.885, -99.948)
    extra = [f"G0 Z{park[2]:.3f}", f"G0 Y{park[1]:.3f}", f"G0 X{park[0]:.3f} A={a_new:.3f}",
             f"G0 X{spur.x_retract:.3f} A={a_written:.3f}", "G0 Y0.000"]
    report = simulate_program(after_coupling(spur, extra), spur.gear, spur.hob, machine, "TEST")
    depth = true_depth(35.0, 100.0, a_new, park, 10.0, -math.inf, -spur.gear.face_width)
    assert depth == pytest.approx(0.0066, abs=0.0002)
    assert any("into the fixture" in m or ("swivels" in m and "the fixture" in m) for m in messages(report)), \
        (depth, messages(report))


@PATHS
def test_a_swivel_alone_sweeps_the_hob_through_the_gear(records, monkeypatch, sections):
    """A block that turns A alone is followed at its new A only (walk._contacts: the move's one
    pose, the hob standing still), but the head turns through every A between, and with a shift
    Y the hob centre swings on an arc about the pivot (reference §A6: (X, Y·cos A, Z + Y·sin A)).
    The reference spur program without the tailstock (gear 42: Ø42 over Z 0 … −20), then with
    the spindle stopped: up to Z36, Y20, in to X40 (the hob just above the top face at
    A = 1.763°), and G0 A=80: at 80° the hob stands above the face again, but on the way, at
    A = 40°, its centre is at Z 36 + 20·sin 40° = 48.9 and it reaches 35·cos 40° + 50·sin 40° =
    58.9 mm below that, to Z −10.1, its points there within the gear's Ø42: 3.2 mm deep (the
    lesser of the radial and the axial depth), and the program is accepted."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"], tailstock=False)
    gear = spur.gear
    a_written = round(swivel(gear, spur.hob), 3)
    park = (40.0, 20.0, 36.0)
    extra = [f"G0 Z{park[2]:.3f}", f"G0 Y{park[1]:.3f}", f"G0 X{park[0]:.3f}", "G0 A=80.000",
             f"G0 X{spur.x_retract:.3f}", f"G0 A={a_written:.3f}", "G0 Y0.000"]
    report = simulate_program(after_coupling(spur, extra), gear, spur.hob, records["machine"], "TEST")
    radius = gear.tip_diameter / 2
    at_ends = [true_depth(35.0, 100.0, a, park, radius, -gear.face_width, 0.0) for a in (a_written, 80.0)]
    assert max(at_ends) < 0.0          # clear where it starts and where it ends
    depth = true_depth(35.0, 100.0, 40.0, park, radius, -gear.face_width, 0.0)
    assert depth == pytest.approx(3.24, abs=0.01)
    assert any("into unit 1" in m or ("swivels" in m and "unit 1" in m) for m in messages(report)), \
        (at_ends, depth, messages(report))


@PATHS
def test_the_same_swivel_high_above_the_gear_is_accepted(records, monkeypatch, sections):
    """The swivel of the test above, with the hob 150 mm above the gear's face: at any A between
    1.763° and 80° the hob reaches at most Y·sin A + r0·cos A + (L/2)·sin A ≤ 20 + 35 + 50 = 105 mm
    below its centre's Z (reference §A6), so it stays 45 mm above the face: clear in Z, though its
    tip cylinder (X40 − r0 35 = 5 mm from the axis) is within the gear's radius in X."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"], tailstock=False)
    a_written = round(swivel(spur.gear, spur.hob), 3)
    extra = ["G0 Z150.000", "G0 Y20.000", "G0 X40.000", "G0 A=80.000", f"G0 X{spur.x_retract:.3f}",
             f"G0 A={a_written:.3f}", "G0 Y0.000"]
    report = simulate_program(after_coupling(spur, extra), spur.gear, spur.hob, records["machine"], "TEST")
    assert not [m for m in messages(report) if "swivels" in m or "unit 1" in m], messages(report)
