"""Materials as data (issue 31): table material holds each workpiece material's group, hardness
range and the cutting speeds of reference §C by hob column; its four §C rows are the reference's
own table (read from docs/reference/hobbing.md here), `engine materials list|show|import` round
trip, a gear whose material the table lacks is refused at instantiate (and named in a batch)
naming the known ones closest first, and an imported material's speeds bound the hob's."""
from __future__ import annotations

import json
import math
import re
from decimal import Decimal
from pathlib import Path

import psycopg
import pytest

from engine.gears.records import Hob, load_gear
from engine.gears.speed_table import SPEEDS, most_hob_speed, speed_range

pytestmark = pytest.mark.cli

REFERENCE = Path(__file__).resolve().parent.parent / "docs" / "reference" / "hobbing.md"
HEADER = ("name,material_group,hardness_min,hardness_max,uncoated_low,uncoated_high,coated_low,coated_high,"
          "carbide_low,carbide_high,default_uncoated,default_coated,source\n")
# A slow made-up material: every column of §C at 10–20 m/min, defaults 15.
SLOW = "SlowSteel,test steel,150,200,10,20,10,20,10,20,15,15,test\n"
SLOW_HIGH = 20.0
GEAR_CSV = ("gear_id,gear_class,module,teeth,pressure_angle,helix_angle,hand,face_width,material,hardness,"
            "quality_grade,quantity\n"
            "901,spur,2,25,20,0,,20,{material},180,8,10\n"
            "902,spur,2,27,20,0,,20,40Cr,250,8,10\n")
SEEDED = ("45", "C45", "20CrMnTi", "40Cr", "42CrMo4", "34CrNiMo6", "38CrMoAl", "16MnCr5", "20MnCr5", "20CrMnMo",
          "18CrNiMo7-6", "17CrNiMo6", "EN-GJL-250", "HT250", "EN-GJS-600-3", "QT600-3", "CuSn12", "ZCuSn10P1")


def reference_rows() -> dict[str, tuple]:
    """The rows of the §C speed table of the reference: name(s) -> three (low, high) in m/min."""
    section = REFERENCE.read_text(encoding="utf-8").split("## C.", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = [cell.strip() for cell in line.strip("|").split("|")]
        if len(cells) == 4 and re.fullmatch(r"\d+–\d+", cells[1]):
            ranges = tuple(tuple(float(v) for v in cell.split("–")) for cell in cells[1:])
            for name in re.split(r"\s*/\s*", cells[0].split(" (")[0]):
                rows[name] = ranges
    return rows


def test_the_seeded_rows_are_the_reference_table(conn):
    expected = reference_rows()
    assert set(expected) == {"45", "C45", "20CrMnTi", "40Cr"}
    stored = {row[0]: ((float(row[1]), float(row[2])), (float(row[3]), float(row[4])), (float(row[5]), float(row[6])))
              for row in conn.execute("SELECT name, uncoated_low, uncoated_high, coated_low, coated_high, "
                                      "carbide_low, carbide_high FROM material WHERE name = ANY(%s)",
                                      (list(expected),))}
    assert stored == expected
    assert {name: row.ranges for name, row in SPEEDS.items()} == expected   # a record made without the database


def test_list_names_every_shipped_material_and_csv_is_the_import_columns(read_only_run):
    listed = json.loads(read_only_run("materials", "list", "--json").stdout)["materials"]
    assert sorted(row["name"] for row in listed) == sorted(SEEDED, key=str)
    table = read_only_run("materials", "list")
    assert table.exit_code == 0 and table.stderr.strip() == f"{len(SEEDED)} materials"
    assert read_only_run("materials", "list", "--csv").stdout.splitlines()[0] + "\n" == HEADER


def test_show_finds_a_name_in_any_case_and_refuses_an_unknown_one_closest_first(read_only_run):
    shown = json.loads(read_only_run("materials", "show", "42crmo4", "--json").stdout)["material"]
    assert shown["name"] == "42CrMo4" and shown["gear_count"] == 0
    assert Decimal(str(shown["uncoated_low"])) <= Decimal(str(shown["default_uncoated"])) \
        <= Decimal(str(shown["uncoated_high"]))
    refused = read_only_run("materials", "show", "42CrMo")
    assert refused.exit_code == 1 and len(refused.stderr.strip().splitlines()) == 1
    assert "known, closest first: 42CrMo4" in refused.stderr and "engine materials import" in refused.stderr


def test_the_list_is_the_file_its_import_takes_back_unchanged(run, tmp_path):
    exported = run("materials", "list", "--csv").stdout
    path = tmp_path / "materials.csv"
    path.write_text(exported + SLOW, encoding="utf-8")
    imported = run("materials", "import", path, "--replace", "--json")
    assert imported.exit_code == 0, imported.output
    assert json.loads(imported.stdout) == {"added": 1, "updated": len(SEEDED)}
    again = run("materials", "list", "--csv").stdout
    header, *lines = exported.splitlines(keepends=True)   # by name ignoring case, byte order
    assert again == header + "".join(sorted([*lines, SLOW], key=lambda line: line.split(",")[0].lower()))
    path.write_text(again, encoding="utf-8")
    assert run("materials", "import", path, "--replace").exit_code == 0
    assert run("materials", "list", "--csv").stdout == again


@pytest.mark.parametrize("row,said", [
    ("Bad,steel,200,150,10,20,10,20,10,20,15,15,x\n", "hardness_max"),
    ("Bad,steel,150,200,30,20,10,20,10,20,15,15,x\n", "uncoated_high"),
    ("Bad,steel,150,200,10,20,10,20,10,20,25,15,x\n", "default_uncoated"),
    ("Bad,steel,150,200,10,20,10,20,10,20,15,15,\n", "source"),
    ("c45,steel,150,200,10,20,10,20,10,20,15,15,x\n", "C45"),
])
def test_a_bad_row_is_refused_and_nothing_is_imported(run, tmp_path, row, said):
    before = run("materials", "list", "--csv").stdout
    path = tmp_path / "bad.csv"
    path.write_text(HEADER + SLOW + row, encoding="utf-8")
    result = run("materials", "import", path)
    assert result.exit_code == 1 and said in result.stderr, result.output
    assert run("materials", "list", "--csv").stdout == before


def test_replace_takes_whole_rows_only(read_only_run, tmp_path):
    """Every column of a material is required, so the reader refuses a file that leaves one out,
    with --replace or without (import_materials' own --replace refusal is never reached)."""
    path = tmp_path / "part.csv"
    path.write_text(HEADER.replace(",source", "") + SLOW.replace(",test\n", "\n"), encoding="utf-8")
    for replace in (("--replace",), ()):
        result = read_only_run("materials", "import", path, *replace)
        assert result.exit_code == 1 and "missing required column(s) source" in result.stderr, result.output


def jobs(url: str) -> int:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT count(*) FROM job").fetchone()[0]


def test_a_gear_of_an_unknown_material_is_imported_then_refused_at_instantiate(run, tmp_path):
    (tmp_path / "gears.csv").write_text(GEAR_CSV.format(material="St52"), encoding="utf-8")
    assert run("gears", "import", tmp_path / "gears.csv").exit_code == 0   # refused at instantiate, not import
    before = jobs(run.url)
    refused = run("instantiate", "--gear", 901)
    message = refused.stderr.strip()
    assert refused.exit_code == 1 and len(message.splitlines()) == 1, refused.output
    assert message.startswith("error: gear 901: material 'St52' is not a known material (known, closest first: ")
    assert "engine materials import" in message and jobs(run.url) == before

    suggested = run("suggest", "--gear", 901)   # suggest proposes, and says what instantiate will do
    assert suggested.exit_code == 0 and "material St52: instantiate refuses it" in suggested.output

    for workers in ("1", "2"):   # the batch names the bad gear, planned here or in worker processes
        batch = run("instantiate", "--gears", "901-902", "--workers", workers)
        assert batch.exit_code == 1 and "gear 901: material 'St52' is not a known material" in batch.stderr
        assert jobs(run.url) == before

    (tmp_path / "st52.csv").write_text(HEADER + "St52,structural steel,140,180,30,45,60,120,150,300,38,90,x\n",
                                       encoding="utf-8")
    assert run("materials", "import", tmp_path / "st52.csv").exit_code == 0
    assert run("instantiate", "--gear", 901).exit_code == 0 and jobs(run.url) == before + 1


def test_an_imported_materials_speeds_bound_the_hob(run, tmp_path):
    (tmp_path / "slow.csv").write_text(HEADER + SLOW, encoding="utf-8")
    assert run("materials", "import", tmp_path / "slow.csv").exit_code == 0
    (tmp_path / "gears.csv").write_text(GEAR_CSV.format(material="slowsteel"), encoding="utf-8")   # any case
    assert run("gears", "import", tmp_path / "gears.csv").exit_code == 0
    out = tmp_path / "out"
    out.mkdir()
    made = run("instantiate", "--gear", 901, "--out", out / "G901.MPF")
    assert made.exit_code == 0, made.output
    text = (out / "G901.MPF").read_text()
    tip = float(re.search(r"^; HOB \S+ z0=\d+ da0=([\d.]+)", text, re.M).group(1))
    speeds = [float(s) for s in re.findall(r"\bS(\d+(?:\.\d+)?)\b", text)]
    most = math.floor(1000 * SLOW_HIGH / (math.pi * tip) + 1e-9)   # n0 ≤ 1000·v/(π·d_a0), §B4
    assert speeds and max(speeds) <= most
    with psycopg.connect(run.url) as conn:
        gear = load_gear(conn, 901)
    hob = Hob("H", 2, 20, 1, tip, 100, "R", "A", "HSS", "", "cylindrical")
    assert speed_range(gear, hob) == (10.0, SLOW_HIGH, True) and most_hob_speed(gear, hob) == most


def test_the_list_goes_into_a_new_database_unchanged(run, empty_database_url, tmp_path):
    """A shop's materials, exported, are the same materials in a database migrated anew."""
    from click.testing import CliRunner

    from engine.cli.app import main

    (tmp_path / "slow.csv").write_text(HEADER + SLOW, encoding="utf-8")
    assert run("materials", "import", tmp_path / "slow.csv").exit_code == 0
    exported = run("materials", "list", "--csv").stdout
    (tmp_path / "all.csv").write_text(exported, encoding="utf-8")

    def other(*args):
        return CliRunner().invoke(main, ["--database-url", empty_database_url, *map(str, args)])
    assert other("db", "migrate").exit_code == 0
    imported = other("materials", "import", tmp_path / "all.csv", "--replace", "--json")
    assert json.loads(imported.stdout) == {"added": 1, "updated": len(SEEDED)}
    assert other("materials", "list", "--csv").stdout == exported
