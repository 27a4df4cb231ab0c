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


def add_spur_row(url: str, o: str) -> None:
    """An editor's row added in SQL (template_view), where no import checks it."""
    with psycopg.connect(url) as conn:
        conn.execute("INSERT INTO template_view (gear_class, id, t, n, o) VALUES ('spur', 651, 'main', 1, %s)", (o,))


def test_a_row_building_a_lineage_line_is_named_by_lint_and_blocks_the_release(run, tmp_path):
    """Storing refuses every program of such a template: the import refuses the row, lint names
    it when it came in by SQL, and the release gate does not hand the shop floor a template
    that makes no program."""
    built = '"; PROG" + "RAM 1 TEMPLATE spur v9"'
    imported = run("template", "import", "--class", "spur", str(_spur_with_row(run, tmp_path, built)))
    assert imported.exit_code == 1 and "row 651" in imported.stderr, imported.output
    add_spur_row(run.url, built)
    lint = run("lint")
    assert lint.exit_code == 1 and "651" in lint.output, lint.output
    release = run("template", "release", "--class", "spur", "--yes")
    assert release.exit_code == 1, release.output


def test_a_row_computing_a_lineage_line_from_its_inputs_blocks_the_release(run):
    """What lint cannot read (text computed from the gear at run time) is refused where every
    program is made, so the golden tests fail and the gate refuses; a dry run refuses too."""
    add_spur_row(run.url, '"; PROGRAM " + str(z2) + " TEMPLATE spur v9"')
    release = run("template", "release", "--class", "spur", "--yes")
    assert release.exit_code == 1, release.output
    dry_run = run("instantiate", "--gear", 42, "--draft", "--dry-run")
    assert dry_run.exit_code == 1 and "reads as a lineage line" in dry_run.stderr, dry_run.output


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
