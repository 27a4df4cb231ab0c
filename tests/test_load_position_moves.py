"""The rapids between the machine's load position and the work (issue 29). The seeded hobber loads
at X300 Z100; a gear whose tip radius reaches past X300 − r0 lies under that point, and one G0 in X
and Z together (on a line, or as a dog-leg where the control does not interpolate rapids) sweeps
the hob down through its top face. A programmer leaves the load position out in X above the work,
then goes down at the retract X; and at the end goes up first, then in. Here the hobber loads at
X300 Z250: before the program writes A and Y the head may stand at any swivel and shift the last
program left, so the hob there reaches √((L/2 + |Y|max)² + r0²) = √(165² + 62.5²) = 176 mm below
its centre (swivel_sweep), and only a load position that high is clear of this gear's top face
whatever the head's swivel (at Z100 nothing could be proved). The population of
scripts/hob_population.py (300 gears, seed 29) had 25 refused so; now none."""
from __future__ import annotations

import pytest
from helpers.nc_reader import read_program

from engine.errors import EngineError
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode

GEAR = 990_001
# m8 z80 spur: tip Ø656 (radius 328); a DIN 8002-like hob of m8: da0 125, r0 62.5.
HOB = ("H-M8-A-R1-T", 8, 1, 125, 170, "R", "A")


@pytest.fixture
def big_gear(conn):
    conn.execute("UPDATE machine SET x_max = 500, z_max = 300, load_z = 250, module_max = 8 "
                 "WHERE name = 'hobber-840d'")
    conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class) "
                 "VALUES (%s, %s, %s, %s, %s, %s, %s)", HOB)
    conn.execute("INSERT INTO gear (id, gear_class, module, teeth, face_width, material, hardness, quality_grade, "
                 "quantity) VALUES (%s, 'spur', 8, 80, 80, '45', 200, 8, 10)", (GEAR,))
    return conn


def test_a_gear_under_the_load_position_is_reached_one_axis_at_a_time(big_gear):
    nc = read_program(instantiate_gear(big_gear, GEAR).text)   # stored: proved
    rapids = [move for move in nc.moves_in("G0")]
    x_retract = (656 + 125) / 2 + 5                  # tip and hob radii and the retract clearance
    assert rapids[0].changed == {"X"} and rapids[0].end["X"] == pytest.approx(x_retract, abs=0.001)
    assert rapids[1].changed == {"Z"}
    assert rapids[-2].changed == {"Z"} and rapids[-2].end["Z"] == pytest.approx(250.0)
    assert rapids[-1].changed == {"X"} and rapids[-1].end["X"] == pytest.approx(300.0)


def test_one_rapid_in_both_axes_from_the_load_position_is_refused(big_gear):
    """The template as it was: the simulation finds the hob in the gear."""
    big_gear.execute("""UPDATE template_view SET o = 'f"G0 X{x_retract:.3f} Z{z_start:.3f}"', p_emit = NULL
                        WHERE gear_class = 'spur' AND id = 1250""")
    big_gear.execute("UPDATE template_view SET p_emit = 'False' WHERE gear_class = 'spur' AND id IN (1251, 1252)")
    with pytest.raises(EngineError, match=r"within reach of unit 1"):
        instantiate_gear(big_gear, GEAR, mode=RunMode(draft=True))
