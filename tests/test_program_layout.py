"""Every program of a class is written with its class's layout (issue 17): the line ending and
final newline of gear_class, which import-nc takes from the imported file. The .MPF files of
`instantiate` (one program, batches of gears and of jobs), what it prints (also a dry run, and its
--json text) and `programs show` give the stored lines joined that way; a line ending the config
file sets for a machine replaces only the line ending of that machine's files; a template's CSV
carries the layout from one database (or class) to another. The expected bytes are the stored
lines read by SQL, joined here."""
from __future__ import annotations

import csv
import io
import json
import re

import psycopg
import pytest

from engine.release.gate import release

CRLF, LF = "\r\n", "\n"



def set_layout(url: str, gear_class: str, ending: str, final_newline: bool) -> None:
    """The class's layout changed (a new draft version: version_layout_change) and released, as an editor
    and a releaser do: runners' programs are written with it from then on."""
    with psycopg.connect(url) as conn:
        conn.execute("UPDATE gear_class SET line_ending = %s, final_newline = %s WHERE name = %s",
                     (ending, final_newline, gear_class))
    with psycopg.connect(url) as conn:
        release(conn, gear_class)


def stored(url: str, program_id: int) -> list[str]:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT lines FROM program WHERE id = %s", (program_id,)).fetchone()[0]


def joined(lines: list[str], ending: str, final_newline: bool) -> bytes:
    return (ending.join(lines) + (ending if final_newline else "")).encode("ascii")


def made(result) -> dict:
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_a_crlf_class_without_final_newline_writes_its_file_so(run, tmp_path):
    set_layout(run.url, "spur", CRLF, False)
    target = tmp_path / "GEAR42.MPF"
    program = made(run("instantiate", "--gear", 42, "--out", target, "--json"))
    lines = stored(run.url, program["program_id"])
    assert target.read_bytes() == joined(lines, CRLF, False)
    assert not target.read_bytes().endswith(b"\n") and not any("\r" in line for line in lines)


def test_an_lf_class_is_written_as_before(run, tmp_path):
    target = tmp_path / "GEAR42.MPF"
    program = made(run("instantiate", "--gear", 42, "--out", target, "--json"))
    assert target.read_bytes() == joined(stored(run.url, program["program_id"]), LF, True)
    assert target.read_bytes().endswith(b"M30\n") and b"\r" not in target.read_bytes()


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_printed_program_and_programs_show_give_the_same_bytes(run):
    set_layout(run.url, "spur", CRLF, False)
    printed = run("instantiate", "--gear", 42)
    assert printed.exit_code == 0, printed.output
    program_id = int(re.search(r"program (\d+) ", printed.stderr).group(1))
    expected = joined(stored(run.url, program_id), CRLF, False)
    assert printed.stdout_bytes == expected
    shown = run("programs", "show", program_id)
    count = len(stored(run.url, program_id))
    assert shown.exit_code == 0 and shown.stdout_bytes.endswith(f"\nlines:         {count}\n".encode() + expected)
    assert "layout:        CRLF, no final newline" in shown.stdout
    record = made(run("programs", "show", program_id, "--json"))["programs"][0]
    assert (record["line_ending"], record["final_newline"]) == ("crlf", False)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_dry_run_prints_the_program_with_its_class_layout(run):
    set_layout(run.url, "spur", CRLF, False)
    program = made(run("instantiate", "--gear", 42, "--json"))
    # the dry run makes the same program; its lineage line says DRY-RUN where the stored one has the id
    lines = [line.replace(f"PROGRAM {program['program_id']} ", "PROGRAM DRY-RUN ")
             for line in stored(run.url, program["program_id"])]
    dry = run("instantiate", "--gear", 42, "--dry-run")
    assert dry.exit_code == 0 and dry.stdout_bytes == joined(lines, CRLF, False)
    text = made(run("instantiate", "--gear", 42, "--dry-run", "--json"))["text"]
    assert text.encode("ascii") == joined(lines, CRLF, False)


def batch_files(url: str, folder, layouts: dict) -> dict:
    """{file name: (its bytes, the stored lines of its program joined with its class's layout)}:
    the latest program of each name, as the batch wrote it."""
    with psycopg.connect(url) as conn:
        programs = conn.execute("SELECT DISTINCT ON (name) name, gear_class, lines FROM program "
                                "ORDER BY name, id DESC").fetchall()
    return {f"{name}.MPF": ((folder / f"{name}.MPF").read_bytes(), joined(lines, *layouts.get(gear_class, (LF, True))))
            for name, gear_class, lines in programs}


@pytest.mark.parametrize("workers", ["1", "2"])
def test_a_batch_writes_each_program_with_its_own_class_layout(run, tmp_path, workers):
    set_layout(run.url, "spur", CRLF, False)
    folder = tmp_path / "nc"
    batch = run("instantiate", "--gears", "42-47", "--workers", workers, "--out", folder, "--mkdir")
    assert batch.exit_code == 0, batch.output
    files = batch_files(run.url, folder, {"spur": (CRLF, False)})
    assert sorted(files) == sorted(path.name for path in folder.iterdir()) and len(files) == 6
    assert all(written == expected for written, expected in files.values())
    endings = {written.endswith(b"\n") for written, _ in files.values()}
    assert endings == {True, False}   # the helical gears' LF files and the spur gears' CRLF ones


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_stored_jobs_made_again_keep_their_class_layout(run, tmp_path):
    first = made(run("instantiate", "--gear", 42, "--json"))
    last = made(run("instantiate", "--gear", 43, "--json"))
    set_layout(run.url, "spur", CRLF, False)
    set_layout(run.url, "helical", CRLF, True)
    one = tmp_path / "one.MPF"
    again = made(run("instantiate", "--job", first["job_id"], "--out", one, "--json"))
    assert one.read_bytes() == joined(stored(run.url, again["program_id"]), CRLF, False)
    folder = tmp_path / "jobs"
    assert run("instantiate", "--jobs", f"{first['job_id']}-{last['job_id']}", "--out", folder,
               "--mkdir").exit_code == 0
    files = batch_files(run.url, folder, {"spur": (CRLF, False), "helical": (CRLF, True)})
    assert len(files) == 2 and all(written == expected for written, expected in files.values())


def test_a_machine_line_ending_of_the_config_file_replaces_only_the_ending(run, tmp_path):
    set_layout(run.url, "spur", CRLF, False)
    run.config.write_text('[machines.hobber-840d]\nline_endings = "lf"\n')
    target = tmp_path / "GEAR42.MPF"
    program = made(run("instantiate", "--gear", 42, "--out", target, "--json"))
    lines = stored(run.url, program["program_id"])
    assert target.read_bytes() == joined(lines, LF, False)   # the final newline stays the class's
    assert run("programs", "show", program["program_id"]).stdout_bytes.endswith(joined(lines, CRLF, False))


def test_another_machine_line_ending_leaves_the_class_layout(run, tmp_path):
    set_layout(run.url, "spur", CRLF, False)
    run.config.write_text('[machines.lathe-840d]\nline_endings = "lf"\n')
    target = tmp_path / "GEAR42.MPF"
    program = made(run("instantiate", "--gear", 42, "--out", target, "--json"))
    assert target.read_bytes() == joined(stored(run.url, program["program_id"]), CRLF, False)


def without_layout_columns(text: str) -> str:
    """The CSV as an export made before the layout columns (or a hand-written file) has it."""
    rows = list(csv.reader(io.StringIO(text, newline="")))
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows(row[:7] for row in rows)
    return buffer.getvalue()


def class_layout_stored(url: str, gear_class: str) -> tuple:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT line_ending, final_newline FROM gear_class WHERE name = %s",
                            (gear_class,)).fetchone()


def test_an_exported_template_carries_the_layout_into_another_class(run, tmp_path):
    set_layout(run.url, "spur", CRLF, False)
    exported = tmp_path / "spur.csv"
    assert run("template", "export", "--class", "spur", "--out", exported).exit_code == 0
    header, first = list(csv.reader(io.StringIO(exported.read_text(), newline="")))[:2]
    assert header[-2:] == ["line_ending", "final_newline"] and first[-2:] == ["crlf", "no"]
    imported = run("template", "import", "--class", "spur_copy", "--parent", "spur", exported)
    assert imported.exit_code == 0 and "CRLF, no final newline" in imported.stdout, imported.output
    assert class_layout_stored(run.url, "spur_copy") == (CRLF, False)
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE gear SET gear_class = 'spur_copy' WHERE id = 42")
    printed = run("instantiate", "--gear", 42, "--draft")   # a draft is printed, never written (issue 26)
    assert printed.exit_code == 0, printed.output
    program_id = int(re.search(r"program (\d+) \(job \d+, \d+ lines\) from spur_copy v", printed.stderr).group(1))
    assert printed.stdout_bytes == joined(stored(run.url, program_id), CRLF, False)


def test_a_csv_without_the_layout_columns_leaves_the_class_layout(run, tmp_path):
    set_layout(run.url, "spur", CRLF, False)
    exported = run("template", "export", "--class", "spur")
    old = tmp_path / "old.csv"
    old.write_text(without_layout_columns(exported.stdout))
    assert old.read_text().splitlines()[0] == "id,t,n,p_calc,s,o,p_emit"
    imported = run("template", "import", "--class", "spur", old)
    assert imported.exit_code == 0, imported.output
    assert class_layout_stored(run.url, "spur") == (CRLF, False)


def test_an_lf_class_exports_the_seven_columns_it_always_had(read_only_run):
    exported = read_only_run("template", "export", "--class", "spur").stdout
    assert exported.splitlines()[0] == "id,t,n,p_calc,s,o,p_emit"


def edited_layout(exported: str, cells: dict) -> str:
    """The CSV with the layout cells of each row replaced: cells[line number] or else cells[None]."""
    lines = exported.splitlines()
    assert all(line.endswith(",crlf,no") for line in lines[1:])   # no cell of the spur rows spans lines
    return "\n".join([lines[0]] + [line.removesuffix(",crlf,no") + cells.get(number, cells[None])
                                   for number, line in enumerate(lines[1:], start=2)]) + "\n"


def test_the_csv_can_make_a_class_lf_again_and_blank_cells_take_the_others(run, tmp_path):
    set_layout(run.url, "spur", CRLF, False)
    edited = tmp_path / "edited.csv"
    edited.write_text(edited_layout(run("template", "export", "--class", "spur").stdout, {None: ",lf,yes", 3: ",,"}))
    imported = run("template", "import", "--class", "spur", edited)
    assert imported.exit_code == 0 and "LF, final newline" in imported.stdout, imported.output
    assert class_layout_stored(run.url, "spur") == (LF, True)


def test_a_csv_giving_two_layouts_is_refused_naming_the_line(run, tmp_path):
    set_layout(run.url, "spur", CRLF, False)
    edited = tmp_path / "edited.csv"
    edited.write_text(edited_layout(run("template", "export", "--class", "spur").stdout,
                                    {None: ",lf,yes", 4: ",crlf,yes"}))
    refused = run("template", "import", "--class", "spur", edited)
    assert refused.exit_code == 1 and f"{edited}, line 4, column line_ending" in refused.stderr, refused.output
    assert class_layout_stored(run.url, "spur") == (CRLF, False)
