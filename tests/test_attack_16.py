"""Attacks on the promises of issue 16 (adversary review): each test states the behaviour a
user relies on, and fails while the engine breaks it."""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import psycopg
import pytest
from test_operate import Engine, user_tables

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


def test_a_gear_deleted_while_its_program_is_made_is_bad_input_not_a_bug(fresh_database_url):
    """`engine gears delete 91501 --yes` committing while `instantiate --gear 91501` plans: the
    gear is gone, which is said in one line (exit 1), not ForeignKeyViolation with exit 2."""
    import os
    import subprocess
    import sys
    import time

    url = fresh_database_url
    with psycopg.connect(url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material, hardness, "
                     "quality_grade, quantity) VALUES (91501, 'spur', 2, 31, 0, 20, '40Cr', 250, 7, 50)")
    deleter = psycopg.connect(url)
    deleter.execute("DELETE FROM gear WHERE id = 91501")   # the delete, not yet committed
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).resolve().parent.parent),
                                                        os.environ.get("PYTHONPATH", "")]), "ENGINE_CONFIG": ""}
    making = subprocess.Popen([sys.executable, "-m", "engine", "--database-url", url, "instantiate", "--gear",
                               "91501"], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    with psycopg.connect(url, autocommit=True) as watcher:
        while making.poll() is None and not watcher.execute(
                "SELECT count(*) FROM pg_stat_activity WHERE datname = current_database() "
                "AND wait_event_type = 'Lock'").fetchone()[0]:
            time.sleep(0.05)   # until instantiate waits for the delete's transaction
    deleter.commit()
    deleter.close()
    stdout, stderr = making.communicate(timeout=120)
    assert making.returncode == 1, stderr
    assert stderr.startswith("error: ") and stderr.count("\n") == 1 and "91501" in stderr


def invoke_with(url: str, env: dict, *args):
    """The CLI in-process with the environment variables given (and no config file)."""
    from click.testing import CliRunner

    from engine.cli.app import main

    return CliRunner().invoke(main, ["--database-url", url, *map(str, args)], env={"ENGINE_CONFIG": "", **env})


@pytest.mark.parametrize("variable", ["ENGINE_INSTANTIATE_SKIP_BAD", "ENGINE_INSTANTIATE_WORKERS"])
def test_a_batch_default_from_the_environment_does_not_refuse_one_gear(fresh_database_url, variable):
    """A shop sets its batches' habit once (README: Configuration); `instantiate --gear 42`, on
    which the user gave no batch option, must still make the program."""
    value = "4" if variable.endswith("WORKERS") else "1"
    result = invoke_with(fresh_database_url, {variable: value}, "instantiate", "--gear", 42)
    assert result.exit_code == 0, result.output
    assert result.stdout.rstrip().endswith("M30")


def test_a_delete_is_confirmed_on_the_command_line_only(fresh_database_url):
    """README: a delete without --yes says what it would delete and exits 1. An environment
    variable (or a config file's [gears.delete] yes = true) must not confirm every delete."""
    with psycopg.connect(fresh_database_url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width) "
                     "VALUES (91502, 'spur', 2, 33, 0, 20)")
    result = invoke_with(fresh_database_url, {"ENGINE_GEARS_DELETE_YES": "1"}, "gears", "delete", 91502)
    assert result.exit_code == 1, result.output
    with psycopg.connect(fresh_database_url) as conn:
        assert conn.execute("SELECT count(*) FROM gear WHERE id = 91502").fetchone()[0] == 1


def test_the_samples_do_not_hang_golden_tests_on_a_shops_own_gear(empty_database_url):
    """A shop's own gear 42 (m3 z33), then `engine seed --samples`: the sample golden tests of
    gear 42 (m2 z19) must not be attached to the shop's gear (which then can never be deleted)."""
    for args in (("db", "migrate"), ("seed",)):
        assert invoke_with(empty_database_url, {}, *args).exit_code == 0
    with psycopg.connect(empty_database_url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material) "
                     "VALUES (42, 'spur', 3, 33, 0, 20, 'C45')")
    seeded = invoke_with(empty_database_url, {}, "seed", "--samples")
    with psycopg.connect(empty_database_url) as conn:
        attached = conn.execute("SELECT count(*) FROM template_test WHERE gear_id = 42").fetchone()[0]
    assert seeded.exit_code == 1 or attached == 0, seeded.output


def test_demo_leaves_a_shop_database_on_the_embedded_server_untouched(engine):
    """Without a URL the embedded server is the shop's database (README: Operating the embedded
    server). `engine demo` must not seed the samples into it, nor store a job and a program (a
    record nobody deletes) for the shop's own gear 42."""
    for args in (("db", "migrate"), ("seed",)):
        assert engine(*args).returncode == 0
    url = engine("db", "url").stdout.strip()
    with psycopg.connect(url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material) "
                     "VALUES (42, 'spur', 3, 33, 0, 20, 'C45')")
    before = user_tables(url)
    demo = engine("demo")
    assert demo.returncode == 0, demo.stderr
    assert user_tables(url) == before
