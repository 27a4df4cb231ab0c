"""How much of the work a skilled programmer would hob does the engine make and prove? (issue 29:
"at least 99 % of the gears a skilled programmer would cut become programs that the simulation
proves, and every refusal names a physical reason and what was tried").

A population drawn with a fixed seed from the reference ranges: module 1–8 on a hobber rated for
it (the seeded hobber-840d's record, widened to m 8 and 500 mm of X, loading at Z300), 12–120 teeth, every hobbing
class (spur, helical of both hands, taper, crowned, cluster, worm wheels with catalogue hobs by
axial module); a hob library sized roughly per DIN 8002 (tip diameter and length by module,
both hands, 1–3 starts, classes AA and A) and catalogue worm-wheel hobs for the worms drawn.
Every gear is made by a dry-run batch (the verifier and the simulation prove each program, nothing
stored), in a database of its own, dropped at the end. Printed: per class, how many are proved,
and the refusals grouped by their reason's first words.

    python scripts/hob_population.py [--count 600] [--seed 29] [--workers 2] [--database-url URL]

The default server is DATABASE_URL, else 127.0.0.1:5432. Exit 0 always: it reports.
"""
from __future__ import annotations

import argparse
import math
import os
import random
import re
import sys
import uuid
from collections import Counter
from pathlib import Path

import psycopg
from psycopg import sql

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from engine.db.migrate import migrate  # noqa: E402
from engine.library.seed import seed  # noqa: E402
from engine.programs.instantiate import instantiate_gears  # noqa: E402
from engine.programs.options import RunMode  # noqa: E402

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
# one unit at full depth, the hob's tip circle (centre distance r_f + r_a0) meets the other unit's
# tip cylinder over a half-chord sqrt(r_a0² − (a − r_a,other)²) along Z; the gap must hold that,
# a clearance and the hob centre carried past the face it leaves (both 1 mm). Narrower gaps are a
# gear shaper's job, whatever the engine says: they are counted apart. The hob's swivel and length
# are left out, so the bound is the most generous to "hobbable".
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


GEAR_COLUMNS = ("id", "gear_class", "module", "teeth", "pressure_angle", "helix_angle", "hand", "face_width",
                "tip_diameter", "root_diameter", "cone_angle", "crowning", "material", "hardness", "quality_grade",
                "quantity", "module_kind")
UNIT_COLUMNS = ("gear_id", "unit", "teeth", "face_width", "tip_diameter", "root_diameter", "z_top")
HOB_COLUMNS = ("id", "module", "starts", "tip_diameter", "length", "hand", "accuracy_class", "purpose", "module_kind")
# The seeded hobber's record rated for the population's largest module.
MACHINE = """INSERT INTO machine SELECT * FROM machine WHERE name = 'hobber-840d'
             ON CONFLICT DO NOTHING"""


def hobbable_gap(module: float, units: list[tuple[int, float]], hob_tip: float) -> float:
    """The least gap (mm) between two spur units (teeth, face) of a cluster gear that a hob of
    tip diameter `hob_tip` can cut, each unit next to the other (see GAP_CLEARANCE)."""
    r_a0 = hob_tip / 2
    need = 0.0
    for (teeth, _), (other_teeth, _) in ((units[0], units[1]), (units[1], units[0])):
        root, other_tip = module * (teeth - 2.5) / 2, module * (other_teeth + 2) / 2
        centre_above = root + r_a0 - other_tip     # hob centre's distance outside the other's tip
        if centre_above < r_a0:                    # the tip circle dips under the other unit's tip
            need = max(need, math.sqrt(r_a0 ** 2 - max(centre_above, 0.0) ** 2))
    return need + GAP_CLEARANCE + GAP_OVERRUN


def shaper_jobs(conn) -> set[int]:
    """The cluster gears whose gap no hob of the library for their module fits (worm-wheel hobs, copies
    of a worm, are not for spur units)."""
    rows = conn.execute("""SELECT g.id, g.module, g.teeth, g.face_width, u.teeth, u.face_width,
                                  -g.face_width - u.z_top,
                                  (SELECT min(tip_diameter) FROM hob h
                                   WHERE h.module = g.module AND h.purpose <> 'worm_wheel')
                           FROM gear g JOIN gear_unit u ON u.gear_id = g.id
                           WHERE g.gear_class = 'duplex' AND g.id >= %s""", (FIRST,)).fetchall()
    return {gear_id for gear_id, module, z1, b1, z2, b2, gap, tip in rows
            if tip is None or float(gap) < hobbable_gap(float(module), [(z1, b1), (z2, b2)], float(tip))}


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
    conn.execute("UPDATE machine SET module_max = 8, x_max = 500, z_max = 350, load_z = 300 "
                 "WHERE name = 'hobber-840d'")
    conn.commit()


def _insert(conn, table: str, columns: tuple, rows: list) -> None:
    query = sql.SQL("INSERT INTO {} ({}) VALUES ({})").format(
        sql.Identifier(table), sql.SQL(", ").join(map(sql.Identifier, columns)),
        sql.SQL(", ").join(sql.Placeholder() * len(columns)))
    with conn.cursor() as cursor:
        cursor.executemany(query, rows)


def reason(message: str) -> str:
    """The refusal's kind: its message without the gear and the numbers."""
    text = re.sub(r"^gear \d+: ", "", message)
    text = re.sub(r"-?\d+(\.\d+)?", "#", text)
    return text[:110]


def report(conn, count: int, workers: int, examples: int = 0) -> None:
    classes = dict(conn.execute("SELECT id, gear_class FROM gear WHERE id >= %s", (FIRST,)).fetchall())
    batch = instantiate_gears(conn, FIRST, FIRST + count - 1, mode=RunMode(dry_run=True, skip_bad=True,
                                                                          workers=workers))
    refused = {gear_id: message for gear_id, message in _skipped(batch)}
    shaped = shaper_jobs(conn)
    work = count - len(shaped)
    made = work - len(set(refused) - shaped)
    print(f"population: {count} gears, {count - len(refused)} proved ({100 * (count - len(refused)) / count:.1f} %); "
          f"of the {work} a hob of the library fits, {made} proved ({100 * made / work:.1f} %); "
          f"{len(shaped)} cluster gears too narrow for any hob (a shaper's job), {len(shaped & set(refused))} "
          "of them refused")
    for gear_class in sorted(set(classes.values())):
        ids = [gear_id for gear_id, name in classes.items() if name == gear_class and gear_id not in shaped]
        bad = [gear_id for gear_id in ids if gear_id in refused]
        print(f"  {gear_class:10s} {len(ids) - len(bad):4d} of {len(ids):4d} proved")
        for text, number in Counter(reason(refused[gear_id]) for gear_id in bad).most_common(6):
            print(f"      {number:4d}  {text}")
        for gear_id in bad[:examples]:
            print(f"      e.g. gear {gear_id}: {refused[gear_id]}")


def _skipped(batch) -> list[tuple[int, str]]:
    """(gear id, reason) of each skipped line "gear 7: <reason>"."""
    return [(int(line.split(":")[0].split()[1]), line.partition(": ")[2]) for line in batch.skipped]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=600)
    parser.add_argument("--seed", type=int, default=29)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--examples", type=int, default=0, help="print this many whole refusals of each class")
    parser.add_argument("--database-url", default=os.environ.get("DATABASE_URL",
                                                                  "postgresql://postgres@127.0.0.1:5432/postgres"))
    args = parser.parse_args(argv)
    name = f"population_{uuid.uuid4().hex[:8]}"
    with psycopg.connect(args.database_url, autocommit=True) as admin:
        admin.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(name)))
    try:
        url = psycopg.conninfo.make_conninfo(args.database_url, dbname=name)
        with psycopg.connect(url) as conn:
            migrate(conn)
            seed(conn)
            conn.commit()
            populate(conn, args.count, args.seed)
            report(conn, args.count, args.workers, args.examples)
    finally:
        with psycopg.connect(args.database_url, autocommit=True) as admin:
            admin.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(sql.Identifier(name)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
