"""Every list exports what its import reads (issue 31): for gears, their further units, hobs,
work-holdings and cutting cases, `list --csv` writes the columns the import reads, every field,
every number digit for digit, and the import takes that file back unchanged: into the database it
came from (`--replace`) and into a shop's new database. A row a stored job was made from is
replaced by itself only. And a refusal never says one rounded number for two that differ."""
from __future__ import annotations

import csv
import io
import json
import math
import uuid
from decimal import Decimal
from pathlib import Path

import psycopg
import pytest
from click.testing import CliRunner
from helpers.database_pool import create_database
from psycopg.conninfo import conninfo_to_dict, make_conninfo

from engine.cli.app import main
from engine.db.migrate import migrate
from engine.errors import EngineError
from engine.gears.hob_matching import choose_hob
from engine.gears.records import Gear, Hob
from engine.library.seed import seed
from engine.paths import SEED_DIR

pytestmark = pytest.mark.cli

# kind: (list command, import command, seed file, key column, the columns the import reads, in order,
# the table and its columns as a shop would compare them: everything but the database's own dates
# and links to jobs)
KINDS = {
    "gears": (("gears", "list", "--csv"), ("gears", "import"), "gears.csv", "gear_id",
              ["gear_id", "gear_class", "module", "teeth", "pressure_angle", "helix_angle", "hand", "face_width",
               "tip_diameter", "root_diameter", "cone_angle", "crowning", "material", "hardness", "quality_grade",
               "quantity", "module_kind", "profile_shift"],
              "SELECT id, gear_class, module, teeth, pressure_angle, helix_angle, hand, face_width, tip_diameter, "
              "root_diameter, cone_angle, crowning, material, hardness, quality_grade, quantity, module_kind, "
              "profile_shift FROM gear ORDER BY id"),
    "units": (("gears", "list", "--units", "--csv"), ("gears", "units"), "gear_units.csv", "gear_id",
              ["gear_id", "unit", "teeth", "face_width", "tip_diameter", "root_diameter", "z_top"],
              "SELECT * FROM gear_unit ORDER BY gear_id, unit"),
    "hobs": (("hobs", "list", "--csv"), ("hobs", "import"), "hobs.csv", "id",
             ["id", "module", "module_kind", "pressure_angle", "starts", "tip_diameter", "length", "hand",
              "accuracy_class", "material", "coating", "purpose", "tool_number", "gashes", "profile"],
             "SELECT * FROM hob ORDER BY id"),
    "fixtures": (("fixtures", "list", "--csv"), ("fixtures", "import"), "work_holdings.csv", "id",
                 ["id", "kind", "diameter", "height", "tailstock_diameter", "machine"],
                 "SELECT * FROM work_holding ORDER BY id"),
    "cases": (("cases", "list", "--csv"), ("cases", "import"), "cases.csv", None,
              ["id", "module", "teeth", "material", "hardness", "quality_grade", "hob_material", "hob_coating",
               "hob_starts", "hob_tip_diameter", "cut", "hob_speed", "axial_feed", "radial_feed", "source"],
              "SELECT id, module, teeth, material, hardness, quality_grade, hob_material, hob_coating, hob_starts, "
              "hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed, source FROM cutting_case ORDER BY id"),
}
REPLACE = {"units": ()}   # `engine gears units` replaces the units of each gear in the file: no flag


@pytest.fixture(scope="module")
def shop_kind(server_url, database_pool):
    """Databases as `engine seed` makes a shop's (classes, templates, machines; no gears, hobs,
    work-holdings nor cases), copied from one made here."""
    name = f"engine_shop_{uuid.uuid4().hex[:10]}"
    with psycopg.connect(server_url, autocommit=True) as admin:
        create_database(admin, name)
    with psycopg.connect(url_of(server_url, name)) as conn:
        migrate(conn)
        seed(conn, samples=False)
        conn.commit()
    yield database_pool.kind(name, "engine_shop", ahead=2)
    database_pool.give_back(name)


@pytest.fixture
def shop(server_url, database_pool, shop_kind):
    """A database url maker: each call, a new shop database (dropped after the test)."""
    taken: list[str] = []

    def new() -> str:
        taken.append(database_pool.take(shop_kind))
        return url_of(server_url, taken[-1])
    yield new
    for name in taken:
        database_pool.give_back(name)


def url_of(server_url: str, database: str) -> str:
    return make_conninfo(**{**conninfo_to_dict(server_url), "dbname": database})


def engine(url: str, *args) -> str:
    """The command's stdout; the test fails with its output if it exits other than 0."""
    result = CliRunner().invoke(main, ["--database-url", url, *map(str, args)])
    assert result.exit_code == 0, (args, result.output)
    return result.stdout


def refused(url: str, *args) -> str:
    result = CliRunner().invoke(main, ["--database-url", url, *map(str, args)])
    assert result.exit_code == 1, (args, result.output)
    return result.stderr.strip()


def rows(url: str, query: str) -> list[tuple]:
    with psycopg.connect(url) as conn:
        return conn.execute(query).fetchall()


def read(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


def same_value(seeded: str, exported: str) -> bool:
    """A seed cell and the exported one: the same number (2 and 2.0 alike), or the same text."""
    try:
        return Decimal(seeded) == Decimal(exported)
    except ArithmeticError:
        return seeded == exported


@pytest.mark.slow   # its first set migrates and seeds a shop's database (8 s); `make test` runs every set
@pytest.mark.parametrize("kind", KINDS)
def test_the_list_is_the_file_its_import_takes_back_unchanged(shop, tmp_path, kind):
    listing, importing, seed_file, key, columns, table = KINDS[kind]
    replace = REPLACE.get(kind, ("--replace",))
    first, second = shop(), shop()
    if kind == "units":   # the units' gears first
        for url in (first, second):
            engine(url, "gears", "import", SEED_DIR / "gears.csv")
    engine(first, *importing, SEED_DIR / seed_file)
    exported = engine(first, *listing)
    assert exported.splitlines()[0].split(",") == columns

    seeded = read((SEED_DIR / seed_file).read_text(encoding="utf-8"))
    written = read(exported)
    by_key = {row[key]: row for row in written} if key else dict(enumerate(written))
    assert len(written) == len(seeded)
    for at, row in enumerate(seeded):   # every value the seed file gives is in the export (cases: in order)
        out = by_key[row[key] if key else at]
        assert all(same_value(cell, out[name]) for name, cell in row.items() if cell), (row, out)

    path = tmp_path / f"{kind}.csv"
    path.write_text(exported, encoding="utf-8")
    engine(first, *importing, path, *replace)
    engine(second, *importing, path, *replace)
    assert engine(first, *listing) == exported
    assert engine(second, *listing) == exported
    assert rows(first, table) == rows(second, table)


def test_numbers_survive_digit_for_digit(run, tmp_path):
    """numeric columns hold more digits than a float: the export writes each digit the database holds."""
    module, length = "2.0000000000000000001", "100.12345678901234567890"
    hobs = tmp_path / "hob.csv"
    hobs.write_text(f"id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class\n"
                    f"H-EXACT-1,{module},20,1,70,{length},R,AA\n", encoding="utf-8")
    engine(run.url, "hobs", "import", hobs)
    line = next(row for row in engine(run.url, "hobs", "list", "--csv").splitlines() if row.startswith("H-EXACT-1,"))
    assert line.split(",")[1] == module and line.split(",")[6] == length
    listed = engine(run.url, "hobs", "list", "--json")
    assert f'"module": {module},' in listed and f'"length": {length},' in listed
    hob = next(hob for hob in json.loads(listed)["hobs"] if hob["hob_id"] == "H-EXACT-1")
    assert hob["pressure_angle"] == 20 and hob["tool_number"] == 1


def test_a_gear_a_stored_job_was_made_from_is_replaced_by_itself_only(run, tmp_path):
    made = json.loads(engine(run.url, "instantiate", "--gear", 42, "--json"))
    exported = engine(run.url, "gears", "list", "--csv")
    path = tmp_path / "gears.csv"
    path.write_text(exported, encoding="utf-8")
    engine(run.url, "gears", "import", path, "--replace")   # unchanged: taken back

    changed = read(exported)
    gear_42 = next(row for row in changed if row["gear_id"] == "42")
    assert gear_42["face_width"] == "20"   # seed_templates/gears.csv
    path.write_text(exported.replace("\n42,spur,2,19,20,0,,20,", "\n42,spur,2,19,20,0,,25,"), encoding="utf-8")
    said = refused(run.url, "gears", "import", path, "--replace")
    assert (f"gear 42: the file changes its face_width 20 → 25, but job {made['job_id']} was made from it; "
            "nothing imported") in said
    assert rows(run.url, "SELECT face_width FROM gear WHERE id = 42") == [(20,)]


def test_a_hob_a_stored_job_was_made_with_keeps_its_values(run, tmp_path):
    made = json.loads(engine(run.url, "instantiate", "--gear", 42, "--json"))
    hob_id = rows(run.url, f"SELECT hob_id FROM job WHERE id = {int(made['job_id'])}")[0][0]
    exported = engine(run.url, "hobs", "list", "--csv")
    path = tmp_path / "hobs.csv"
    path.write_text(exported, encoding="utf-8")
    engine(run.url, "hobs", "import", path, "--replace")
    line = next(row for row in exported.splitlines() if row.startswith(f"{hob_id},"))
    cells = line.split(",")
    assert exported.splitlines()[0].split(",")[6] == "length"
    cells[6] = "150"
    path.write_text(exported.replace(line, ",".join(cells)), encoding="utf-8")
    said = refused(run.url, "hobs", "import", path)   # without --replace too: an import updates
    assert f"hob {hob_id}: the file changes its length {line.split(',')[6]} → 150, but job " in said
    assert rows(run.url, f"SELECT length FROM hob WHERE id = '{hob_id}'") == [(Decimal(line.split(',')[6]),)]


def test_replace_takes_whole_rows_only(read_only_run, tmp_path):
    path = tmp_path / "hobs.csv"
    path.write_text("id,module,pressure_angle,starts,tip_diameter,length,hand,accuracy_class\n"
                    "H-M2-AA-R1,2,20,1,70,100,R,AA\n", encoding="utf-8")
    said = refused(read_only_run.url, "hobs", "import", path, "--replace")
    assert said.endswith("leaves out material, coating, purpose, tool_number, module_kind, gashes, profile; "
                         "nothing imported: give every column (`engine hobs list --csv` writes them), or import "
                         "without --replace to keep each hob's own values of those")


def test_a_stored_case_is_refused_without_replace_and_replaced_with_it(run, tmp_path):
    exported = engine(run.url, "cases", "list", "--csv")
    first = read(exported)[0]
    path = tmp_path / "cases.csv"
    header = exported.splitlines()[0]
    faster = {**first, "hob_speed": "250"}
    buffer = io.StringIO()
    csv.DictWriter(buffer, header.split(","), lineterminator="\n").writerows([faster])
    path.write_text(header + "\n" + buffer.getvalue(), encoding="utf-8")
    said = refused(run.url, "cases", "import", path)
    assert (f"{path}, line 2, column id: case {first['id']} already exists; leave the id empty for a new case, or "
            "import with --replace to replace it") in said
    replaced = engine(run.url, "cases", "import", path, "--replace")
    assert f"case {first['id']}: hob_speed {first['hob_speed']} → 250" in replaced
    new_case = tmp_path / "new.csv"
    new_case.write_text(header + "\n" + buffer.getvalue().replace(f"{first['id']},", ",", 1), encoding="utf-8")
    assert "added 1 case(s), replaced 0" in engine(run.url, "cases", "import", new_case)
    ids = [row[0] for row in rows(run.url, "SELECT id FROM cutting_case ORDER BY id")]
    assert len(ids) == len(read(exported)) + 1 and ids[-1] > max(int(row["id"]) for row in read(exported))


def test_cases_imported_with_their_ids_leave_the_next_id_above_them(run, tmp_path):
    stored = max(row[0] for row in rows(run.url, "SELECT id FROM cutting_case"))
    path = Path(tmp_path / "cases.csv")
    path.write_text("id,module,teeth,material,hob_material,hob_starts,hob_tip_diameter,cut,hob_speed,axial_feed,"
                    f"radial_feed\n{stored + 10},2,30,45,HSS,1,70,rough,173,14.4,5.2\n"
                    ",2,30,45,HSS,1,70,finish,191,7.6,2.5\n", encoding="utf-8")
    engine(run.url, "cases", "import", path)
    assert rows(run.url, f"SELECT id, cut FROM cutting_case WHERE id > {stored} ORDER BY id") == [
        (stored + 10, "rough"), (stored + 11, "finish")]


def test_a_work_holding_a_stored_job_is_clamped_on_keeps_its_values(run, tmp_path):
    made = json.loads(engine(run.url, "instantiate", "--gear", 42, "--fixture", "A-D12-H60", "--json"))
    exported = engine(run.url, "fixtures", "list", "--csv")
    assert "\nA-D12-H60,arbor,12,60,8,\n" in exported   # seed_templates/work_holdings.csv
    path = tmp_path / "holdings.csv"
    path.write_text(exported, encoding="utf-8")
    engine(run.url, "fixtures", "import", path, "--replace")   # unchanged: taken back
    path.write_text(exported.replace("\nA-D12-H60,arbor,12,60,8,\n", "\nA-D12-H60,arbor,12,65,8,\n"), encoding="utf-8")
    said = refused(run.url, "fixtures", "import", path, "--replace")
    assert (f"work-holding A-D12-H60: the file changes its height 60 → 65, but job {made['job_id']} was clamped "
            "on it; nothing imported") in said
    assert rows(run.url, "SELECT height FROM work_holding WHERE id = 'A-D12-H60'") == [(60,)]


# --- messages: never one rounded number on both sides of a mismatch -------------------------------------

def hob_of(hob_id: str, module: float = 2.0, length: float = 100.0) -> Hob:
    return Hob(hob_id, module, 20.0, 1, 70.0, length, "R", "AA", "HSS", "TiN", "cylindrical")


def gear_of(module: float = 2.0) -> Gear:
    """A spur gear m, z 30, α 20°, b 20, grade 7 (a class AA hob)."""
    return Gear(901, "spur", module, 30, 20.0, 0.0, None, 20.0, None, None, None, None, "40Cr", 220.0, 7, 10)


def hob_refusal(gear: Gear, hobs: list[Hob], **options) -> str:
    with pytest.raises(EngineError) as caught:
        choose_hob(gear, hobs, **options)
    return str(caught.value)


def test_a_refusal_never_says_one_number_for_the_need_and_an_offer_that_differ():
    """"no hob has module 3.98478 … they have module 3.98478": the two are 0.000003 apart, beyond the
    1e-6 a module must match to; the refusal says them with the digits that tell them apart."""
    message = hob_refusal(gear_of(3.984781), [hob_of("H-X", module=3.984784)])
    assert message.startswith("gear 901: no hob has module 3.984781 among those with purpose cylindrical: "
                              "they have module 3.984784 (H-X)")
    # the hob length needed: generating 2·2.25·m/tan α + π·m, the shift and 2·5 mm of margins
    needed = 2 * 2.25 * 2 / math.tan(math.radians(20)) + math.pi * 2 + 59.03 + 2 * 5
    assert f"{needed:.1f}" == "100.0"   # said as before, the hob's 100 would read alike
    message = hob_refusal(gear_of(), [hob_of("H-M2-AA-R1")], shift_travel=59.03)
    assert f"no hob has length ≥ {needed:.10g} mm" in message and "they have length 100 (H-M2-AA-R1)" in message
    short = hob_refusal(gear_of(), [hob_of("H-M2-AA-R1")], shift_travel=60)   # 101.0 against 100: as before
    assert "no hob has length ≥ 101.0 mm" in short
