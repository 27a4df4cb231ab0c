"""How much of the work a skilled programmer would hob does the engine make and prove? (issue 29:
"at least 99 % of the gears a skilled programmer would cut become programs that the simulation
proves, and every refusal names a physical reason and what was tried").

A population drawn with a fixed seed from the reference ranges: module 1–8 on a hobber rated for
it (the seeded hobber-840d's record, widened to m 8 and 600 mm of X, loading at Z300: the
largest gear, m 8 with 120 teeth, at full depth with its hob), 12–120 teeth, every hobbing
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
import os
import re
import sys
import uuid
from collections import Counter
from pathlib import Path

import psycopg
from psycopg import sql

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]   # the engine, and the population the tests draw

from helpers.hob_population import FIRST, populate, shaper_jobs  # noqa: E402

from engine.db.migrate import migrate  # noqa: E402
from engine.library.seed import seed  # noqa: E402
from engine.programs.instantiate import instantiate_gears  # noqa: E402
from engine.programs.options import RunMode  # noqa: E402


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
