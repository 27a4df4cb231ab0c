"""Batches and dry runs (issue 16): a batch names every bad gear or job in one run and stores
nothing unless --skip-bad, which stores the good ones and lists the skipped; --dry-run computes
and checks as a stored run does and stores nothing at all; a batch shows a progress bar on a
terminal only."""
import json
import os
import pty
import subprocess
import sys
from pathlib import Path

import psycopg
import pytest
from helpers.batches import spoil
from helpers.roles import as_role
from psycopg import sql

from engine.programs.instantiate import instantiate_gear, instantiate_gears
from engine.programs.options import RunMode

CHECKOUT = Path(__file__).resolve().parent.parent

# Seeded gears made bad, each for another reason (the words a user reads in its line), and the
# gears of 42-54 that stay good. The tailstock of 45 mm is a machine record the simulation
# refuses for the gears whose root is too small for it to stay clear of the hob.
SPOILED = {
    42: "tailstock",                  # the simulation: the hob runs into the tailstock
    44: "no gear class",              # gear_class NULL
    45: "maximum module 4",           # module 5 on a hobber for module 4 at most
    46: "no hob has module 1.25",     # no hob in the library matches
    47: "computed root diameter",     # written in SQL without diameters, and too few teeth for a root
    50: "tailstock",
    51: "crowning 0.2 mm on a face of 4 mm",   # the crowning too steep for the face
}
GOOD = [43, 53, 54]


def everything(url: str) -> dict:
    """The row count of every table and the state of every sequence."""
    with psycopg.connect(url) as conn:
        tables = [name for name, in conn.execute(
            "SELECT table_name FROM information_schema.tables WHERE table_schema = 'public' "
            "AND table_type = 'BASE TABLE' ORDER BY table_name")]
        counts = {table: conn.execute(sql.SQL("SELECT count(*) FROM {}").format(sql.Identifier(table))).fetchone()[0]
                  for table in tables}
        sequences = conn.execute("SELECT sequencename, last_value FROM pg_sequences ORDER BY 1").fetchall()
    return {"tables": counts, "sequences": sequences}


def stored_gears(url: str) -> list[int]:
    with psycopg.connect(url) as conn:
        return [gear for gear, in conn.execute("SELECT j.gear_id FROM program p JOIN job j ON j.id = p.job_id "
                                                "ORDER BY j.gear_id")]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("workers", ["1", "2"])
def test_every_bad_gear_is_named_in_one_run_and_nothing_is_stored(run, tmp_path, workers):
    spoil(run.url)
    before = everything(run.url)
    refused = run("instantiate", "--gears", "42-54", "--workers", workers, "--out", tmp_path / "nc")
    assert refused.exit_code == 1 and "Traceback" not in refused.output
    lines = refused.stderr.splitlines()
    assert lines[0].startswith("error: 7 of 10 gears") and "nothing stored" in lines[0] and "--skip-bad" in lines[0]
    named = {int(line.split()[1].rstrip(":")): line for line in lines[1:]}
    assert sorted(named) == sorted(SPOILED)              # each bad gear once, on its own line, in gear order
    assert [int(line.split()[1].rstrip(":")) for line in lines[1:]] == sorted(SPOILED)
    for gear, reason in SPOILED.items():
        assert reason in named[gear], named[gear]
    assert everything(run.url) == before and not (tmp_path / "nc").exists()


@pytest.mark.parametrize("workers", ["1", "2"])
def test_skip_bad_stores_the_good_gears_and_lists_the_skipped(run, tmp_path, workers):
    spoil(run.url)
    made = run("instantiate", "--gears", "42-54", "--skip-bad", "--workers", workers, "--out", tmp_path)
    assert made.exit_code == 0, made.output
    assert stored_gears(run.url) == GOOD
    assert sorted(path.name for path in tmp_path.iterdir()) == [f"GEAR{gear}.MPF" for gear in GOOD]
    skipped = [line for line in made.stderr.splitlines() if line.startswith("skipped: gear ")]
    assert [int(line.split()[2].rstrip(":")) for line in skipped] == sorted(SPOILED)
    assert all(SPOILED[int(line.split()[2].rstrip(":"))] in line for line in skipped)
    assert "skipped 7 bad of 10" in made.stdout and "stored 3 program(s)" in made.stdout   # the summary line


def test_skip_bad_in_json_lists_the_skipped_gears(run):
    spoil(run.url)
    made = run("instantiate", "--all", "--skip-bad", "--json")
    assert made.exit_code == 0, made.output
    report = json.loads(made.stdout)
    assert report["programs"] == len(GOOD) and report["dry_run"] is False
    assert [int(reason.split()[1].rstrip(":")) for reason in report["skipped"]] == sorted(SPOILED)


def test_skip_bad_with_every_gear_bad_stores_nothing_and_exits_1(run):
    spoil(run.url)
    before = everything(run.url)
    refused = run("instantiate", "--gears", "44-46", "--skip-bad")
    assert refused.exit_code == 1 and refused.stderr.count("\n  gear ") == 3
    assert everything(run.url) == before


def test_every_bad_job_is_named_and_skip_bad_makes_the_others(run):
    assert run("instantiate", "--gears", "42-47").exit_code == 0
    with psycopg.connect(run.url) as conn:
        jobs = [job for job, in conn.execute("SELECT id FROM job ORDER BY id")]
        conn.execute("UPDATE job SET params = params - 'z2' WHERE id = %s", (jobs[1],))
        conn.execute("UPDATE job SET params = jsonb_set(params, '{program_name}', '\"GEAR42\"') WHERE id = %s",
                     (jobs[3],))
    before = everything(run.url)
    refused = run("instantiate", "--jobs", f"{jobs[0]}-{jobs[-1]}")
    assert refused.exit_code == 1 and refused.stderr.startswith(f"error: 2 of {len(jobs)} jobs")
    assert f"\n  job {jobs[1]}: " in refused.stderr and "unknown parameter 'z2'" in refused.stderr
    assert f"\n  job {jobs[3]}: program name 'GEAR42'" in refused.stderr
    assert everything(run.url) == before
    made = run("instantiate", "--jobs", f"{jobs[0]}-{jobs[-1]}", "--skip-bad", "--json")
    assert made.exit_code == 0, made.output
    assert json.loads(made.stdout)["programs"] == len(jobs) - 2
    with psycopg.connect(run.url) as conn:
        remade = [job for job, in conn.execute("SELECT job_id FROM program ORDER BY id")][len(jobs):]
    assert remade == [job for job in jobs if job not in (jobs[1], jobs[3])]


def test_skip_bad_is_for_batches(read_only_run):
    refused = read_only_run("instantiate", "--gear", "42", "--skip-bad")
    assert refused.exit_code == 1 and "--skip-bad" in refused.stderr and "--gears" in refused.stderr


# --dry-run ------------------------------------------------------------------------------------

def lineage(lines: list[str]) -> tuple[list[str], list[str]]:
    """(the program's lines without its lineage line, the lineage line(s))."""
    found = [line for line in lines if line.startswith("; PROGRAM ")]
    return [line for line in lines if line not in found], found


def test_a_dry_run_stores_nothing_and_prints_the_program_a_run_then_stores(run, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = everything(run.url)
    dry = run("instantiate", "--gear", "42", "--dry-run")
    assert dry.exit_code == 0, dry.output
    assert everything(run.url) == before and list(tmp_path.iterdir()) == []   # no row, no sequence step, no file
    assert "nothing stored" in dry.stderr
    stored = json.loads(run("instantiate", "--gear", "42", "--json").stdout)
    with psycopg.connect(run.url) as conn:
        lines = conn.execute("SELECT lines FROM program WHERE id = %s", (stored["program_id"],)).fetchone()[0]
    dry_body, dry_lineage = lineage(dry.stdout.splitlines())
    body, stored_lineage = lineage(lines)
    assert dry_body == body and len(stored_lineage) == 1
    # the same template, version and input hash; DRY-RUN where the stored one has its id
    assert dry_lineage == [stored_lineage[0].replace(f"PROGRAM {stored['program_id']} ", "PROGRAM DRY-RUN ")]


def test_a_dry_run_of_a_stored_job_prints_the_program_a_run_then_stores(run):
    made = json.loads(run("instantiate", "--gear", "43", "--json").stdout)
    with psycopg.connect(run.url) as conn:   # edited in SQL, as a runner does
        conn.execute("UPDATE job SET params = jsonb_set(params, '{coolant}', 'false') WHERE id = %s",
                     (made["job_id"],))
    before = everything(run.url)
    dry = run("instantiate", "--job", made["job_id"], "--dry-run", "--json")
    assert dry.exit_code == 0, dry.output
    assert everything(run.url) == before
    report = json.loads(dry.stdout)
    assert report["dry_run"] is True and report["program_id"] is None and report["job_id"] == made["job_id"]
    again = json.loads(run("instantiate", "--job", made["job_id"], "--json").stdout)
    with psycopg.connect(run.url) as conn:
        lines = conn.execute("SELECT lines FROM program WHERE id = %s", (again["program_id"],)).fetchone()[0]
    assert report["text"].splitlines() == [line.replace(f"PROGRAM {again['program_id']} ", "PROGRAM DRY-RUN ")
                                           for line in lines]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("batch", [("--gears", "42-54"), ("--all",), ("--gears", "42-54", "--workers", "2")])
def test_a_dry_run_of_a_batch_reports_what_a_run_then_stores(run, batch):
    before = everything(run.url)
    dry = run("instantiate", *batch, "--dry-run", "--json")
    assert dry.exit_code == 0, dry.output
    assert everything(run.url) == before
    would = json.loads(dry.stdout)
    stored = json.loads(run("instantiate", *batch, "--json").stdout)
    assert would["dry_run"] is True and would["program_ids"] == [None, None]
    assert (would["programs"], would["lines"]) == (stored["programs"], stored["lines"]) == (10, would["lines"])


def test_a_dry_run_of_stored_jobs_reports_what_a_run_then_stores(run):
    assert run("instantiate", "--gears", "42-47").exit_code == 0
    with psycopg.connect(run.url) as conn:
        first, last = conn.execute("SELECT min(id), max(id) FROM job").fetchone()
    before = everything(run.url)
    dry = run("instantiate", "--jobs", f"{first}-{last}", "--dry-run")
    assert dry.exit_code == 0, dry.output
    assert everything(run.url) == before
    stored = json.loads(run("instantiate", "--jobs", f"{first}-{last}", "--json").stdout)
    assert f"would store {stored['programs']} program(s), {stored['lines']} lines" in dry.stdout


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_dry_run_of_a_batch_with_bad_gears_names_them_and_skip_bad_reports_the_rest(run):
    spoil(run.url)
    before = everything(run.url)
    refused = run("instantiate", "--gears", "42-54", "--dry-run")
    assert refused.exit_code == 1 and refused.stderr.count("\n  gear ") == len(SPOILED)
    would = run("instantiate", "--gears", "42-54", "--dry-run", "--skip-bad", "--json")
    assert would.exit_code == 0 and json.loads(would.stdout)["programs"] == len(GOOD)
    assert len(json.loads(would.stdout)["skipped"]) == len(SPOILED)
    assert everything(run.url) == before


@pytest.mark.parametrize("target", [("--gear", "42"), ("--gears", "42-43")])
def test_a_dry_run_writes_no_file_and_says_so_for_out(read_only_run, tmp_path, target):
    before = everything(read_only_run.url)
    refused = read_only_run("instantiate", *target, "--dry-run", "--out", tmp_path / "nc")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert "--dry-run" in refused.stderr and "--out" in refused.stderr
    assert everything(read_only_run.url) == before and not (tmp_path / "nc").exists()


def test_the_database_refuses_a_dry_run_lineage_line(run):
    """The text a dry run prints can never become a stored program: the lineage check refuses it."""
    made = json.loads(run("instantiate", "--gear", "42", "--json").stdout)
    with psycopg.connect(run.url) as conn:
        job, gear_class, version, template_hash, name, lines, row_ids = conn.execute(
            "SELECT job_id, gear_class, template_version, template_hash, name, lines, row_ids FROM program "
            "WHERE id = %s", (made["program_id"],)).fetchone()
        dry = [line.replace(f"PROGRAM {made['program_id']} ", "PROGRAM DRY-RUN ") for line in lines]
        with pytest.raises(psycopg.Error, match="lineage line"):
            conn.execute("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, "
                         "name, lines, row_ids, trace) VALUES (nextval('program_id_seq'), %s, %s, %s, %s, %s, %s, "
                         "%s, '{}')", (job, gear_class, version, template_hash, name, dry, row_ids))


def test_a_reader_may_look_at_a_program_that_only_a_runner_may_store(conn):
    """A dry run writes nothing, so the role that only reads (engine_reader) may make one; the
    stored run is the database's to refuse it. Inside the caller's transaction it is a savepoint."""
    with as_role(conn, "engine_reader"):
        program = instantiate_gear(conn, 42, mode=RunMode(dry_run=True))
        batch = instantiate_gears(conn, 42, 47, mode=RunMode(dry_run=True))
    assert program.program_id is None and program.name == "GEAR42"
    assert sum(line.startswith("; PROGRAM DRY-RUN TEMPLATE spur v") for line in program.lines) == 1
    assert batch.dry_run and batch.programs == 6 and batch.first_program_id is None
    with as_role(conn, "engine_reader"), pytest.raises(psycopg.errors.InsufficientPrivilege):
        instantiate_gear(conn, 42)


# the progress bar --------------------------------------------------------------------------

def stderr_of(url: str, *args: str, terminal: bool) -> str:
    """The CLI's stderr, written to a terminal (a pseudo-terminal) or to a pipe."""
    command = [sys.executable, "-m", "engine", "--database-url", url, *args]
    environment = {**os.environ, "PYTHONPATH": str(CHECKOUT), "COLUMNS": "100"}
    if not terminal:
        return subprocess.run(command, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                              text=True, check=True).stderr
    leader, follower = pty.openpty()
    with subprocess.Popen(command, env=environment, stdout=subprocess.DEVNULL, stderr=follower) as process:
        os.close(follower)
        written = b""
        while True:
            try:
                chunk = os.read(leader, 4096)
            except OSError:   # the terminal closed: the process ended
                break
            if not chunk:
                break
            written += chunk
        assert process.wait() == 0
    os.close(leader)
    return written.decode(errors="replace")


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_batch_shows_a_progress_bar_on_a_terminal_only(read_only_run):
    on_terminal = stderr_of(read_only_run.url, "instantiate", "--gears", "42-54", "--dry-run", terminal=True)
    assert "planning" in on_terminal and "100%" in on_terminal
    in_pipe = stderr_of(read_only_run.url, "instantiate", "--gears", "42-54", "--dry-run", terminal=False)
    assert "planning" not in in_pipe and "100%" not in in_pipe


def test_instantiate_help_has_an_example(read_only_run):
    shown = read_only_run("instantiate", "--help")
    assert shown.exit_code == 0
    assert any(line.strip().startswith("Example: engine instantiate ") for line in shown.stdout.splitlines())
    assert "--dry-run" in shown.stdout and "--skip-bad" in shown.stdout
