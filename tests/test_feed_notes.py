"""The notes on an m2.5 gear's feed agree with each other (new-user review 29): the §C range is
named with the row it was read from (the row up to m3, not "m3"), a feed the engine lowered to its
own chip-thickness bound is not then called below the typical range, and the notes of a job of one
cut say "single cut:", not "rough:". The gear: m2.5 z20 spur, grade 5, cut with the library's only
AAA m2.5 hob, 3 starts, d_a0 75, 9 gashes; its bound (the reference's formula) is below the §C row's
2.0 mm/rev."""
from __future__ import annotations

from helpers import chip_reference as reference

from engine.gears.cases import suggest_for_gear
from engine.programs.instantiate import instantiate_gear

GEAR, MODULE, TEETH, TIP, GASHES, STARTS = 82000, 2.5, 20, 75, 9, 3
ROUGH_LOW_UP_TO_M3 = 2.0   # §C: roughing f_a 2.0–3.5 mm/rev for modules above 2 up to 3


def add_gear(conn) -> float:
    conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class, coating, gashes) "
                 "VALUES ('C-M2.5-R3', %s, %s, %s, 140, 'R', 'AAA', 'TiN', %s)", (MODULE, STARTS, TIP, GASHES))
    conn.execute("INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, helix_angle, face_width, "
                 "material, hardness, quality_grade) VALUES (%s, 'spur', %s, %s, 20, 0, 20, '40Cr', 220, 5)",
                 (GEAR, MODULE, TEETH))
    bound = reference.feed_at_bound(MODULE, TEETH, 0, 0, TIP, GASHES, STARTS)
    assert bound < ROUGH_LOW_UP_TO_M3, "the chip bound lowers the feed below the typical range"
    return bound


def test_suggest_names_the_row_and_does_not_complain_of_its_own_bound(conn):
    bound = add_gear(conn)
    notes = suggest_for_gear(conn, GEAR).notes
    lowered = [note for note in notes if "Hoffmeister" in note]
    assert lowered and f"bounded to {bound:.2f}" in lowered[0]
    assert not any("m3" in note for note in notes), notes
    assert not any(f"{bound:.2f} mm per workpiece rev is below" in note for note in notes), notes


def test_a_single_cut_job_says_single_cut(conn):
    bound = add_gear(conn)
    program = instantiate_gear(conn, GEAR)   # m2.5: one cut by module (§B14)
    lowered = [note for note in program.notes if "Hoffmeister" in note]
    assert lowered and lowered[0].startswith(f"gear {GEAR}: single cut: axial feed") and f"{bound:.2f}" in lowered[0]
    assert not any(note.startswith(f"gear {GEAR}: rough:") for note in program.notes), program.notes
