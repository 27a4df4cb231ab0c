"""A population of hobbing work drawn with a fixed seed from the reference ranges (issue 29: "module
1–8 on a machine rated for it, 12–120 teeth, every class"): spur, helical of both hands, taper (about half helical),
crowned, cluster and worm wheels with catalogue hobs by axial module; a hob library sized roughly
per DIN 8002 (tip diameter and length by module, both hands, 1–3 starts, classes AA and A),
catalogue worm-wheel hobs for the worms drawn, the shop's arbors for small bores, and the seeded
hobber-840d rated for it (m 8, 600 mm of X: the largest gear, m 8 with 120 teeth, at full depth
with its hob; loading at Z300). Which gears are hobbing work at all is decided here from the
geometry, not by the engine (shaper_jobs). Used by tests/test_population.py and
scripts/hob_population.py."""
from __future__ import annotations

import math
import random

import numpy as np
from psycopg import sql

FIRST = 500_000
MODULES = (1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)
# DIN 8002-like single-start hob tip diameters by module (mm), rounded up to catalogue sizes.
HOB_TIP = {1.0: 50, 1.25: 50, 1.5: 56, 2.0: 63, 2.5: 70, 3.0: 80, 4.0: 90, 5.0: 100, 6.0: 112, 8.0: 125}
CLASSES = ("spur", "spur", "helical", "helical", "taper", "crowned", "duplex", "worm_wheel")
MATERIALS = ("45", "C45", "20CrMnTi", "40Cr")
WORM_QUOTIENTS = (10.0, 12.5)    # q = d1/m_x of the worms drawn (DIN 3976 values)
# The shop's arbors between centres for small bores, beside the seeded library: (diameter under
# the gear, height from the table to the gear, centre diameter above it), mm. A gear of m 1-1.5
# with 12-14 teeth has a root of about Ø14-19: it is hobbed on a thin arbor tall enough that the
# hob (Ø50-63) runs out below the gear without reaching the table.
WORK_HOLDINGS = [(f"POP-A-D{d}-H{h}", "arbor", d, h, round(0.6 * d)) for d in (8, 10, 12) for h in (80, 100)]
# A cluster gear is a hobbing job only when a hob of the library fits between its units: cutting
# one unit at full depth (hob centre at r_f + r_a0), the hob's tip cylinder, swivelled by its lead
# angle γ = asin(z0·m / (d_a0 − 2.5·m)) as a spur gear needs, reaches some way along Z into the
# other unit's tip cylinder (found here by sampling the hob's surface); the gap must hold that, a
# clearance and the hob centre carried past the face it leaves (both 1 mm), the pass leaving each
# unit into the gap. Narrower gaps are a gear shaper's job, whatever the engine says: they are
# counted apart.
GAP_CLEARANCE = 1.0
GAP_OVERRUN = 1.0


def hob_rows() -> list[tuple]:
    """(id, module, starts, tip, length, hand, class, purpose, module_kind) of the library."""
    rows = []
    for module, tip in HOB_TIP.items():
        length = round(max(1.2 * tip, 17 * module + 20))
        for hand in "RL":
            for starts in (1, 2, 3):
                for grade in ("AA", "A"):
                    rows.append((f"P-M{module:g}-{grade}-{hand}{starts}", module, starts, tip, length, hand, grade,
                                 "cylindrical", "normal"))
    return rows


def worm_hobs(module: float, starts: int, quotient: float, hand: str) -> list[tuple]:
    """Catalogue worm-wheel hobs copying the worm d1 = q·m_x: tip d1 + 2.5·m_x (reference §B10), classes AA and A."""
    tip, length = quotient * module + 2.5 * module, round(max(3 * quotient * module, 17 * module + 20))
    return [(f"P-WW-MX{module:g}-Q{quotient:g}-{grade}-{hand}{starts}", module, starts, tip, length, hand, grade,
             "worm_wheel", "axial") for grade in ("AA", "A")]


def gear_row(rng: random.Random, gear_id: int, hobs: set) -> tuple[tuple, list[tuple]]:
    """One gear (the gear table's columns) and its further units (a cluster gear's)."""
    gear_class = rng.choice(CLASSES)
    module = rng.choice(MODULES)
    teeth = rng.randint(12, 120)
    grade = rng.choice((6, 7, 8, 8, 9))
    material, hardness = rng.choice(MATERIALS), rng.randint(170, 280)
    face = round(rng.uniform(6, 12) * module, 1)
    helix, hand, cone, crowning, kind, units = 0.0, None, None, None, None, []
    if gear_class == "helical":
        helix, hand = round(rng.uniform(8, 30), 2), rng.choice("RL")
    elif gear_class == "taper":
        cone = round(rng.uniform(2, 10), 1)
        helix, hand = taper_helix(gear_id, cone)
    elif gear_class == "crowned":
        crowning = round(rng.uniform(0.01, 0.03), 3)
    elif gear_class == "duplex":
        second = rng.randint(12, max(12, teeth - 5))
        gap = round(rng.uniform(8, 20) * module, 1)
        units = [(gear_id, 2, second, round(rng.uniform(6, 10) * module, 1), None, None, round(-face - gap, 1))]
    elif gear_class == "worm_wheel":
        starts, quotient = rng.choice((1, 1, 2, 3)), rng.choice(WORM_QUOTIENTS)
        hand, kind = rng.choice("RL"), "axial"
        module = min(module, 6.0)
        helix = round(math.degrees(math.atan(starts / quotient)), 4)
        teeth, face = rng.randint(25, 80), round(0.7 * quotient * module, 1)
        hobs.update(worm_hobs(module, starts, quotient, hand))
        material, hardness = "CuSn12", 90
    return ((gear_id, gear_class, module, teeth, 20, helix, hand, face, None, None, cone, crowning, material,
             hardness, grade, rng.randint(1, 200), kind), units)


def taper_helix(gear_id: int, cone: float) -> tuple[float, str | None]:
    """About half the tapers helical (issue 29: a swivelled hob's pass is a polyline), β 8–30° of
    either hand. Drawn from a generator of their own, seeded by the gear and its cone (drawn from
    the population's), so the population's sequence, and every other gear, stays as it was."""
    own = random.Random(f"taper helix {gear_id} {cone}")
    if own.random() < 0.5:
        return 0.0, None
    return round(own.uniform(8, 30), 2), own.choice("RL")


GEAR_COLUMNS = ("id", "gear_class", "module", "teeth", "pressure_angle", "helix_angle", "hand", "face_width",
                "tip_diameter", "root_diameter", "cone_angle", "crowning", "material", "hardness", "quality_grade",
                "quantity", "module_kind")
UNIT_COLUMNS = ("gear_id", "unit", "teeth", "face_width", "tip_diameter", "root_diameter", "z_top")
HOB_COLUMNS = ("id", "module", "starts", "tip_diameter", "length", "hand", "accuracy_class", "purpose", "module_kind")


def hob_reach(r_a0: float, length: float, swivel: float, centre_x: float, other_tip: float) -> float:
    """How far (mm, along Z) the tip cylinder of a hob (radius r_a0, length, swivel in degrees
    about X, centre at X = centre_x) reaches into a cylinder of radius other_tip about the work
    axis: the largest Z over the hob's surface points inside it, sampled every 0.25° and L/400.
    Only the angles whose X lies within the cylinder's radius can hold a point inside it (x² ≤
    x² + y²), so the points of the others are not made (issue 28: this was a quarter of the
    population test; the points kept and their values are the same as with every angle)."""
    eta = math.radians(swivel)
    t = np.linspace(-length / 2, length / 2, 401)[:, None]
    phi = np.radians(np.arange(0.0, 360.0, 0.25))[None, :]
    x = centre_x + r_a0 * np.cos(phi)
    near = x[0] ** 2 <= other_tip ** 2
    phi, x = phi[:, near], x[:, near]
    y = t * math.cos(eta) - r_a0 * np.sin(phi) * math.sin(eta)
    z = t * math.sin(eta) + r_a0 * np.sin(phi) * math.cos(eta)
    inside = x ** 2 + y ** 2 <= other_tip ** 2
    return float(np.abs(z[inside]).max()) if inside.any() else 0.0


def hobbable_gap(module: float, units: list[int], hob: tuple[float, float, int]) -> float:
    """The least gap (mm) between two spur units (their teeth) of a cluster gear that a hob
    (tip diameter, length, starts) cuts, each unit next to the other (see GAP_CLEARANCE)."""
    tip, length, starts = hob
    r_a0, swivel = tip / 2, math.degrees(math.asin(starts * module / (tip - 2.5 * module)))
    reach = max(hob_reach(r_a0, length, swivel, module * (teeth - 2.5) / 2 + r_a0, module * (other + 2) / 2)
                for teeth, other in ((units[0], units[1]), (units[1], units[0])))
    return reach + GAP_CLEARANCE + GAP_OVERRUN


def shaper_jobs(conn) -> set[int]:
    """The cluster gears whose gap no hob of the library for their module fits (worm-wheel hobs, copies
    of a worm, are not for spur units)."""
    rows = conn.execute("""SELECT g.id, g.module, g.teeth, u.teeth, -g.face_width - u.z_top,
                                  array_agg(ARRAY[h.tip_diameter, h.length, h.starts])
                           FROM gear g JOIN gear_unit u ON u.gear_id = g.id
                           JOIN hob h ON h.module = g.module AND h.purpose <> 'worm_wheel'
                           WHERE g.gear_class = 'duplex' AND g.id >= %s
                           GROUP BY g.id, u.teeth, u.z_top""", (FIRST,)).fetchall()
    return {gear_id for gear_id, module, z1, z2, gap, hobs in rows
            if float(gap) < min(hobbable_gap(float(module), [z1, z2], tuple(map(float, hob))) for hob in hobs)}


def populate(conn, count: int, seed_value: int) -> None:
    rng, hobs = random.Random(seed_value), set(hob_rows())
    gears, units = [], []
    for index in range(count):
        gear, more = gear_row(rng, FIRST + index, hobs)
        gears.append(gear)
        units += more
    _insert(conn, "hob", HOB_COLUMNS, sorted(hobs))
    _insert(conn, "gear", GEAR_COLUMNS, gears)
    _insert(conn, "gear_unit", UNIT_COLUMNS, units)
    _insert(conn, "work_holding", ("id", "kind", "diameter", "height", "tailstock_diameter"), WORK_HOLDINGS)
    # loaded high enough that a hob at the load position clears the largest gear at any swivel and
    # shift the last program may have left (engine.simulation.hobbing.swivel_sweep.unknown_pose)
    conn.execute("UPDATE machine SET module_max = 8, x_max = 600, z_max = 350, load_z = 300 "
                 "WHERE name = 'hobber-840d'")
    conn.commit()


def _insert(conn, table: str, columns: tuple, rows: list) -> None:
    query = sql.SQL("INSERT INTO {} ({}) VALUES ({})").format(
        sql.Identifier(table), sql.SQL(", ").join(map(sql.Identifier, columns)),
        sql.SQL(", ").join(sql.Placeholder() * len(columns)))
    with conn.cursor() as cursor:
        cursor.executemany(query, rows)


