"""Adversary 29 against 9217ff7 (a swivel's reach in Z exact, engine.simulation.hobbing.swivel_sweep):
the closed form is right for the hob the walk thinks it follows, but the walk handed it a hob at a
swivel and a shift it did not know. Now a move before A is written, or (swivelled) before Y is,
is proved for every swivel and every shift of the machine's travel (swivel_sweep.unknown_pose).

* Before the program writes A, the walk follows every move at A = 0 (walk.BlockSimulation.swivel
  starts at 0.0, swivel_known False), though the head stands at whatever A the last program
  left: the sweep itself calls that "an A not written before" and takes it as any swivel in
  −90…90° (swivel_sweep.UNKNOWN) once A is written, but the moves before it are not swept.
* Before the program writes Y, the sweep takes the shift as 0 (sweep_problem: position.get("Y",
  0.0)), as the contacts do, though Y stands wherever the last program left it (reference §A7:
  "Position Y in every program"; the verifier refuses EGON before Y for that reason), anywhere
  in the machine's travel (the seeded hobber-840d: Y −80…80, the template's shift per part
  leaves Y = R11 anywhere in the shift range).

The true depths are the hob's sampled surface (tests/helpers/collision_truth.true_depth: tip
cylinder and end faces, swivelled by A about X, Y along its own axis, reference §A6), never the
engine's geometry. Gear 42 (Ø42 over Z 0 … −20), hob H-M2-AA-R1 (d_a0 70, L 100), no tailstock."""
from __future__ import annotations

import math

import pytest
from helpers.collision_truth import ALLOWED, PATHS, messages, seeded_records, true_depth
from helpers.simulation_programs import LOAD, RAPID_RATE, Hand, program_minutes, swivel

from engine.simulation import simulate_program
from engine.simulation.hobbing import contact

R0, LENGTH = 35.0, 100.0


@pytest.fixture
def records(conn):
    return seeded_records(conn)


def inserted(spur: Hand, after: str, extra: list[str]) -> list[str]:
    """The hand's program with `extra` blocks after the line `after`, its cycle time header recomputed."""
    spur.header = None
    lines = spur.lines()
    at = lines.index(after) + 1
    body = lines[:at] + extra + lines[at:]
    return body[:2] + [f"; CYCLE TIME {program_minutes(body, RAPID_RATE, LOAD):.1f} MIN"] + body[2:]


def test_the_programs_without_the_extra_blocks_are_accepted(records):
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"], tailstock=False)
    assert messages(simulate_program(inserted(spur, "WALIMON", []), spur.gear, spur.hob, records["machine"], "T")) == []


def gear_depth(gear, swivel_deg: float, position: tuple) -> float:
    return true_depth(R0, LENGTH, swivel_deg, position, gear.tip_diameter / 2, -gear.face_width, 0.0)


@PATHS
def test_a_move_before_a_is_written_is_followed_at_a_zero_only(records, monkeypatch, sections):
    """Before `G0 A=…`, a hand parks the hob at X30 Z36 and leaves again. At A = 0 the hob reaches
    r0 = 35 mm below its centre: its lowest point is 1 mm above the top face (clear, what the walk
    sees). The head still stands where the last program left it; after a 20° helical gear's
    program (A = ±20°, well inside the −90…90° the sweep itself assumes for an A not yet written)
    the hob reaches r0·cos 20° + (L/2)·sin 20° = 50.0 mm below its centre, into the gear."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"], tailstock=False)
    park = (30.0, 0.0, 36.0)
    extra = [f"G0 Z{park[2]:.3f}", f"G0 X{park[0]:.3f}", f"G0 X{spur.x_retract:.3f}"]
    report = simulate_program(inserted(spur, "WALIMON", extra), spur.gear, spur.hob, records["machine"], "TEST")
    assert gear_depth(spur.gear, 0.0, park) < 0.0                  # clear at A = 0
    depth = gear_depth(spur.gear, 20.0, park)
    assert depth == pytest.approx(1.94, abs=0.01)
    assert R0 * math.cos(math.radians(20)) + LENGTH / 2 * math.sin(math.radians(20)) > park[2]
    assert messages(report), depth          # refused, whatever the words (the same program without them is accepted)


@PATHS
@pytest.mark.parametrize(("shift", "expected"), [(-20.0, 8.68), (-40.0, 8.68)])
def test_a_swivel_before_y_is_written_is_swept_as_if_unshifted(records, monkeypatch, sections, shift, expected):
    """The reference program writes A (1.763°) before Y. Between the two a hand lifts the hob to
    Z62, moves in to X30 and swivels to A = 60° and back. Unshifted, the hob reaches at most
    √(50² + 35²) = 61.03 mm below its centre at any swivel (the sweep's bound, clear of the face
    by 0.97 mm) and 35·cos 60° + 50·sin 60° = 60.8 mm at 60°. Shifted Y−20 (or Y−40, both inside
    the machine's ±80 travel) by the last program, its centre stands Y·sin 60° = 17.3 (34.6) mm
    lower (reference §A6: (X, Y·cos A, Z + Y·sin A)), and at A = 60° it is deep in the gear."""
    monkeypatch.setattr(contact, "MATH_SECTIONS", sections)
    spur = Hand(records["gear"](42), records["hobs"]["H-M2-AA-R1"], tailstock=False)
    a_written = f"{round(swivel(spur.gear, spur.hob), 3):.3f}"
    park = (30.0, 0.0, 62.0)
    extra = [f"G0 Z{park[2]:.3f}", f"G0 X{park[0]:.3f}", "G0 A=60.000", f"G0 A={a_written}",
             f"G0 X{spur.x_retract:.3f}"]
    report = simulate_program(inserted(spur, f"G0 A={a_written}", extra), spur.gear, spur.hob,
                              records["machine"], "TEST")
    assert gear_depth(spur.gear, 60.0, park) < 0.0                 # clear unshifted
    depth = gear_depth(spur.gear, 60.0, (park[0], shift, park[2]))
    assert depth == pytest.approx(expected, abs=0.01)
    assert depth > ALLOWED
    assert messages(report), depth          # refused, whatever the words (the same program without them is accepted)
