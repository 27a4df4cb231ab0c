"""Installing and operating the engine as a shop does (issue 16): its version, an install without
its migrations refused, the embedded server's URL, psql and stop (as whoever runs them, root
included), a demo that never writes into the shop's database, and a seed that loads the samples
only when asked."""
import importlib.metadata
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import psycopg
import pytest
from click.testing import CliRunner
from psycopg import sql

from engine.cli.app import main
from engine.db.embedded import find_psql, server_state

SEED_DIR = Path(__file__).resolve().parent.parent / "seed_templates"
SOURCE_ROOT = Path(__file__).resolve().parent.parent
SHOP_COUNTS = tuple("SELECT count(*) FROM " + what for what in (
    "gear", "gear_unit", "hob", "cutting_case", "machine", "template_test",
    "gear_class WHERE name IN ('spur', 'helical', 'duplex', 'worm_wheel')",
    "released_template_view WHERE gear_class = 'spur'"))


def user_tables(url: str) -> dict[str, int]:
    """Every table outside the system schemas with its row count."""
    with psycopg.connect(url) as conn:
        names = conn.execute("SELECT schemaname, tablename FROM pg_tables "
                             "WHERE schemaname NOT IN ('pg_catalog', 'information_schema')").fetchall()
        return {f"{schema}.{table}": conn.execute(sql.SQL("SELECT count(*) FROM {}.{}").format(
            sql.Identifier(schema), sql.Identifier(table))).fetchone()[0] for schema, table in names}


def counts(url: str, *queries: str) -> list[int]:
    """The single numbers the queries (SELECT count(*) …) give."""
    with psycopg.connect(url) as conn:
        return [conn.execute(query).fetchone()[0] for query in queries]


class Engine:
    """`python -m engine` in a subprocess, on its own embedded data directory, with no
    DATABASE_URL or PG* variable unless a test gives one."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.data_dir = folder / "pgdata"
        self.env = {k: v for k, v in os.environ.items() if k != "DATABASE_URL" and not k.startswith("PG")}
        self.env.update(ENGINE_DATA_DIR=str(self.data_dir),
                        PYTHONPATH=os.pathsep.join([str(SOURCE_ROOT), os.environ.get("PYTHONPATH", "")]))

    def __call__(self, *args, **extra_env) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "engine", *map(str, args)], env={**self.env, **extra_env},
                              cwd=self.folder, capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def engine():
    """Not under pytest's basetemp (a concurrent session prunes it); stopped and removed at the end."""
    folder = Path(tempfile.mkdtemp(prefix="engine-operate-"))
    runner = Engine(folder)
    yield runner
    runner("db", "stop")
    shutil.rmtree(folder, ignore_errors=True)


def test_version_is_one_line_from_the_installed_package():
    result = CliRunner().invoke(main, ["--version"])
    assert result.exit_code == 0
    assert result.stdout == f"nc-template-engine {importlib.metadata.version('nc-template-engine')}\n"


@pytest.mark.parametrize("command", [("db", "migrate"), ("db", "status"), ("instantiate", "--gear", "42")])
def test_an_install_without_migrations_is_refused_naming_the_folder(command, empty_database_url, tmp_path,
                                                                    monkeypatch):
    folder = tmp_path / "site-packages" / "migrations"
    folder.mkdir(parents=True)
    monkeypatch.setattr("engine.db.migrate.MIGRATIONS_DIR", folder)   # what an install without its data finds
    result = CliRunner().invoke(main, ["--database-url", empty_database_url, *command])
    assert result.exit_code == 1
    assert result.stderr.startswith(f"error: no migrations found in {folder}")
    assert len(result.stderr.splitlines()) == 1
    assert user_tables(empty_database_url) == {}   # not even the ledger


@pytest.mark.slow
def test_the_embedded_server_is_started_shown_opened_and_stopped(engine):
    assert engine("db", "stop").stdout.startswith("the embedded PostgreSQL is not running")
    shown = engine("db", "url")
    assert shown.returncode == 0, shown.stderr
    url = shown.stdout.strip()
    assert len(shown.stdout.splitlines()) == 1 and str(engine.data_dir) in url
    assert f"embedded PostgreSQL, data in {engine.data_dir}" in shown.stderr
    with psycopg.connect(url) as conn:
        assert conn.execute("SELECT current_database()").fetchone() == ("engine",)

    opened = engine("db", "psql", "-At", "-c", "SELECT 'psql on ' || current_database()")
    assert opened.returncode == 0, opened.stderr
    assert opened.stdout == "psql on engine\n"

    running = server_state(engine.data_dir)
    stopped = engine("db", "stop")
    assert stopped.returncode == 0, stopped.stderr
    assert stopped.stdout.startswith(
        f"stopped the embedded PostgreSQL (pid {running.pid}, data in {engine.data_dir})")
    assert not server_state(engine.data_dir).running
    with pytest.raises(psycopg.OperationalError):
        psycopg.connect(url, connect_timeout=5)
    again = engine("db", "stop")
    assert again.returncode == 0 and again.stdout.startswith("the embedded PostgreSQL is not running")

    after = engine("db", "status")   # the next command starts it again, its data kept
    assert after.returncode == 0, after.stderr
    assert after.stdout.startswith("pending  0001.core.sql")
    assert server_state(engine.data_dir).running


@pytest.mark.slow
def test_demo_leaves_the_database_it_was_pointed_at_untouched(engine, empty_database_url):
    before = user_tables(empty_database_url)
    by_variable = engine("demo", DATABASE_URL=empty_database_url)
    by_option = engine("--database-url", empty_database_url, "demo")
    for result in (by_variable, by_option):
        assert result.returncode == 0, result.stderr
        assert result.stdout.rstrip().endswith("M30")
        assert f"in the database engine_demo of the embedded PostgreSQL (data in {engine.data_dir})" in result.stderr
        assert "ignored" in result.stderr and "engine seed --samples" in result.stderr
    assert user_tables(empty_database_url) == before == {}
    embedded = engine("db", "url").stdout.strip()   # the embedded server's own database: a shop's
    assert user_tables(embedded) == {}
    demo_database = embedded.replace("/engine?", "/engine_demo?")
    assert demo_database != embedded
    assert counts(demo_database, "SELECT count(*) FROM gear WHERE id = 42", "SELECT count(*) FROM program") == [1, 2]


@pytest.mark.slow
def test_demo_turning_prints_the_sample_drawing_s_program_and_where_the_drawing_is(engine):
    shown = engine("demo", "--sample-path")
    assert (shown.returncode, shown.stdout) == (0, f"{SEED_DIR / 'drawings' / 'sample_shaft.dxf'}\n")
    result = engine("demo", "--turning")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[-2:] == ["M30", "%"] and "(DRAWING sample_shaft.dxf)" in lines
    assert [line.split()[2] for line in lines if line.startswith("(OP ")] == ["ROUGH", "SLOT", "FINISH", "THREAD"]
    assert f"sample drawing {shown.stdout.strip()}" in result.stderr
    assert "in the database engine_demo of the embedded PostgreSQL" in result.stderr


def test_db_url_prints_the_url_given_or_the_libpq_variables():
    given = "postgresql://shop@db.example:5433/engine"
    shown = CliRunner().invoke(main, ["--database-url", given, "db", "url"])
    assert (shown.exit_code, shown.stdout, shown.stderr) == (0, given + "\n", "from --database-url\n")
    from_libpq = CliRunner().invoke(main, ["db", "url"], env={"DATABASE_URL": None, "PGHOST": "/run/pg",
                                                              "PGDATABASE": "shop", "PGPORT": "5433"})
    assert from_libpq.exit_code == 0
    assert sorted(from_libpq.stdout.split()) == ["dbname=shop", "host=/run/pg", "port=5433"]
    from_variable = CliRunner().invoke(main, ["db", "url"], env={"DATABASE_URL": given})
    assert (from_variable.stdout, from_variable.stderr) == (given + "\n", "from DATABASE_URL\n")


def test_psql_missing_everywhere_says_the_command_to_run(tmp_path, monkeypatch):
    empty = tmp_path / "bin"
    empty.mkdir()
    assert find_psql([empty], path=str(empty)) is None
    monkeypatch.setattr("engine.db.embedded.bin_dir", lambda: empty)   # a package without its binaries
    result = CliRunner().invoke(main, ["--database-url", "postgresql://shop@db.example/engine", "db", "psql",
                                       "-c", "SELECT 1"], env={"PATH": str(empty)})
    assert result.exit_code == 1
    assert result.stderr.startswith(f"error: no psql found (neither in {empty} nor on PATH)")
    assert result.stderr.rstrip().endswith("run: psql --dbname postgresql://shop@db.example/engine -c 'SELECT 1'")


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_seed_loads_what_a_shop_needs_and_the_samples_only_when_asked(empty_database_url):
    def engine_on_it(*args):
        result = CliRunner().invoke(main, ["--database-url", empty_database_url, *args])
        assert result.exit_code == 0, result.output
        return result

    engine_on_it("db", "migrate")
    engine_on_it("seed")
    tests = json.loads((SEED_DIR / "template_tests.json").read_text(encoding="utf-8"))
    machines = (SEED_DIR / "machines.csv").read_text(encoding="utf-8").strip().splitlines()[1:]
    shop = counts(empty_database_url, *SHOP_COUNTS)
    assert shop[:7] == [0, 0, 0, 0, len(machines), sum(test.get("gear_id") is None for test in tests), 4]
    assert shop[7] > 0   # the standard code, released
    assert "nothing changed" in engine_on_it("seed").stdout

    engine_on_it("seed", "--samples")
    assert counts(empty_database_url, "SELECT count(*) FROM gear WHERE id = 42",
                  "SELECT count(*) FROM template_test") == [1, len(tests)]
    assert min(counts(empty_database_url, "SELECT count(*) FROM hob", "SELECT count(*) FROM cutting_case",
                      "SELECT count(*) FROM gear_unit")) > 0
    assert engine_on_it("instantiate", "--gear", 42).stdout.rstrip().endswith("M30")


@pytest.mark.parametrize("command", [("demo",), ("seed",), ("db", "url"), ("db", "psql"), ("db", "stop"),
                                     ("db", "migrate"), ("db", "status")])
def test_operating_commands_show_an_example(command):
    result = CliRunner().invoke(main, [*command, "--help"])
    assert result.exit_code == 0
    assert any(line.strip().startswith("Example: ") for line in result.stdout.splitlines())


def test_an_installed_engine_reads_its_own_data_not_the_current_folders(tmp_path, monkeypatch):
    """A wheel puts engine_data/ beside engine/ in site-packages; `python -m engine` puts the
    current folder first on sys.path, and an engine_data/migrations/ there must not be applied."""
    from engine.paths import data_folder

    site_packages, elsewhere = tmp_path / "site-packages", tmp_path / "cwd"
    (site_packages / "engine_data" / "migrations").mkdir(parents=True)
    (elsewhere / "engine_data" / "migrations").mkdir(parents=True)
    (elsewhere / "engine_data" / "migrations" / "0099.from_cwd.sql").write_text("CREATE TABLE x ()")
    monkeypatch.chdir(elsewhere)
    monkeypatch.syspath_prepend(str(elsewhere))
    assert data_folder("migrations", site_packages) == site_packages / "engine_data" / "migrations"
    checkout = Path(__file__).resolve().parent.parent
    assert data_folder("migrations", checkout) == checkout / "migrations"


@pytest.fixture
def own_engine():
    """Like `engine`, on an embedded data directory of the test's own (the test breaks it or
    needs it new)."""
    folder = Path(tempfile.mkdtemp(prefix="engine-own-"))
    runner = Engine(folder)
    yield runner
    runner("db", "stop")
    shutil.rmtree(folder, ignore_errors=True)


@pytest.mark.slow
def test_demo_ignores_pghostaddr_it_runs_on_the_embedded_server(own_engine):
    """PGHOSTADDR (libpq's address of the shop's server) must not steer the demo's connection:
    with it, libpq connected the embedded URL to the shop's server (and seeded it)."""
    demo = own_engine("demo", PGHOSTADDR="192.0.2.1", PGCONNECT_TIMEOUT="3")
    assert demo.returncode == 0, demo.stderr
    assert demo.stdout.rstrip().endswith("M30")


def test_an_embedded_data_folder_that_cannot_be_used_is_one_line(own_engine):
    own_engine.data_dir.mkdir()
    (own_engine.data_dir / "notes.txt").write_text("a shop's file, not a database\n")
    shown = own_engine("db", "url")
    assert shown.returncode == 1
    assert shown.stderr.startswith("error: ") and shown.stderr.count("\n") == 1, shown.stderr


@pytest.mark.slow
def test_demo_leaves_a_shop_database_on_the_embedded_server_untouched(own_engine):
    """Without a URL the embedded server is the shop's database (guide, install-and-operate: the embedded
    server). `engine demo` must not seed the samples into it, nor store a job and a program (a
    record nobody deletes) for the shop's own gear 42."""
    for args in (("db", "migrate"), ("seed",)):
        assert own_engine(*args).returncode == 0
    url = own_engine("db", "url").stdout.strip()
    with psycopg.connect(url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, helix_angle, face_width, material) "
                     "VALUES (42, 'spur', 3, 33, 0, 20, 'C45')")
    before = user_tables(url)
    demo = own_engine("demo")
    assert demo.returncode == 0, demo.stderr
    assert user_tables(url) == before
