"""Gears, hobs and machines for the acceptance tests of issue 14, put into the database with SQL
(never through the engine), and the test's own description of them (tests/helpers/hobbing_reference.py).
Diameters follow the reference: d = mn·z/cosβ, d_a = d + 2mn(1 + x), d_f = d_a − 2·2.25mn.
"""
from __future__ import annotations

import math
import re

from helpers.hobbing_checks import Holding
from helpers.hobbing_reference import Gear, Hob, Machine, Unit, lead_angle

DIN = Machine()
MIRROR = Machine("hobber-mirror", a=-1, c=-1, z=-1)          # A, C and Z against DIN 66217
REVERSED = Machine("hobber-reversed", a=-1, b=-1, c=-1, y=-1, z=-1)   # every sense against DIN 66217
HOB_DIAMETER = {1: 45.0, 1.5: 57.0, 2: 70.0, 2.5: 75.0, 3: 80.0, 4: 90.0}
WORM_HOB_DIAMETER = 50.0
TOOL_NUMBER = 7

def insert_hob(conn, hob: Hob, mn: float, purpose: str = "cylindrical") -> str:
    hob_id = f"RT-{purpose[:3].upper()}-M{mn:g}-{hob.hand}{hob.z0}-{hob.da0:g}"
    conn.execute("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class, purpose, "
                 "tool_number) VALUES (%s, %s, %s, %s, %s, %s, 'AA', %s, %s) ON CONFLICT DO NOTHING",
                 (hob_id, mn, hob.z0, hob.da0, hob.length, hob.hand, purpose, hob.tool_number))
    return hob_id


def only_hob(conn, hob_id: str) -> None:
    """Every other hob becomes too coarse for a grade-8 gear, so the engine must take this one."""
    conn.execute("UPDATE hob SET accuracy_class = CASE WHEN id = %s THEN 'AA' ELSE 'D' END", (hob_id,))


STOCK = ("45", 200, 8)          # material, hardness HB, quality grade
PAPER_STOCK = ("40Cr", 250, 7)  # the paper's: its seeded case feeds 8.11 mm per workpiece revolution at m2


def insert_gear(conn, gear_id: int, gear: Gear, crowning: float = 0.0, stock: tuple = STOCK) -> None:
    first = gear.first
    conn.execute("INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, helix_angle, hand, face_width, "
                 "tip_diameter, root_diameter, cone_angle, crowning, material, hardness, quality_grade, quantity, "
                 "module_kind) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s, %s, %s, %s, %s, %s, %s, 50, 'normal')",
                 (gear_id, gear.gear_class, gear.mn, first.z2, gear.alpha, gear.beta, gear.hand, first.b,
                  first.da, first.df, gear.cone or None, crowning or None, *stock))
    for number, unit in enumerate(gear.units[1:], start=2):
        conn.execute("INSERT INTO gear_unit (gear_id, unit, teeth, face_width, tip_diameter, root_diameter, z_top) "
                     "VALUES (%s, %s, %s, %s, %s, %s, %s)", (gear_id, number, unit.z2, unit.b, unit.da, unit.df,
                                                             unit.z_top))


def insert_machine(conn, machine: Machine = MIRROR) -> None:
    """hobber-840d with the senses of `machine`: its Z travel and load Z mirror when Z is reversed
    (Z_prog = −Z_DIN); its Y travel is symmetric."""
    conn.execute("CREATE TEMP TABLE mirrored ON COMMIT DROP AS SELECT * FROM machine WHERE name = 'hobber-840d'")
    conn.execute("UPDATE mirrored SET name = %s, a_direction = %s, b_direction = %s, c_direction = %s, "
                 "y_direction = %s, z_direction = %s, z_min = CASE WHEN %s < 0 THEN -z_max ELSE z_min END, "
                 "z_max = CASE WHEN %s < 0 THEN -z_min ELSE z_max END, load_z = load_z * %s",
                 (machine.name, machine.a, machine.b, machine.c, machine.y, machine.z, machine.z, machine.z, machine.z))
    conn.execute("INSERT INTO machine SELECT * FROM mirrored")
    conn.execute("DROP TABLE mirrored")


def cylindrical(mn: float, z2: int, beta: float = 0.0, x: float = 0.0) -> tuple[float, float]:
    """Tip and root diameter: d = mn·z/cosβ, d_a = d + 2mn(1 + x), d_f = d_a − 2·2.25mn."""
    d = mn * z2 / math.cos(math.radians(beta))
    da = round(d + 2 * mn * (1 + x), 3)
    return da, round(da - 4.5 * mn, 3)


def make_hob(mn: float, hand: str, z0: int = 1, worm: bool = False) -> Hob:
    if worm:
        return Hob(z0, WORM_HOB_DIAMETER, hand, 90.0, TOOL_NUMBER)
    return Hob(z0, HOB_DIAMETER[mn], hand, 90.0 + 12.5 * mn, TOOL_NUMBER)


def make_gear(gear_class: str, hand: str | None, hob: Hob, cone: float = 0.0, large_below: bool = True) -> Gear:
    if gear_class == "helical":
        return Gear("helical", 3, 15.0, hand, (Unit(41, 30, *cylindrical(3, 41, 15)),))
    if gear_class == "taper":
        return Gear("taper", 2, 0.0, None, (Unit(19, 20, 42.5, 33.5),), cone=cone)
    if gear_class == "crowned":
        return Gear("crowned", 2.5, 0.0, None, (Unit(32, 30, *cylindrical(2.5, 32)),))
    if gear_class == "worm_wheel":
        beta = round(lead_angle(3, hob), 3)
        return Gear("worm_wheel", 3, beta, hob.hand, (Unit(40, 25, *cylindrical(3, 40, beta)),))
    if gear_class == "duplex" and large_below:      # the example: small unit 1 over a large unit 2
        return Gear("duplex", 4, 0.0, None, (Unit(74, 30, 304.0, 286.0), Unit(106, 30, 433.9, 415.9, -75.0)))
    if gear_class == "duplex":
        return Gear("duplex", 2, 0.0, None, (Unit(30, 20, 64.0, 55.0), Unit(19, 15, 42.0, 33.0, -75.0)))
    return Gear("spur", 2, 0.0, None, (Unit(30, 20, 64.0, 55.0),))


def read_machine(conn, name: str) -> Machine:
    """The test's Machine as the shop declared it in the machine row: senses, work offset, table speed,
    rapid rate, fixture and tailstock (diameter, gap; NULL = none) and load position (program frame)."""
    row = conn.execute("SELECT a_direction, b_direction, c_direction, y_direction, z_direction, work_offset, "
                       "table_speed_max, rapid_rate, fixture_diameter, fixture_gap, tailstock_diameter, "
                       "tailstock_gap, load_x, load_z FROM machine WHERE name = %s", (name,)).fetchone()
    a, b, c, y, z, offset, table, rapid, fix_d, fix_gap, tail_d, tail_gap, load_x, load_z = row
    number = lambda value: float(value or 0.0)      # noqa: E731
    return Machine(name, a, b, c, y, z, offset, float(table) if table else math.inf, float(rapid),
                   (number(fix_d), number(fix_gap)), (number(tail_d), number(tail_gap)),
                   (None if load_x is None else float(load_x), None if load_z is None else float(load_z)))


def read_holding(conn, program_text: str):
    """The work-holding the program states (`; FIXTURE <id>`), as its record declares it; None
    where the program states none (the machine's own fixture and tailstock)."""
    stated = re.search(r"^; FIXTURE (\S+)$", program_text, re.MULTILINE)
    if stated is None:
        return None
    row = conn.execute("SELECT diameter, height, tailstock_diameter FROM work_holding WHERE id = %s",
                       (stated.group(1),)).fetchone()
    return Holding(*(float(value) for value in row))
