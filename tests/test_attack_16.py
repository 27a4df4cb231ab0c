"""Attacks on the promises of issue 16 (adversary review): each test states the behaviour a
user relies on, and fails while the engine breaks it."""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import psycopg
import pytest

from test_operate import Engine

OUT_OF_RANGE_FILTERS = (   # a filter id beyond PostgreSQL's integer/bigint: bad input, not a bug
    ("jobs", "list", "--gear", "99999999999"),
    ("programs", "list", "--gear", "99999999999"),
    ("programs", "list", "--job", "99999999999999999999"),
)


@pytest.mark.parametrize("args", OUT_OF_RANGE_FILTERS, ids=" ".join)
def test_a_filter_id_out_of_range_is_bad_input_not_a_bug(run, args):
    result = run(*args)
    assert result.exit_code == 1, result.output
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1
    assert args[-1] in result.stderr


def test_the_text_of_a_dry_run_is_never_stored_as_a_program(run, tmp_path):
    """import-nc of a dry run's printout must not carry its `; PROGRAM DRY-RUN …` line into a
    template, from which every program of the class would then store it."""
    dry = run("instantiate", "--gear", 42, "--dry-run")
    assert dry.exit_code == 0, dry.output
    printed = tmp_path / "GEAR42.MPF"
    printed.write_text(dry.stdout)
    assert "; PROGRAM DRY-RUN" in dry.stdout
    run("import-nc", "--class", "spur", str(printed))
    run("instantiate", "--gear", 42, "--draft")
    with psycopg.connect(run.url) as conn:
        stored = conn.execute("SELECT count(*) FROM program WHERE array_to_string(lines, E'\\n') "
                              "LIKE '%PROGRAM DRY-RUN%'").fetchone()[0]
    assert stored == 0


def test_a_stored_programs_lineage_line_is_not_copied_into_a_template(run, tmp_path):
    """A second lineage line naming another program id and template version would lie to
    whoever reads the program at the machine."""
    real = run("instantiate", "--gear", 42)
    assert real.exit_code == 0, real.output
    printed = tmp_path / "GEAR42.MPF"
    printed.write_text(real.stdout)
    run("import-nc", "--class", "spur", str(printed))
    again = run("instantiate", "--gear", 42, "--draft")
    if again.exit_code == 0:
        assert sum(line.startswith("; PROGRAM ") for line in again.stdout.splitlines()) == 1


@pytest.fixture
def engine():
    folder = Path(tempfile.mkdtemp(prefix="engine-attack16-"))
    runner = Engine(folder)
    yield runner
    runner("db", "stop")
    shutil.rmtree(folder, ignore_errors=True)


def test_demo_ignores_pghostaddr_it_runs_on_the_embedded_server(engine):
    """PGHOSTADDR (libpq's address of the shop's server) must not steer the demo's connection:
    with it, libpq connected the embedded URL to the shop's server (and seeded it)."""
    demo = engine("demo", PGHOSTADDR="192.0.2.1", PGCONNECT_TIMEOUT="3")
    assert demo.returncode == 0, demo.stderr
    assert demo.stdout.rstrip().endswith("M30")


def test_an_embedded_data_folder_that_cannot_be_used_is_one_line(engine):
    engine.data_dir.mkdir()
    (engine.data_dir / "notes.txt").write_text("a shop's file, not a database\n")
    shown = engine("db", "url")
    assert shown.returncode == 1
    assert shown.stderr.startswith("error: ") and shown.stderr.count("\n") == 1, shown.stderr
