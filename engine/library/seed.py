"""`engine seed`: load seed_templates/ — what is missing is added, nothing is overwritten,
so a second run changes nothing and a template an engineer edited stays edited."""
from __future__ import annotations

import csv
import json
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
from psycopg import sql
from psycopg.types.json import Jsonb

from ..csv_reader import Column, CsvKind, parse_text, read_csv_file
from ..errors import EngineError
from ..gears.gear_import import GEAR_KIND, read_gears
from ..gears.gear_store import identical_gears, import_gears, installed_classes
from ..gears.hob_library import HOB_COLUMNS
from ..gears.units import UNIT_KIND, import_units
from ..machines.holding_library import HOLDING_COLUMNS
from ..machines.importing import MACHINE_KIND
from ..paths import SEED_DIR
from ..templates.expectations import refuse_slow_patterns
from ..templates.store import ensure_class, replace_template
from ..templates.template_csv import read_csv

if TYPE_CHECKING:
    from ..db.connection import Connection

# The seed tables' CSV kinds: every cell goes as text, and the database parses it into its column's type.
CLASS_KIND = CsvKind("gear class", (Column("name", parse_text, required=True), Column("parent", parse_text),
                                    Column("description", parse_text)))
SEED_HOB_KIND = CsvKind("hob", tuple(Column(column.name, parse_text, column.required) for column in HOB_COLUMNS))
SEED_HOLDING_KIND = CsvKind("work-holding", tuple(Column(column.name, parse_text, column.required)
                                                  for column in HOLDING_COLUMNS))

# table, CSV file, key column, its kind; loaded in this order.
SEED_TABLES = (
    ("machine", "machines.csv", "name", MACHINE_KIND),
    ("hob", "hobs.csv", "id", SEED_HOB_KIND),
    ("work_holding", "work_holdings.csv", "id", SEED_HOLDING_KIND),
)
SHOP_TABLES = SEED_TABLES[:1]   # the machines; the hobs and work-holdings are samples


class SeedReport(msgspec.Struct):
    added: dict[str, int] = {}
    created: list[str] = []   # the classes this seed created
    # sample gear id → golden tests of it not added: the database's gear of that id is another
    skipped_tests: dict[int, int] = {}

    def count(self, what: str, number: int = 1) -> None:
        self.added[what] = self.added.get(what, 0) + number

    def __str__(self) -> str:
        said = "seed: added " + ", ".join(f"{n} {what}" for what, n in self.added.items() if n)
        if not any(self.added.values()):
            said = "seed: everything was already there; nothing changed"
        return said + "".join(f"\n{line}" for line in self.skipped_lines())

    def skipped_lines(self) -> list[str]:
        """Why golden tests of the samples were left out, one line per sample gear."""
        return [f"seed: skipped {n} golden test{'s' * (n != 1)} of sample gear {gear_id}: gear {gear_id} here is "
                "not the sample (a gear of the shop's own), and a test of it would test that gear"
                for gear_id, n in sorted(self.skipped_tests.items())]


def seed(conn: Connection, directory: Path = SEED_DIR, *, samples: bool = True) -> SeedReport:
    """Load what is missing, in one transaction.

    What every shop needs (`engine seed`): the class tree and the standard code of each class,
    released (the shipped templates, tested here); the machine records (every program is checked
    against its machine's limits, the default machines are the ones the standard code's dialects
    are written for, and a shop edits its records rather than typing them from nothing); the
    golden tests that state their job's parameters (the release gate runs them).

    The samples (`samples`: `engine seed --samples`, `engine demo`, the tests; the library's
    default, for them): the sample gears and their further units, the sample hob library, the
    machining-history cases, and the golden tests that name a sample gear. Gears, hobs and the
    history are a shop's own data; a sample gear 42 next to the shop's gears would be
    instantiated by mistake, a sample hob chosen for a real job, sample cases would move its
    cutting data; a test naming gear 42 would test whatever the shop's gear 42 is."""
    report = SeedReport()
    with conn.transaction():
        _seed_classes(conn, directory, report)
        for table, file_name, key, kind in SEED_TABLES if samples else SHOP_TABLES:
            rows = _read(directory / file_name, kind)
            report.count(table.replace("_", "-") + "s", _insert_missing(conn, table, key, rows))
        seeded = _seed_templates(conn, directory, report)
        samples_stored = _seed_samples(conn, directory, report) if samples else None
        _seed_template_tests(conn, directory, report, samples_stored)
        _release_seeded(conn, seeded, report)
    return report


def _seed_samples(conn: Connection, directory: Path, report: SeedReport) -> set[int]:
    """The samples; returns the ids of the sample gears the database holds as the samples give
    them (added now, or identical): a shop's own gear under a sample's id gets no sample units
    nor golden tests."""
    samples_stored = _seed_gears(conn, directory, report)
    _seed_units(conn, directory, report, samples_stored)
    _seed_cases(conn, directory, report)
    return samples_stored


RELEASE_SEEDED = ("SELECT release_template(g.name, g.template_version, v.hash, note => %s, via => 'seed') "
                  "FROM gear_class g "
                  "JOIN template_version_rows v ON v.gear_class = g.name AND v.version = g.template_version "
                  "WHERE g.name = %s AND released_version(g.name) IS DISTINCT FROM g.template_version")


INSERT_TEST = ("INSERT INTO template_test (gear_class, name, gear_id, params, choices, expect, description) "
               "SELECT %s, %s, %s, %s, %s, %s, %s WHERE EXISTS (SELECT 1 FROM gear_class WHERE name = %s) "
               "ON CONFLICT (gear_class, name) DO NOTHING RETURNING 1")


def _seed_template_tests(conn: Connection, directory: Path, report: SeedReport,
                         samples_stored: set[int] | None) -> None:
    """The golden tests of the shipped templates (engine test), by class and name: a test a DBA
    edited stays edited; a missing one is added, like every seeded row. Those naming a sample
    gear only with the samples, and only where that gear is the sample (`samples_stored`)."""
    path = directory / "template_tests.json"
    if not path.exists():
        return
    added, stored = 0, set(conn.execute("SELECT gear_class, name FROM template_test").fetchall())
    for test in json.loads(path.read_text(encoding="utf-8")):
        if (test["class"], test["name"]) in stored or not _of_a_sample(test.get("gear_id"), samples_stored, report):
            continue
        _refuse_slow_patterns(path, test)
        params = test.get("params")
        added += conn.execute(INSERT_TEST, (test["class"], test["name"], test.get("gear_id"),
                                            Jsonb(params) if params is not None else None,
                                            Jsonb(test.get("choices", {})), test["expect"],
                                            test.get("description", ""), test["class"])).fetchone() is not None
    report.count("template tests", added)


def _refuse_slow_patterns(path: Path, test: dict) -> None:
    """A pattern RE2 cannot run in linear time is refused where the test enters (issue 26)."""
    try:
        refuse_slow_patterns(test["expect"])
    except EngineError as error:
        raise EngineError(f"{path} test {test['class']}/{test['name']}: {error}") from None


def _of_a_sample(gear_id: int | None, samples_stored: set[int] | None, report: SeedReport) -> bool:
    """True for a test that names no gear, or a sample gear stored as the sample; a test of a
    sample gear that is another gear here is counted as skipped. Without the samples
    (`samples_stored` None) every test of a gear is left out, and none is counted."""
    if gear_id is None or (samples_stored is not None and gear_id in samples_stored):
        return True
    if samples_stored is not None:
        report.skipped_tests[gear_id] = report.skipped_tests.get(gear_id, 0) + 1
    return False


def _release_seeded(conn: Connection, classes: list[str], report: SeedReport) -> None:
    """The templates the seed loaded are released: they are the shipped, tested templates."""
    for gear_class in classes:
        conn.execute("SELECT store_current_version(%s) WHERE NOT EXISTS (SELECT 1 FROM template_version_rows v "
                     "JOIN gear_class g ON g.name = v.gear_class AND g.template_version = v.version "
                     "WHERE g.name = %s)", (gear_class, gear_class))
        released = conn.execute(RELEASE_SEEDED, ("released by engine seed: the shipped template", gear_class))
        report.count("template releases", len(released.fetchall()))


def _read(path: Path, kind: CsvKind) -> list[dict[str, Any]]:
    """The rows of a seed file as {column: text}, an empty cell None (the column's default)."""
    return [{key: (value if value != "" else None) for key, value in row.items()}
            for _, row in read_csv_file(path, kind).rows()]


def _seed_classes(conn: Connection, directory: Path, report: SeedReport) -> None:
    for row in _read(directory / "gear_classes.csv", CLASS_KIND):
        if ensure_class(conn, row["name"], row["parent"], row["description"] or ""):
            report.count("gear classes")
            report.created.append(row["name"])


def _insert_missing(conn: Connection, table: str, key: str, rows: list[dict[str, Any]]) -> int:
    added = 0
    for row in rows:
        row = {column: value for column, value in row.items() if value is not None}   # empty: the default
        query = sql.SQL("INSERT INTO {} ({}) VALUES ({}) ON CONFLICT ({}) DO NOTHING RETURNING 1").format(
            sql.Identifier(table), sql.SQL(", ").join(map(sql.Identifier, row)),
            sql.SQL(", ").join(sql.Placeholder() * len(row)), sql.Identifier(key))
        added += conn.execute(query, list(row.values())).fetchone() is not None
    return added


def _seed_templates(conn: Connection, directory: Path, report: SeedReport) -> list[str]:
    """Parents before the classes derived from them (the tree order of gear_classes.csv), so
    a derived class stores only the rows that differ from what it inherits."""
    order = [row["name"] for row in _read(directory / "gear_classes.csv", CLASS_KIND)]
    paths = sorted((directory / "classes").glob("*.csv"),
                   key=lambda path: (order.index(path.stem) if path.stem in order else len(order), path.stem))
    templated = []
    for path in paths:
        has_rows = conn.execute("SELECT 1 FROM assembly WHERE gear_class = %s LIMIT 1", (path.stem,)).fetchone()
        if not has_rows:
            ensure_class(conn, path.stem)
            replace_template(conn, path.stem, read_csv(path))
            report.count("templates")
            templated.append(path.stem)
    return report.created + [name for name in templated if name not in report.created]


def _seed_gears(conn: Connection, directory: Path, report: SeedReport) -> set[int]:
    """Sample gears not yet in the database, through the same checks as `engine gears import`;
    the ids of the sample gears stored as the samples give them (see _seed_samples)."""
    source = directory / "gears.csv"
    _add_missing_gears(conn, source, report)
    return identical_gears(conn, read_gears(source, installed_classes(conn)))


def _add_missing_gears(conn: Connection, source: Path, report: SeedReport) -> None:
    known = {row[0] for row in conn.execute("SELECT id FROM gear")}
    file = read_csv_file(source, GEAR_KIND)
    missing = [row for _, row in file.rows() if int(row["gear_id"]) not in known]
    header = file.header
    if not missing:
        return
    with tempfile.TemporaryDirectory() as folder:
        subset = Path(folder) / source.name
        with subset.open("w", encoding="utf-8", newline="") as written:
            writer = csv.DictWriter(written, header)
            writer.writeheader()
            writer.writerows(missing)
        report.count("gears", import_gears(conn, subset).imported)


def _seed_units(conn: Connection, directory: Path, report: SeedReport, samples_stored: set[int]) -> None:
    """Further units of the sample multi-unit gears, where the gear is the sample and has none yet."""
    source = directory / "gear_units.csv"
    with_units = {row[0] for row in conn.execute("SELECT DISTINCT gear_id FROM gear_unit")}
    rows = [row for row in _read(source, UNIT_KIND)
            if int(row["gear_id"]) not in with_units and int(row["gear_id"]) in samples_stored]
    if rows:
        report.count("gear units", import_units(conn, source, only_gears={int(r["gear_id"]) for r in rows}))


def _seed_cases(conn: Connection, directory: Path, report: SeedReport) -> None:
    """The machining history's seed cases (the paper's example among them)."""
    from ..gears.cases import seed_cases  # pandas: loaded only when the history is seeded

    report.count("cases", seed_cases(conn, directory / "cases.csv"))
