"""The settings a shop gives once instead of on every command line: environment variables
ENGINE_<COMMAND>_<OPTION> and the config file (ENGINE_CONFIG, else the user's config
directory), with the precedence command line > environment > config file > built-in default."""
import json

import pytest

from engine.cli.app import main
from engine.cli.conventions import RESERVED_ENVVARS, envvar_name, options, walk


def test_an_environment_variable_sets_an_option(read_only_run):
    read_only_run.config.write_text("")
    result = read_only_run("lint", env={"ENGINE_LINT_JSON": "1"})
    assert result.exit_code == 0 and json.loads(result.stdout) == {"errors": []}
    refused = read_only_run("instantiate", "--gear", 42, env={"ENGINE_INSTANTIATE_MACHINE": "nope"})
    assert refused.exit_code == 1 and "machine 'nope'" in refused.stderr


def test_the_config_file_gives_option_defaults(read_only_run):
    read_only_run.config.write_text('[instantiate]\nmachine = "nope"\n\n[lint]\njson = true\n')
    assert json.loads(read_only_run("lint").stdout) == {"errors": []}
    refused = read_only_run("instantiate", "--gear", 42)
    assert refused.exit_code == 1 and "machine 'nope'" in refused.stderr


def test_the_default_machine_of_the_config_file(read_only_run):
    read_only_run.config.write_text('machine = "lathe-iso"\n')
    refused = read_only_run("instantiate", "--gear", 42)
    assert refused.exit_code == 1 and "not a hobbing machine" in refused.stderr


def test_command_line_beats_environment_beats_config_file(read_only_run):
    read_only_run.config.write_text('[instantiate]\nmachine = "from-the-file"\n')
    from_environment = read_only_run("instantiate", "--gear", 42, env={"ENGINE_INSTANTIATE_MACHINE": "from-the-env"})
    assert "'from-the-env'" in from_environment.stderr
    from_command_line = read_only_run("instantiate", "--gear", 42, "--machine", "from-the-line",
                                      env={"ENGINE_INSTANTIATE_MACHINE": "from-the-env"})
    assert "'from-the-line'" in from_command_line.stderr
    read_only_run.config.write_text('machine = "general"\n[instantiate]\nmachine = "from-the-table"\n')
    assert "'from-the-table'" in read_only_run("instantiate", "--gear", 42).stderr


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_database_url_keeps_working_and_engine_database_url_too(read_only_run):
    read_only_run.config.write_text("")
    for variable in ("DATABASE_URL", "ENGINE_DATABASE_URL"):
        result = read_only_run("lint", "--json", env={"DATABASE_URL": None, variable: read_only_run.url}, url=False)
        assert result.exit_code == 0, result.output
    both = read_only_run("lint", env={"DATABASE_URL": read_only_run.url,
                                      "ENGINE_DATABASE_URL": "postgresql://nobody@127.0.0.1:1/x"}, url=False)
    assert both.exit_code == 0, both.output   # DATABASE_URL, as before, comes first


def test_the_machine_folder_of_the_config_file_gets_the_program(run, tmp_path):
    folder = tmp_path / "hobber"
    folder.mkdir()   # a missing one is refused (tests/test_out_folders.py)
    run.config.write_text(f'[machines.hobber-840d]\nout = "{folder}"\n')
    result = run("instantiate", "--gear", 42, "--json")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["path"] == str(folder / "GEAR42.MPF")
    assert (folder / "GEAR42.MPF").read_text().startswith("%_N_GEAR42_MPF\n")
    elsewhere = tmp_path / "ONE.MPF"
    assert run("instantiate", "--gear", 42, "--out", elsewhere).exit_code == 0 and elsewhere.exists()


def test_crlf_line_endings_change_the_file_not_the_stored_program(run, tmp_path):
    import psycopg

    run.config.write_text('line_endings = "crlf"\n')
    target = tmp_path / "GEAR42.MPF"
    made = json.loads(run("instantiate", "--gear", 42, "--out", target, "--json").stdout)
    data = target.read_bytes()
    with psycopg.connect(run.url) as conn:
        stored = conn.execute("SELECT lines FROM program WHERE id = %s", (made["program_id"],)).fetchone()[0]
    assert data == ("\r\n".join(stored) + "\r\n").encode("ascii")
    assert not any("\r" in line for line in stored)


def test_a_stored_job_is_not_refused_for_a_configured_machine(run):
    run.config.write_text('[instantiate]\nmachine = "hobber-840d"\ncuts = 2\n')
    made = json.loads(run("instantiate", "--gear", 42, "--json").stdout)
    again = run("instantiate", "--job", made["job_id"], "--json")
    assert again.exit_code == 0, again.output


@pytest.mark.parametrize("text, words", [
    ('[instantiate\nmachine = "x"\n', ["line 1"]),
    ('line_endings = "cr"\n', ["line 1", "line_endings", "'crlf'"]),
    ('\n[instantiate]\nmachin = "x"\n', ["line 3", "--machin", "machine"]),
    ('[hobs.match]\nshift-travel = 20\n[nope]\nx = 1\n', ["line 3", "nope"]),
    ('[machines.hobber-840d]\nfolder = "/srv"\n', ["line 2", "folder"]),
])
def test_a_malformed_config_file_is_refused_naming_the_file_and_line(read_only_run, text, words):
    read_only_run.config.write_text(text)
    result = read_only_run("lint")
    message = result.stderr.strip()
    assert result.exit_code == 1 and len(message.splitlines()) == 1 and "Traceback" not in result.output
    for word in [str(read_only_run.config), *words]:
        assert word in message


def test_a_config_file_named_but_missing_is_refused(read_only_run, tmp_path):
    result = read_only_run("lint", env={"ENGINE_CONFIG": str(tmp_path / "missing.toml")})
    assert result.exit_code == 1 and "missing.toml" in result.stderr


def test_config_show_says_what_the_file_sets(read_only_run, tmp_path):
    read_only_run.config.write_text(f'line_endings = "crlf"\n[machines.hobber-840d]\nout = "{tmp_path}"\n'
                                    '[hobs.match]\nshift-travel = 20\n')
    shown = json.loads(read_only_run("config", "show", "--json").stdout)
    assert shown["path"] == str(read_only_run.config) and shown["line_endings"] == "crlf"
    assert shown["machines"] == {"hobber-840d": {"out": str(tmp_path)}}
    assert shown["defaults"] == {"hobs": {"match": {"shift_travel": 20}}}
    assert read_only_run("config", "path").stdout.strip() == str(read_only_run.config)


def test_no_option_variable_is_one_the_engine_reads_itself():
    names = [envvar_name(path, option) for path, command in walk(main) for option in options(command)]
    assert len(names) == len(set(names)) and not RESERVED_ENVVARS & set(names)
    assert "ENGINE_INSTANTIATE_MACHINE" in names and "ENGINE_HOBS_MATCH_SHIFT_TRAVEL" in names


def test_the_file_in_the_users_config_directory_is_read(read_only_run, tmp_path):
    home = tmp_path / "xdg"
    (home / "nc-template-engine").mkdir(parents=True)
    (home / "nc-template-engine" / "config.toml").write_text("[lint]\njson = true\n")
    environment = {"ENGINE_CONFIG": None, "XDG_CONFIG_HOME": str(home)}
    assert json.loads(read_only_run("lint", env=environment).stdout) == {"errors": []}
    assert read_only_run("config", "path", env=environment).stdout.strip() == \
        str(home / "nc-template-engine" / "config.toml")
    assert read_only_run("lint", env={**environment, "ENGINE_CONFIG": ""}).stdout == ""   # ENGINE_CONFIG= reads none
