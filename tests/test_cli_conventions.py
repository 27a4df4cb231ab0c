"""What every command promises (issue 16): --json is one line (JSON Lines: `>> refactor.jsonl`
gives one line per night) with the same key names everywhere; with --json an error is one JSON
object on stderr; every --help ends with an example of that command."""
import json

import click
import pytest
from click.testing import CliRunner
from helpers.drawings import seed_drawing

from engine.cli.app import main
from engine.cli.conventions import walk
from engine.cli.examples import EXAMPLES

COMMANDS = list(walk(main))


@pytest.mark.parametrize("path, command", COMMANDS, ids=[path for path, _ in COMMANDS])
def test_every_help_ends_with_an_example_of_its_command(path, command):
    result = CliRunner().invoke(main, [*path.split()[1:], "--help"])
    assert result.exit_code == 0, result.output
    examples = [line.strip() for line in result.stdout.splitlines() if line.strip().startswith("Example:")]
    assert examples, f"{path} --help has no line starting with Example:"
    assert any(f"{path} " in f"{example} " or (path == "engine" and "engine " in example) for example in examples)


def test_an_example_in_a_docstring_is_kept_on_a_line_of_its_own():
    @click.command("probe")
    def probe():
        """Probe the conventions: an example written at the end of a paragraph.
        Example: engine probe --now"""

    group = click.Group("engine", commands={"probe": probe})
    from engine.cli.conventions import apply_conventions

    apply_conventions(group)
    shown = CliRunner().invoke(group, ["probe", "--help"]).stdout
    assert "  Example: engine probe --now\n" in shown and "paragraph. Example" not in shown


def one_json_line(result) -> dict:
    assert result.exit_code == 0, result.output
    assert result.stdout.count("\n") == 1, result.stdout[:300]
    return json.loads(result.stdout)


def first_level_keys(payload: dict) -> set[str]:
    """The keys of the object and of the objects in its lists (records, rows, tests)."""
    inner = [key for value in payload.values() if isinstance(value, list)
             for item in value if isinstance(item, dict) for key in item]
    return set(payload) | set(inner)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_json_is_one_line_with_the_same_key_names_on_every_command(run, tmp_path):
    made = one_json_line(run("instantiate", "--gear", 42, "--json"))
    assert {"program_id", "job_id", "class"} <= made.keys()
    (tmp_path / "gears.csv").write_text("gear_id,module,teeth,face_width,material\n100,2,20,15,45\n")
    seed_drawing(tmp_path / "part.dxf")
    program = str(made["program_id"])
    invocations = [
        ("refactor", "--json"), ("lint", "--json"), ("hobs", "list", "--json"), ("cases", "list", "--json"),
        ("hobs", "match", "--gear", "42", "--json"), ("suggest", "--gear", "42", "--json"),
        ("gears", "import", tmp_path / "gears.csv", "--json"), ("explain", "--program", program, "--json"),
        ("programs", "show", program, "--json"), ("simulate", "--program", program, "--json"),
        ("template", "history", "--class", "spur", "--json"), ("test", "--class", "spur", "--json"),
        ("template", "diff", "--class", "spur", "--from", "1", "--to", "1", "--json"),
        ("instantiate", "--gears", "42-43", "--json"), ("import-dxf", tmp_path / "part.dxf", "--json"),
        ("config", "show", "--json"), ("test", "--coverage", "--class", "spur", "--json"),
    ]
    for args in invocations:
        payload = one_json_line(run(*args))
        assert "gear_class" not in first_level_keys(payload), args
    matched = one_json_line(run("hobs", "match", "--gear", "42", "--json"))
    assert {"gear_id", "hob_id"} <= matched.keys()
    assert "hob_id" in one_json_line(run("hobs", "list", "--json"))["hobs"][0]
    shown = one_json_line(run("programs", "show", program, "--json"))["programs"][0]
    assert (shown["program_id"], shown["class"]) == (made["program_id"], made["class"])
    assert one_json_line(run("template", "history", "--class", "spur", "--json"))["class"] == "spur"
    assert one_json_line(run("simulate", "--program", program, "--json"))["program_id"] == made["program_id"]


def test_the_nightly_refactor_appends_one_line_per_night(run, tmp_path):
    log = tmp_path / "refactor.jsonl"
    for _night in range(2):
        with log.open("a") as file:
            file.write(run("refactor", "--json").stdout)
    nights = [json.loads(line) for line in log.read_text().splitlines()]
    assert len(nights) == 2 and nights[1]["changed"] is False


def json_error(result, code: int = 1) -> dict:
    assert result.exit_code == code, result.output
    assert result.stdout == "" and result.stderr.count("\n") == 1, result.output
    error = json.loads(result.stderr)
    assert error["exit"] == code and "Traceback" not in result.stderr
    return error


@pytest.mark.parametrize("args, env, words", [
    (("instantiate", "--gear", "999", "--json"), {}, ["gear 999", "does not exist"]),
    (("instantiate", "--gear", "42", "--bogus", "--json"), {}, ["--bogus"]),
    (("instantiate", "--gear", "forty-two", "--json"), {}, ["forty-two"]),
    (("instantiate", "--gear", "999"), {"ENGINE_INSTANTIATE_JSON": "1"}, ["gear 999"]),
    (("hobs", "match", "--json"), {}, ["--gear"]),
    (("template", "history", "--class", "nope", "--json"), {}, ["nope"]),
])
def test_errors_of_a_json_invocation_are_json_on_stderr(read_only_run, args, env, words):
    result = read_only_run(*args, env=env)
    error = json_error(result)
    for word in words:
        assert word in error["error"]


def test_an_unexpected_error_of_a_json_invocation_is_json_with_exit_2(read_only_run, monkeypatch):
    import engine.templates.lint

    def broken(conn):
        raise ZeroDivisionError("a bug")
    monkeypatch.setattr(engine.templates.lint, "lint_all", broken)
    error = json_error(read_only_run("lint", "--json"), code=2)
    assert "ZeroDivisionError" in error["error"] and "--traceback" in error["error"]


def test_without_json_errors_stay_one_line_of_text(read_only_run):
    result = read_only_run("instantiate", "--gear", 999)
    assert result.exit_code == 1 and result.stderr.startswith("error: gear 999")


def test_version_and_help_get_no_variable_and_an_own_epilog_is_kept(monkeypatch):
    from engine.cli.conventions import apply_conventions

    @click.command("probe", epilog="See also the README.")
    @click.version_option("1.0", prog_name="engine")
    @click.option("--level", type=int, default=1, help="A level.")
    def probe(level):
        """Probe the conventions."""
        click.echo(f"level {level}")

    monkeypatch.setitem(EXAMPLES, "engine probe", "engine probe --level 2")
    group = click.Group("engine", commands={"probe": probe})
    apply_conventions(group)
    shown = CliRunner().invoke(group, ["probe", "--help"]).stdout
    assert "See also the README." in shown and "Example: engine probe --level 2" in shown
    ran = CliRunner().invoke(group, ["probe"], env={"ENGINE_PROBE_VERSION": "1", "ENGINE_PROBE_LEVEL": "3"})
    assert ran.stdout == "level 3\n"
