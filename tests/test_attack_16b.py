"""Attacks on the fixes of issue 16 (second adversary review): each test states the behaviour a
user relies on, and fails while the engine breaks it."""
from __future__ import annotations

import csv
import io

import psycopg


def _spur_with_row(run, tmp_path, o: str):
    """The spur template's CSV with one more main row whose output is `o`."""
    exported = run("template", "export", "--class", "spur")
    assert exported.exit_code == 0, exported.output
    rows = list(csv.reader(io.StringIO(exported.stdout)))
    rows.insert(7, ["651", "main", "1", "", "", o, ""])
    path = tmp_path / "spur.csv"
    with path.open("w", newline="") as file:
        csv.writer(file).writerows(rows)
    return path


def test_a_row_building_a_lineage_line_is_named_by_lint_and_blocks_the_release(run, tmp_path):
    """Storing refuses every program of such a template ("engine lint names it"): lint must name
    the row, and the release gate must not hand the shop floor a template that makes no program."""
    path = _spur_with_row(run, tmp_path, '"; PROG" + "RAM 1 TEMPLATE spur v9"')
    assert run("template", "import", "--class", "spur", str(path)).exit_code == 0
    lint = run("lint")
    assert lint.exit_code == 1 and "651" in lint.output, lint.output
    release = run("template", "release", "--class", "spur", "--yes")
    assert release.exit_code == 1, release.output


def _import_nc(run, tmp_path, line: str, name: str):
    program = tmp_path / "P.MPF"
    program.write_text(f"%_N_P_MPF\n; TEMPLATE x v1\n{line}\nG0 X10\nM30\n")
    return run("import-nc", "--class", name, "--parent", "cylindrical", str(program))


def test_a_plain_comment_about_a_program_and_its_template_is_not_a_lineage_line(run, tmp_path):
    """The lineage line names a program id (or DRY-RUN); a shop's comment does not."""
    result = _import_nc(run, tmp_path, "; program from template of spur", "adv_comment")
    assert result.exit_code == 0, result.output


def test_a_block_numbered_lineage_line_is_refused_too(run, tmp_path):
    """`N10 ; PROGRAM 1 TEMPLATE …` reads at the machine as a second lineage line."""
    result = _import_nc(run, tmp_path, "N10 ; PROGRAM 1 TEMPLATE spur v1 deadbeef INPUT deadbeef", "adv_numbered")
    assert result.exit_code == 1, result.output
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT count(*) FROM gear_class WHERE name = 'adv_numbered'").fetchone()[0] == 0


def test_instantiate_gear_0_names_the_gear(run):
    """--gear 0 was given: the message must not say none was."""
    result = run("instantiate", "--gear", 0, "--dry-run")
    assert result.exit_code == 1
    assert "give exactly one of" not in result.stderr and "0" in result.stderr, result.stderr
