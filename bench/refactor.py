"""The nightly refactor on a generated library: 1,000 classes x ~80 rows, then 10x the rows
(10,000 classes), each in its own database. Baseline measured in the same run: reading the
stored library once (every assembly row with its component body, one statement).
Targets: a full refactor of the 1x library in at most 10 s, and the 10x library in at
most 12x the time of the 1x library (near-linear).

    python bench/refactor.py [--classes 1000] [--rows 80] [--scale 10] [--reps 3]
                             [--database-url postgresql://postgres@127.0.0.1:5432/postgres]

The library is built from the seeded standard code (seed_templates/classes/*.csv), as a
shop's library grows from its proven programs:
* families: FAMILIES standard codes of ~ROWS rows, each drawn from the seeded bodies of
  every module type, in module order;
* each class is one family's rows, where about VARIANT_SHARE of the rows use one of
  VARIANTS_PER_ROW shared variants of the line (another comment, a near-duplicate that
  the report should find) and about OWN_SHARE are the class's own lines (the seed line's
  NC words with the class's own parameters: class-specific, not near-duplicates);
* DERIVED_SHARE of the classes derive from another class and store only DERIVED_ROWS
  rows of their own (like duplex from spur);
* COPIED_SHARE of the assembly rows point at a copy of their body, as SQL edits leave
  them, so the refactor has bodies to merge.
Before timing, each database is checked: the refactor keeps every class's template, a
second run changes nothing.
"""
from __future__ import annotations

import argparse
import random
import sys
import time
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _common import add_database_argument, bench_database, median, parse_arguments, verdict  # noqa: E402

TARGET_SECONDS = 10.0
TARGET_SCALING = 12.0
FAMILIES = 25
VARIANTS_PER_ROW = 3
VARIANT_SHARE = 0.10
OWN_SHARE = 0.05
DERIVED_SHARE = 0.10
DERIVED_ROWS = 8
COPIED_SHARE = 0.02
SEED_CLASSES = Path(__file__).resolve().parent.parent / "seed_templates" / "classes"
MODULE_ORDER = ("main", "prep", "sync", "shift", "cutcond", "cutmotion")
ROWS_PER_TYPE = {"main": 0.15, "prep": 0.10, "sync": 0.05, "shift": 0.07, "cutcond": 0.13, "cutmotion": 0.50}


def seed_bodies() -> dict[str, list[tuple]]:
    """Distinct bodies (t, o, p_calc, s, p_emit) of the seeded standard code, per module type."""
    from engine.templates.template_csv import read_csv

    bodies: dict[str, set] = defaultdict(set)
    for path in sorted(SEED_CLASSES.glob("*.csv")):
        for row in read_csv(path):
            bodies[row.t].add((row.t, row.o, row.p_calc, row.s, row.p_emit))
    return {t: sorted(found, key=repr) for t, found in bodies.items()}


class Library:
    """Components and assemblies of a generated library, ready for COPY."""

    def __init__(self, classes: int, rows: int, seed: int):
        self.random = random.Random(seed)
        self.bodies = seed_bodies()
        self.component_ids: dict[tuple, int] = {}
        self.components: list[tuple] = []
        self.assembly: list[tuple] = []
        self.classes: list[tuple] = []
        families = [self._family(rows) for _ in range(FAMILIES)]
        for number in range(classes):
            self._add_class(number, families[number % FAMILIES])

    def _family(self, rows: int) -> list[tuple]:
        family = []
        for t in MODULE_ORDER:
            pool = [body for body in self.bodies.get(t, []) if body[1] is not None] or self.bodies[t]
            family += [self.random.choice(pool) for _ in range(max(1, round(rows * ROWS_PER_TYPE[t])))]
        return family

    def _add_class(self, number: int, family: list[tuple]) -> None:
        name = f"g{number:05d}"
        derived = number >= FAMILIES and self.random.random() < DERIVED_SHARE
        parent = f"g{number - FAMILIES:05d}" if derived else None
        self.classes.append((name, parent))
        positions = sorted(self.random.sample(range(len(family)), DERIVED_ROWS)) if derived else range(len(family))
        for position in positions:
            body = self._body_for(name, family[position], position)
            self.assembly.append((name, 100 * (position + 1), 1, self._component(body, copied=self._copied())))

    def _body_for(self, name: str, body: tuple, position: int) -> tuple:
        draw = self.random.random()
        if draw < OWN_SHARE:
            return own_line(body, f"{name}_{position}")
        if draw < OWN_SHARE + VARIANT_SHARE and body[1] is not None:
            return variant(body, self.random.randrange(VARIANTS_PER_ROW))
        return body

    def _copied(self) -> bool:
        return self.random.random() < COPIED_SHARE

    def _component(self, body: tuple, copied: bool) -> int:
        if body in self.component_ids and not copied:
            return self.component_ids[body]
        self.components.append((len(self.components) + 1, *body))
        self.component_ids.setdefault(body, len(self.components))
        return len(self.components)


def variant(body: tuple, number: int) -> tuple:
    """A shared variant of the line: the same NC words and one more comment unit."""
    t, o, p_calc, s, p_emit = body
    return (t, f'{o} + " ; V{number + 1}"', p_calc, s, p_emit)


def own_line(body: tuple, suffix: str) -> tuple:
    """The class's own line: the seed line's NC words with the class's own parameters."""
    from engine.library.similarity import nc_units

    t, o, *_ = body
    units = nc_units(o) if o is not None else ("G0",)
    parts = [f"{{p_{suffix}_{k}:.3f}}" if unit.startswith("{") else unit.replace("{", "{{").replace("}", "}}")
             for k, unit in enumerate(units)]
    text = " ".join(parts) + f" ; OWN {suffix}"
    quote = "'" if '"' in text else '"'
    return (t, f"f{quote}{text}{quote}", None, None, None)


def load(conn, library: Library) -> None:
    with conn.transaction():
        with conn.cursor().copy("COPY gear_class (name, parent) FROM STDIN") as copy:
            for record in library.classes:
                copy.write_row(record)
        with conn.cursor().copy("COPY component (id, t, o, p_calc, s, p_emit) FROM STDIN") as copy:
            for record in library.components:
                copy.write_row(record)
        conn.execute("SELECT setval('component_id_seq', (SELECT max(id) FROM component))")
        with conn.cursor().copy("COPY assembly (gear_class, id, n, component_id) FROM STDIN") as copy:
            for record in library.assembly:
                copy.write_row(record)
    conn.execute("ANALYZE gear_class, component, assembly")
    conn.commit()


def timed_refactor(conn) -> tuple[float, object, dict]:
    """Seconds of one committed refactor, its report and the seconds of each stage."""
    from engine.library.refactor import refactor

    stages, marks = {}, []

    def progress(stage, done, total):
        marks.append((stage, time.perf_counter()))
    start = time.perf_counter()
    report = refactor(conn, 0.8, progress)
    conn.commit()
    seconds = time.perf_counter() - start
    ends = [moment for _, moment in marks[1:]] + [start + seconds]
    for (stage, begin), end in zip(marks, ends):
        stages[stage] = end - begin
    return seconds, report, stages


def assembled_templates(conn) -> list[tuple]:
    """Every class's assembled rows, in order: compared before and after, independently of the
    refactor's own digest check."""
    return conn.execute("SELECT gear_class, id, t, n, p_calc, s, o, p_emit FROM template_view "
                        "ORDER BY gear_class, id").fetchall()


# The stored library read once into Python, with JIT off as in the refactor: the least that
# touching every row costs.
STORED_ROWS = """
SELECT a.gear_class, a.id, a.n, c.t, c.o, c.p_calc, c.s, c.p_emit
FROM assembly a JOIN component c ON c.id = a.component_id"""


def timed_read(conn) -> float:
    start = time.perf_counter()
    conn.execute("SET LOCAL jit = off")
    conn.execute(STORED_ROWS).fetchall()
    conn.rollback()
    return time.perf_counter() - start


def measure(server_url: str, classes: int, rows: int, reps: int, seed: int) -> dict:
    """Fresh library per repetition (the first refactor has copies to merge); alternated
    with the baseline read."""
    import psycopg

    refactors, reads, result = [], [], {}
    for rep in range(reps):
        library = Library(classes, rows, seed + rep)
        with bench_database(server_url, "bench_refactor", seeded=False) as url:
            from engine.db.migrate import migrate

            with psycopg.connect(url) as conn:
                migrate(conn)
                conn.commit()
                load(conn, library)
                reads.append(timed_read(conn))
                before = assembled_templates(conn)
                conn.rollback()
                seconds, report, stages = timed_refactor(conn)
                refactors.append(seconds)
                again = timed_refactor(conn)[1]
                if assembled_templates(conn) != before or again.changed or not report.changed:
                    raise SystemExit("bench/refactor.py: the refactor changed a template, or a second run "
                                     "changed something, or the first merged nothing: figures meaningless")
                reads.append(timed_read(conn))
                conn.rollback()
        result = {"rows": len(library.assembly), "classes": classes, "report": report, "stages": stages,
                  "copies": len(library.components) - len(library.component_ids)}
    result.update(refactor=median(refactors), read=median(reads), refactors=refactors)
    return result


def describe(label: str, found: dict) -> None:
    report = found["report"]
    stages = ", ".join(f"{stage} {seconds:.2f} s" for stage, seconds in found["stages"].items())
    print(f"{label}: {found['classes']:,} classes, {found['rows']:,} assembly rows, "
          f"components {report.components_before:,} -> {report.components_after:,} "
          f"({found['copies']:,} copies merged), {report.shared:,} shared by 2+ classes, "
          f"{len(report.near_duplicates):,} near-duplicate pairs")
    print(f"  refactor median {found['refactor']:.2f} s (runs: "
          f"{', '.join(f'{s:.2f}' for s in found['refactors'])}); reading the library once "
          f"{found['read']:.2f} s; ratio {found['refactor'] / found['read']:.2f}x")
    print(f"  stages of the last run: {stages}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_database_argument(parser)
    parser.add_argument("--classes", type=int, default=1000, help="classes of the 1x library (default 1000)")
    parser.add_argument("--rows", type=int, default=80, help="rows per class (default 80)")
    parser.add_argument("--scale", type=int, default=10, help="the larger library has this many times the "
                        "classes (default 10)")
    parser.add_argument("--reps", type=int, default=3, help="repetitions per size (default 3; the 10x "
                        "size runs max(1, reps // 2))")
    parser.add_argument("--seed", type=int, default=20261122, help="random seed of the generated library")
    args = parse_arguments(parser, argv, smoke={"classes": 20, "rows": 20, "scale": 2, "reps": 1})

    small = measure(args.database_url, args.classes, args.rows, args.reps, args.seed)
    describe("1x", small)
    large = measure(args.database_url, args.classes * args.scale, args.rows, max(1, args.reps // 2), args.seed)
    describe(f"{args.scale}x", large)
    scaling = large["refactor"] / small["refactor"]
    row_ratio = large["rows"] / small["rows"]
    print(f"\nfull refactor of the 1x library: {small['refactor']:.2f} s, target <= {TARGET_SECONDS:g} s: "
          f"{verdict(small['refactor'] <= TARGET_SECONDS)}")
    print(f"{row_ratio:.1f}x the rows took {scaling:.2f}x the time, target <= {TARGET_SCALING:g}x: "
          f"{verdict(scaling <= TARGET_SCALING)} (reading the library: {large['read'] / small['read']:.2f}x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
