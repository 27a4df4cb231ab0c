"""Bad input ends with exit 1 and one line naming the thing, never exit 2 (a bug), and stores
nothing (issue 26, finding 10): an SQL condition sqlglot itself fails inside, a gear of 5,000 to
100,000 teeth (its feed would be written F0), a runner's job with a feed of 0, and ENGINE_CONFIG
naming /dev/zero (read until memory ran out) or a FIFO (waited for a writer forever)."""
from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import psycopg
import pytest

ROOT = Path(__file__).resolve().parents[1]
HANG_GUARD = 30                # seconds: a refusal takes well under one; on main the FIFO hung
ADDRESS_SPACE = 1 << 30        # the /dev/zero read stops here (MemoryError, exit 2) instead of the machine's RAM
GEAR_COLUMNS = ("gear_id,gear_class,module,teeth,pressure_angle,helix_angle,hand,face_width,tip_diameter,"
                "root_diameter,cone_angle,crowning,material,hardness,quality_grade,quantity,module_kind")


def stored(url: str) -> tuple:
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program), "
                            "(SELECT count(*) FROM gear)").fetchone()


def refused_in_one_line(result, *words: str) -> None:
    assert result.exit_code == 1, (result.exit_code, result.output, result.exception)
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and all(word in lines[0] for word in words), result.stderr


def test_a_condition_the_sql_parser_fails_inside_is_refused_naming_its_row(run):
    with psycopg.connect(run.url) as conn:   # an editor's draft row, in SQL
        conn.execute("INSERT INTO template_view (gear_class, id, t, n, o, p_emit) "
                     "VALUES ('spur', 751, 'main', 1, '''M0''', '(floor()[:]')")
    before = stored(run.url)
    refused_in_one_line(run("instantiate", "--gear", 42, "--draft"), "row 751", "p_emit", "(floor()[:]")
    assert stored(run.url) == before


@pytest.mark.parametrize("teeth", [5_000, 20_000, 100_000])
def test_a_gear_whose_feed_would_be_written_f0_is_refused(run, tmp_path, teeth):
    """§B5: v_f = f·n2 with the table at n2 = n0·z0/z2: at n0 = 246 r/min and one start, 5,000
    teeth turn the table at 0.05 r/min, and a radial feed of about 1 mm per table turn is
    0.05 mm/min, below the 0.1 mm/min of an F word's one decimal (it was written F0)."""
    gears = tmp_path / "gears.csv"
    gears.write_text(f"{GEAR_COLUMNS}\n901,spur,2,{teeth},20,0,,20,,,,,40Cr,250,7,50,\n", encoding="utf-8")
    assert run("gears", "import", gears).exit_code == 0
    before = stored(run.url)
    refused_in_one_line(run("instantiate", "--gear", 901), "feed", "below the 0.1 mm/min", "teeth")
    assert stored(run.url) == before


@pytest.mark.parametrize("feed", ["feed_axial", "feed_radial"])
def test_a_runners_job_with_a_feed_of_0_is_refused(run, feed):
    assert run("instantiate", "--gear", 42).exit_code == 0
    with psycopg.connect(run.url) as conn:   # a runner edits the stored job in SQL
        job = conn.execute("SELECT max(id) FROM job").fetchone()[0]
        conn.execute("UPDATE job SET module_params = jsonb_set(module_params, %s, '0') WHERE id = %s",
                     (["cutmotion:2", feed], job))
    before = stored(run.url)
    refused_in_one_line(run("instantiate", "--job", job), f"cutmotion:2.{feed}: 0 mm/min must be above 0",
                        "correct job.module_params")
    assert stored(run.url) == before


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))


@pytest.fixture
def fifo(tmp_path):
    path = tmp_path / "config.fifo"
    os.mkfifo(path)
    return path


@pytest.mark.parametrize("config", ["/dev/zero", "fifo"])
def test_a_config_that_is_no_regular_file_is_refused_without_reading_it(read_only_database_url, fifo, config):
    path = str(fifo) if config == "fifo" else config
    environment = {**os.environ, "PYTHONPATH": str(ROOT), "ENGINE_CONFIG": path}
    done = subprocess.run([sys.executable, "-m", "engine", "--database-url", read_only_database_url, "gears", "list"],
                          capture_output=True, text=True, env=environment, preexec_fn=_limited, timeout=HANG_GUARD)
    assert done.returncode == 1, done.stderr
    assert done.stderr.count("\n") == 1 and path in done.stderr and "not a regular file" in done.stderr, done.stderr


def test_a_tab_inside_an_imported_nc_line_is_refused_at_import_naming_the_line(read_only_run, tmp_path):
    """A stored NC line holds no control character (check_program): a program with a tab was
    imported, and then `--unverified`, which skips the verifier, ended in the database's
    CheckViolation and exit 2 (issue 26); since issue 27 the import refuses the tab, naming its
    line, and stores nothing."""
    source = (ROOT / "tests" / "data" / "nc" / "linuxcnc" / "lathe_pawn.ngc").read_text().splitlines()
    source[3] = source[3].replace(" ", "\t", 1)
    program = tmp_path / "tabbed.ngc"
    program.write_text("\n".join(source) + "\n")
    before = stored(read_only_run.url)
    refused_in_one_line(read_only_run("import-nc", program, "--class", "tabbed"), "line 4", "holds a tab",
                        "nothing stored")
    assert stored(read_only_run.url) == before
