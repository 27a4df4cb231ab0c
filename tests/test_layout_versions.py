"""The line layout of a class (line ending, final newline; issue 17) is part of its template and
travels with its versions (template_version_rows): an editor's change of it is a new draft version, the
released version keeps the layout it was released with until a releaser releases the draft, and
history, diff and restore treat it as they treat rows. The expected bytes are the stored lines
read by SQL, joined here."""
from __future__ import annotations

import csv
import io
import json
import re

import psycopg
import pytest
from helpers.roles import logins

CRLF, LF = "\r\n", "\n"



@pytest.fixture
def login_in(server_url):
    with logins(server_url) as create:
        yield create


def made(result) -> dict:
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def stored(url: str, program_id: int) -> list[str]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT lines FROM program WHERE id = %s", (program_id,)).fetchone()[0]


def joined(lines: list[str], ending: str, final_newline: bool) -> bytes:
    return (ending.join(lines) + (ending if final_newline else "")).encode("ascii")


def with_layout(exported: str, ending: str, final_newline: str) -> str:
    """The exported CSV with the layout columns on every row (the rows unchanged)."""
    rows = list(csv.reader(io.StringIO(exported, newline="")))
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows([rows[0] + ["line_ending", "final_newline"]]
                                                      + [row + [ending, final_newline] for row in rows[1:]])
    return buffer.getvalue()


def crlf_draft(run, tmp_path) -> None:
    """spur's rows as released, imported with the layout CR LF and no final newline."""
    edited = tmp_path / "spur.csv"
    edited.write_text(with_layout(run("template", "export", "--class", "spur").stdout, "crlf", "no"))
    imported = run("template", "import", "--class", "spur", edited)
    assert imported.exit_code == 0, imported.output
    assert "layout changed (identical rows)" in imported.stdout and "version 2" in imported.stdout


def written(run, tmp_path, *options) -> tuple[dict, bytes]:
    target = tmp_path / f"GEAR42_{len(list(tmp_path.iterdir()))}.MPF"
    program = made(run("instantiate", "--gear", 42, *options, "--out", target, "--json"))
    return program, target.read_bytes()


def printed_draft(run) -> tuple[dict, bytes]:
    """The editor's draft program as printed (a draft is never written to a file, issue 26): its
    record's id and version, and the bytes, in the class's layout as a file would have them."""
    result = run("instantiate", "--gear", 42, "--draft")
    assert result.exit_code == 0, result.output
    program_id, version = re.search(r"program (\d+) \(job \d+, \d+ lines\) from spur v(\d+)", result.stderr).groups()
    return {"program_id": int(program_id), "template_version": int(version)}, result.stdout_bytes


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_layout_change_is_a_draft_until_it_is_released(run, tmp_path):
    crlf_draft(run, tmp_path)
    runner, runners_file = written(run, tmp_path)
    assert runner["template_version"] == 1
    assert runners_file == joined(stored(run.url, runner["program_id"]), LF, True)
    editor, editors_file = printed_draft(run)
    assert editor["template_version"] == 2
    assert editors_file == joined(stored(run.url, editor["program_id"]), CRLF, False)
    released = run("template", "release", "--class", "spur", "--yes")
    assert released.exit_code == 0, released.output
    after, file_after = written(run, tmp_path)
    assert after["template_version"] == 2
    assert file_after == joined(stored(run.url, after["program_id"]), CRLF, False)


def test_programs_show_keeps_the_layout_of_the_version_a_program_was_made_from(run, tmp_path):
    before, file_before = written(run, tmp_path)
    crlf_draft(run, tmp_path)
    assert run("template", "release", "--class", "spur", "--yes").exit_code == 0
    shown = run("programs", "show", before["program_id"])
    assert shown.exit_code == 0 and shown.stdout_bytes.endswith(file_before), shown.output
    record = made(run("programs", "show", before["program_id"], "--json"))["programs"][0]
    assert (record["line_ending"], record["final_newline"]) == ("lf", True)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_history_diff_and_restore_carry_the_layout(run, tmp_path):
    crlf_draft(run, tmp_path)
    versions = made(run("template", "history", "--class", "spur", "--json"))["versions"]
    assert [(v["version"], v["line_ending"], v["final_newline"]) for v in versions] == \
        [(1, "lf", True), (2, "crlf", False)]
    history = run("template", "history", "--class", "spur").stdout.splitlines()
    assert history[-1].startswith("v2") and history[-1].endswith("layout CRLF, no final newline")
    diff = run("template", "diff", "--class", "spur", "--from", 1, "--to", 2)
    assert diff.stdout == "~ layout: LF, final newline -> CRLF, no final newline\n", diff.output
    assert made(run("template", "diff", "--class", "spur", "--from", 1, "--to", 2, "--json"))["changes"] == []
    restored = run("template", "restore", "--class", "spur", "--version", 1)
    assert restored.exit_code == 0 and "restored version 1 as version 3" in restored.stdout, restored.output
    editor, editors_file = printed_draft(run)
    assert editor["template_version"] == 3
    assert editors_file == joined(stored(run.url, editor["program_id"]), LF, True)


def test_an_editor_changing_the_layout_makes_a_draft_and_the_released_version_keeps_its_own(
        run, login_in):
    editor = login_in("engine_editor")
    with psycopg.connect(editor.url(run.url)) as conn:
        conn.execute("SET ROLE engine_editor")
        conn.execute("UPDATE gear_class SET line_ending = %s, final_newline = false WHERE name = 'spur'", (CRLF,))
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT template_version, released_version(name) FROM gear_class "
                            "WHERE name = 'spur'").fetchone() == (2, 1)
        assert conn.execute("SELECT version, line_ending, final_newline FROM template_version_rows "
                            "WHERE gear_class = 'spur' ORDER BY version").fetchall() == \
            [(1, LF, True), (2, CRLF, False)]


def test_a_layout_and_rows_changed_in_one_import_are_one_version(run, tmp_path):
    exported = run("template", "export", "--class", "spur").stdout
    edited = tmp_path / "spur.csv"
    edited.write_text(with_layout(exported, "crlf", "yes").replace('"M30"', '"M30 ; END"', 1))
    imported = run("template", "import", "--class", "spur", edited)
    assert imported.exit_code == 0 and "replaced" in imported.stdout and "version 2" in imported.stdout, \
        imported.output


def test_a_re_import_of_the_file_with_other_line_endings_is_a_new_version(run, tmp_path):
    lf_file, crlf_file = tmp_path / "lf.nc", tmp_path / "crlf.nc"
    lf_file.write_bytes(b"G0 X10\nM30\n")
    crlf_file.write_bytes(b"G0 X10\r\nM30\r\n")
    first = run("import-nc", lf_file, "--class", "nc_relaid", "--json")
    assert first.exit_code == 0, first.output
    again = run("import-nc", crlf_file, "--class", "nc_relaid", "--json")
    assert again.exit_code == 0, again.output
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT version, line_ending FROM template_version_rows WHERE gear_class = 'nc_relaid' "
                            "ORDER BY version").fetchall() == [(1, LF), (2, CRLF)]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_release_that_changes_only_the_layout_says_every_program_file_of_the_class_changes(run, tmp_path):
    written(run, tmp_path)
    written(run, tmp_path)
    with psycopg.connect(run.url) as conn:
        programs = conn.execute("SELECT count(DISTINCT p.job_id) FROM program p JOIN job j ON j.id = p.job_id "
                                "WHERE j.gear_class = 'spur'").fetchone()[0]
    assert programs >= 1
    crlf_draft(run, tmp_path)
    shown = run("template", "release", "--class", "spur", "--dry-run")
    assert shown.exit_code == 0, shown.output
    assert "0 program(s) change" in shown.stdout   # no line changes ...
    assert (f"layout of spur: LF, final newline → CRLF, no final newline: the files of all {programs} stored "
            "program(s) change bytes") in shown.stdout.splitlines()   # ... but every file's bytes do
    impact = made(run("template", "release", "--class", "spur", "--dry-run", "--json"))["impact"]
    assert impact["layout"] == [{"class": "spur", "from": {"line_ending": "lf", "final_newline": True},
                                 "to": {"line_ending": "crlf", "final_newline": False}, "programs": programs}]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_release_of_rows_alone_names_no_layout_change(run, tmp_path):
    written(run, tmp_path)
    edited = tmp_path / "spur.csv"
    edited.write_text(run("template", "export", "--class", "spur").stdout.replace('"M9"', '"M9 ; COOLANT OFF"'))
    assert run("template", "import", "--class", "spur", edited).exit_code == 0
    impact = made(run("template", "release", "--class", "spur", "--dry-run", "--json"))["impact"]
    assert impact["layout"] == [] and impact["jobs"] >= 1
    assert "layout of" not in run("template", "release", "--class", "spur", "--dry-run").stdout


def with_layout_columns(exported: str, ending: str, final_newline: str) -> str:
    """The exported CSV with the two layout columns added to every row (rows unchanged)."""
    rows = list(csv.reader(io.StringIO(exported, newline="")))
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(rows[0] + ["line_ending", "final_newline"])
    writer.writerows(row + [ending, final_newline] for row in rows[1:])
    return buffer.getvalue()


def test_a_csv_import_does_not_change_the_bytes_of_released_programs_without_a_release(run, tmp_path):
    """`template import` is a draft until a releaser releases it (engine_releaser, not the
    editor). A CSV with the very rows of the released version and the layout columns crlf,no
    says 'unchanged (identical rows)', makes no version, and yet every released program of the
    class is from then on written CR LF without a final newline: the bytes that reach the
    machine changed with nobody releasing anything."""
    before = tmp_path / "before.MPF"
    made(run("instantiate", "--gear", 42, "--out", before, "--json"))
    edited = tmp_path / "spur.csv"
    edited.write_text(with_layout_columns(run("template", "export", "--class", "spur").stdout, "crlf", "no"))
    imported = run("template", "import", "--class", "spur", edited)
    assert imported.exit_code == 0, imported.output
    after = tmp_path / "after.MPF"
    program = made(run("instantiate", "--gear", 42, "--out", after, "--json"))   # released, not --draft
    assert program["template_version"] == 1
    assert b"\r" not in after.read_bytes() and after.read_bytes().endswith(b"\n")


def test_programs_show_gives_the_bytes_its_file_was_written_with(run, tmp_path):
    """A stored program is a record nobody rewrites: `programs show` joins its lines with the
    class's layout of today, so after an editor changes the class's layout (one UPDATE, granted
    to engine_editor) the program shows CR LF without a final newline, while the file the
    control holds, written when it was stored, is LF with one."""
    target = tmp_path / "GEAR42.MPF"
    program = made(run("instantiate", "--gear", 42, "--out", target, "--json"))
    written = target.read_bytes()
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE gear_class SET line_ending = %s, final_newline = false WHERE name = 'spur'", (CRLF,))
    shown = run("programs", "show", program["program_id"])
    assert shown.exit_code == 0, shown.output
    assert shown.stdout_bytes.endswith(written)
    record = made(run("programs", "show", program["program_id"], "--json"))["programs"][0]
    assert (record["line_ending"], record["final_newline"]) == ("lf", True)
