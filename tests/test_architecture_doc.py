"""docs/architecture.md stays true: every name it gives a newcomer is one they can find. Each
`engine.…` name imports, each `tests/…::test_…` is a test function, each database object named as
`table …`, `view …`, `function …`, `trigger …`, `sequence …`, `column t.c`, `constraint …` or
`role …` is in the migrated, seeded database, each `engine …` command and its options exist in
the CLI, and the layer list is the one tests/test_house.py enforces. Each checker is also shown
a wrong name, which it must report."""
from __future__ import annotations

import ast
import importlib
import re
import shlex
from pathlib import Path

import click
import pytest

from engine.cli.app import main

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "architecture.md"
HOUSE = ROOT / "tests" / "test_house.py"
WALKED = "engine instantiate --gear 42 --out GEAR42.MPF"

TICKED = re.compile(r"`([^`\n]+)`")
DOTTED = re.compile(r"engine(?:\.[A-Za-z_]\w*)+")
TEST = re.compile(r"(tests/[\w/]+\.py)::(\w+)")
SQL_OBJECT = re.compile(r"(table|view|function|trigger|sequence|column|constraint|role) ([a-z_]\w*(?:\.[a-z_]\w*)?)")
COMMAND = re.compile(r"engine( [^`]+)?")
FOLDER = re.compile(r"`engine/(\w+)/`")

# kind -> the catalog query that finds an object of that kind by name (schema public)
CATALOG = {
    "table": "SELECT 1 FROM pg_tables WHERE schemaname = 'public' AND tablename = %s",
    "view": "SELECT 1 FROM pg_views WHERE schemaname = 'public' AND viewname = %s",
    "sequence": "SELECT 1 FROM pg_sequences WHERE schemaname = 'public' AND sequencename = %s",
    "function": "SELECT 1 FROM pg_proc p JOIN pg_namespace n ON n.oid = p.pronamespace "
                "WHERE n.nspname = 'public' AND p.proname = %s",
    "trigger": "SELECT 1 FROM pg_trigger WHERE NOT tgisinternal AND tgname = %s",
    "constraint": "SELECT 1 FROM pg_constraint c JOIN pg_namespace n ON n.oid = c.connamespace "
                  "WHERE n.nspname = 'public' AND c.conname = %s",
    "role": "SELECT 1 FROM pg_roles WHERE rolname = %s",
    "column": "SELECT 1 FROM information_schema.columns WHERE table_schema = 'public' "
              "AND table_name = %s AND column_name = %s",
}


def ticked(text: str) -> list[str]:
    """What the text holds in backticks, in order (a code block's lines are not ticked)."""
    return TICKED.findall(text)


def doc_names(pattern: re.Pattern, text: str) -> list[str]:
    return sorted({name for name in ticked(text) if pattern.fullmatch(name)})


def resolves(dotted: str) -> bool:
    """The longest importable module prefix of `dotted`, then each remaining part an attribute."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            found = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError as error:
            if not ".".join(parts[:cut]).startswith(error.name or "\0"):
                raise   # the module exists but fails to import: a bug to show, not a wrong name
            continue
        return _attributes(found, parts[cut:])
    return False


def _attributes(found, names: list[str]) -> bool:
    for name in names:
        if not hasattr(found, name):
            return False
        found = getattr(found, name)
    return True


def names_a_test(reference: str) -> bool:
    """`tests/test_x.py::test_name` names a test function of that file (module level or in a class)."""
    path, name = TEST.fullmatch(reference).groups()
    if not (ROOT / path).is_file():
        return False
    tree = ast.parse((ROOT / path).read_text(encoding="utf-8"))
    return name in {node.name for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))}



def in_database(conn, named: str) -> bool:
    kind, name = SQL_OBJECT.fullmatch(named).groups()
    parameters = tuple(name.split(".")) if kind == "column" else (name,)
    return conn.execute(CATALOG[kind], parameters).fetchone() is not None


def command_exists(line: str) -> bool:
    """`engine SUB … --option …`: each subcommand in the group above it, each option on the command
    reached (or on `engine` itself)."""
    command, words = _command_of(shlex.split(line)[1:])
    if command is None:
        return False
    known = {opt for parameter in [*command.params, *main.params] for opt in parameter.opts + parameter.secondary_opts}
    return all(word.split("=")[0] in known | {"--help"} for word in words if word.startswith("--"))


def _command_of(words: list[str]):
    """The command the words name and the words after it; None for a subcommand no group has."""
    command = main
    while words and isinstance(command, click.Group) and not words[0].startswith("-"):
        command = command.commands.get(words[0])
        if command is None:
            return None, []
        words = words[1:]
    return command, words


def doc_layers(text: str) -> list[set[str]]:
    """The folders of each item of the numbered list under '## The layers', bottom first."""
    section = text.split("## The layers", 1)[1].split("\n## ", 1)[0]
    items = re.split(r"\n\d+\. ", section)[1:]
    return [set(FOLDER.findall(item)) for item in items]


def house_layers(house: Path, folders: set[str]) -> list[set[str]] | None:
    """tests/test_house.py's LAYERS as tiers of folder names (read with ast: no test module
    imports another), bottom first; None while it has none."""
    value = next((node.value for node in ast.walk(ast.parse(house.read_text(encoding="utf-8")))
                  if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "LAYERS" for t in node.targets)),
                 None)
    if value is None:
        return None
    layers = ast.literal_eval(value)
    tiers = [layers[key] for key in sorted(layers, key=layers.get)] if isinstance(layers, dict) else list(layers)
    return [tier for tier in (_folder_names(entry, folders) for entry in tiers) if tier]


def _folder_names(entry, folders: set[str]) -> set[str]:
    names = [entry] if isinstance(entry, (str, int)) else list(entry)
    bare = {str(name).removeprefix("engine.").removeprefix("engine/").strip("/") for name in names}
    return bare & folders


@pytest.fixture(scope="module")
def doc() -> str:
    return DOC.read_text(encoding="utf-8")


def test_the_walk_follows_the_command_it_names_through_many_names(doc):
    assert f"`{WALKED}`" in doc
    counts = [len(doc_names(pattern, doc)) for pattern in (DOTTED, TEST, SQL_OBJECT, COMMAND)]
    assert counts[0] >= 60 and counts[1] >= 40 and counts[2] >= 30 and counts[3] >= 5, counts


def test_every_python_name_of_the_doc_imports(doc):
    wrong = [name for name in doc_names(DOTTED, doc) if not resolves(name)]
    assert not wrong, f"docs/architecture.md names Python that does not import: {wrong}"


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_every_test_the_doc_names_exists(doc):
    wrong = [name for name in doc_names(TEST, doc) if not names_a_test(name)]
    assert not wrong, f"docs/architecture.md names tests that do not exist: {wrong}"


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_every_database_object_the_doc_names_exists(doc, conn):
    wrong = [name for name in doc_names(SQL_OBJECT, doc) if not in_database(conn, name)]
    assert not wrong, f"docs/architecture.md names database objects the migrations do not make: {wrong}"


def test_every_command_the_doc_shows_exists(doc):
    wrong = [line for line in doc_names(COMMAND, doc) if not command_exists(line)]
    assert not wrong, f"docs/architecture.md shows commands or options the CLI lacks: {wrong}"


def test_the_layers_are_the_ones_the_house_enforces(doc):
    folders = {path.name for path in (ROOT / "engine").iterdir() if path.is_dir()} | set(FOLDER.findall(doc))
    enforced = house_layers(HOUSE, folders)
    assert enforced is not None, "tests/test_house.py has no LAYERS list the doc can be checked against"
    assert [tier for tier in doc_layers(doc) if tier] == enforced


@pytest.mark.parametrize("wrong", ["engine.programs.storage.no_such_function", "engine.no_such_folder.store_one",
                                   "engine.programs.instantiate.Planner.no_such_method"])
def test_a_python_name_that_moved_or_never_was_is_reported(wrong):
    assert not resolves(wrong)


def test_a_test_that_does_not_exist_is_reported():
    assert not names_a_test("tests/test_cli.py::test_no_such_promise")
    assert not names_a_test("tests/test_no_such_file.py::test_instantiate_prints_the_program_and_stores_it")


@pytest.mark.parametrize("wrong", ["table no_such_table", "view program", "function no_such_function",
                                   "trigger no_such_trigger", "column machine.no_such_column", "role no_such_role"])
def test_a_database_object_that_is_not_there_is_reported(conn, wrong):
    assert not in_database(conn, wrong)


@pytest.mark.parametrize("wrong", ["engine no-such-command", "engine instantiate --no-such-option 1",
                                   "engine template no-such-subcommand"])
def test_a_command_or_option_the_cli_lacks_is_reported(wrong):
    assert not command_exists(wrong)


def test_the_layer_lists_are_compared_folder_by_folder_in_order(tmp_path):
    text = ("## The layers\n\n1. `engine/errors.py`\n2. `engine/db/`\n3. `engine/gears/`, `engine/nc/`\n"
            "4. `engine/cli/`\n")
    house = tmp_path / "test_house.py"
    house.write_text('LAYERS = [("errors", "names"), "db", ("engine.nc", "engine/gears/"), ("cli",)]\n')
    assert house_layers(house, {"db", "nc", "gears", "cli"}) == [tier for tier in doc_layers(text) if tier]
    house.write_text('LAYERS = ["db", "nc", "gears", "cli"]\n')
    assert house_layers(house, {"db", "nc", "gears", "cli"}) != [tier for tier in doc_layers(text) if tier]
