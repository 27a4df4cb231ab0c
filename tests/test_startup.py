"""Start-up (issue 28): a command imports what it uses and nothing else, so `engine instantiate
--gear 42` starts about as fast as a bare connect-and-query (bench/latency.py times it; no test
here is timed). Each check runs a fresh interpreter, where nothing else has imported anything,
and reads its sys.modules after the work."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from engine.verifier.expansion import EXPANDER_MODULES, expander_named
from engine.verifier.grammar import DIALECTS

# libraries an 840D hobbing command does not need: numpy (about 0.1 s of a start), the plots'
# matplotlib, the case base's pandas, the SQL translation's sqlglot, the drawings' ezdxf and the
# turning simulation's shapely
HEAVY = {"numpy", "matplotlib", "pandas", "sqlglot", "ezdxf", "shapely"}
LATHE_EXPANDERS = {"engine.verifier.expanders.iso", "engine.verifier.expanders.linuxcnc",
                   "engine.verifier.expanders.sinumerik"}
# what `engine instantiate --gear 42` used to import and does not use: the other commands' modules
# (engine.cli.commands imports a command on its first lookup), the other hobbing models and the
# turning package's own (engine.programs.all_models defers each to its first use), the batch
# workers' multiprocessing, the embedded server's module (a URL is given), the explanation of
# rows (no --explain), the TOML reader (no config file: ENGINE_CONFIG="", tests/conftest.py), the
# CSV reader and a template's CSV form (engine.quantities holds the bound the records share with it),
# the listings' helpers (engine template list), the checks of rows before they are written, a
# lathe's arcs (a hobbing program has none); the batch's progress bar is not among the CLI's modules;
# the class store that writes templates (a released template is read without it) and the plants'
# origin rules it imports, a Fanuc gear box's reader (an 840D program has none), an imported
# word's NC number (a template written by hand prints none) and the simulation of a stored program
# (what is made is proved as made)
CLI_MODULES_OF_INSTANTIATE = {"engine.cli", "engine.cli.app", "engine.cli.commands", "engine.cli.context",
                              "engine.cli.conventions", "engine.cli.examples", "engine.cli.ids",
                              "engine.cli.instantiate"}
OTHER_MODELS = {"engine.hobbing.duplex", "engine.hobbing.taper", "engine.hobbing.crowned",
                "engine.hobbing.worm_wheel", "engine.hobbing.models"}
UNUSED_BY_ONE_GEAR = {"multiprocessing", "engine.programs.workers", "engine.db.embedded", "engine.programs.explain",
                      "tomllib", "engine.csv_reader", "engine.templates.template_csv", "engine.db.listing",
                      "engine.templates.checks", "engine.verifier.arcs", "engine.templates.store",
                      "engine.db.origin", "engine.verifier.synchronisation", "engine.templates.nc_number",
                      "engine.simulation.hobbing.stored"}


def modules_after(code: str, *arguments: str) -> set[str]:
    """The modules loaded once `code` has run in a fresh interpreter (its last stdout line)."""
    done = subprocess.run([sys.executable, "-c", f"{code}\nimport sys\nprint(' '.join(sorted(sys.modules)))",
                           *arguments], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return set(done.stdout.splitlines()[-1].split())


def top_level(modules: set[str]) -> set[str]:
    return {name.partition(".")[0] for name in modules}


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_proving_and_checking_gear_42_loads_no_library_it_does_not_use(database_url):
    """The whole command, the simulation of the program included (a dry run: stored or not, the
    same checks run)."""
    code = ("import sys\nfrom engine.cli import main\n"
            "try:\n    main(['--database-url', sys.argv[1], 'instantiate', '--gear', '42', '--dry-run'])\n"
            "except SystemExit as done:\n    assert not done.code, done.code")
    loaded = modules_after(code, database_url)
    assert "engine.simulation.hobbing.walk" in loaded          # the program was proved
    assert top_level(loaded) & HEAVY == set()
    assert loaded & LATHE_EXPANDERS == set()
    assert not any(name.startswith("engine.simulation.turning.") for name in loaded)
    assert {name for name in loaded if name.startswith("engine.cli")} == CLI_MODULES_OF_INSTANTIATE
    assert "engine.hobbing.cylindrical" in loaded                # gear 42's class is served by it
    assert loaded & OTHER_MODELS == set()
    assert loaded & UNUSED_BY_ONE_GEAR == set()


def test_the_command_line_imports_no_command_until_it_is_looked_up():
    code = ("from engine.cli.app import main\nassert main.commands.imported() == set(), main.commands.imported()\n"
            "assert 'hobs' in main.commands and 'nosuch' not in main.commands\n"
            "assert main.commands.imported() == set()\nmain.commands['hobs']")
    loaded = modules_after(code)
    assert {name for name in loaded if name.startswith("engine.cli.")} - CLI_MODULES_OF_INSTANTIATE == {
        "engine.cli.hobs", "engine.cli.output"}


def test_each_command_module_is_named_with_the_command_it_holds():
    """engine.cli.commands names each command's module: looked up, it is a command of that name
    (a wrong entry would answer `engine NAME` with another command, or none)."""
    from engine.cli.app import main
    from engine.cli.commands import COMMAND_MODULES

    assert len(main.commands) == len(COMMAND_MODULES) == 26   # issue 32: engine serve; issue 33: engine plant
    for name in COMMAND_MODULES:
        assert main.commands[name].name == name


def test_each_listed_short_help_is_the_commands_own():
    """engine.cli.short_help holds what `engine --help` lists without importing a command: each
    entry is the command's short help as click makes it (a docstring changed without this table
    fails here, naming the command and the text to write)."""
    from engine.cli.app import main
    from engine.cli.short_help import SHORT_HELP

    assert sorted(SHORT_HELP) == sorted(main.commands)
    for name in main.commands:
        assert SHORT_HELP[name] == main.commands[name].get_short_help_str(10 ** 6), name


HELP_LISTINGS = """
import contextlib, io, json, sys
from engine.cli.app import main

def listing(width):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        try:
            main(['--help'], prog_name='engine', terminal_width=width)
        except SystemExit:
            pass
    return out.getvalue()

lazy = [listing(width) for width in (200, 80, 40)]
loaded = sorted(name for name in sys.modules if name.startswith('engine.cli.'))
for name in main.commands:
    main.commands[name]
print(json.dumps([lazy, [listing(width) for width in (200, 80, 40)], loaded]))
"""


def test_engine_help_imports_no_command_and_lists_them_as_click_would():
    """Issue 12's start-up: the listing of `engine --help` imported every command module for its
    short help; it lists the same text (shortened to any width as click shortens it) from
    engine.cli.short_help, and imports none."""
    done = subprocess.run([sys.executable, "-c", HELP_LISTINGS], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    lazy, imported, loaded = json.loads(done.stdout)
    assert lazy == imported and "instantiate" in lazy[1]
    assert set(loaded) - CLI_MODULES_OF_INSTANTIATE == {"engine.cli.short_help"}
    assert set(loaded) & {"engine.cli.instantiate", "engine.cli.hobs", "engine.cli.serve"} == set()


def test_the_models_a_command_does_not_plan_with_are_imported_when_the_registry_is_read_whole():
    """Deferred is not missing: reading the whole registry (engine lint, engine classify) imports
    every model's module, and each model node has its model."""
    code = ("import sys\nimport engine.programs.all_models\n"
            "assert 'engine.hobbing.taper' not in sys.modules\n"
            "from engine.gears.models import MODEL_NODES, registered_models\n"
            "assert sorted(registered_models()) == sorted(MODEL_NODES)")
    loaded = modules_after(code)
    assert OTHER_MODELS - {"engine.hobbing.models"} <= loaded


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_importing_the_command_line_loads_no_heavy_library():
    loaded = modules_after("import engine.cli.app, engine.programs.instantiate, engine.programs.all_models")
    assert top_level(loaded) & HEAVY == set()
    assert loaded & LATHE_EXPANDERS == set()


@pytest.mark.parametrize("name", sorted(EXPANDER_MODULES))
def test_a_dialect_s_expander_is_imported_with_its_first_use_and_alone(name):
    code = ("import sys\nfrom engine.verifier.expansion import EXPANDERS, expander_named\n"
            "assert sys.argv[1] not in EXPANDERS\nexpander_named(sys.argv[1])\nassert sys.argv[1] in EXPANDERS")
    loaded = modules_after(code, name)
    assert loaded & LATHE_EXPANDERS == {EXPANDER_MODULES[name]}


def test_every_dialect_that_names_an_expander_finds_it():
    named = {dialect.expander for dialect in DIALECTS.values() if dialect.expander is not None}
    assert named == set(EXPANDER_MODULES)
    for name in named:
        assert callable(expander_named(name))


def test_a_command_leaves_what_is_alive_at_its_exit_to_the_system():
    """engine.memory.command_collection: the command's exit handler freezes everything alive, so
    Python's last collection at exit walks none of it. A handler registered before the command
    runs after it (last in, first out) and finds it frozen; the command's output is whole."""
    code = ("import atexit, gc, sys\n"
            "atexit.register(lambda: sys.stderr.write(f'frozen {gc.get_freeze_count()}\\n'))\n"
            "from engine.cli import main\n"
            "try:\n    main(['--help'])\nexcept SystemExit as done:\n    assert not done.code, done.code")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "Usage: " in done.stdout and "instantiate" in done.stdout
    frozen = int(done.stderr.split("frozen ")[-1])
    assert frozen > 10_000   # the modules, classes and functions loaded: tens of thousands of objects


def test_a_command_collects_young_objects_rarely_and_restores_the_collector_after_it():
    """While a command runs, a young collection waits for COMMAND_YOUNG_COLLECTION objects (its
    start allocates fewer); after it, the process collects as it did (a test runner, a caller)."""
    import gc

    from click.testing import CliRunner

    from engine.cli import main
    from engine.memory import COMMAND_YOUNG_COLLECTION, command_collection

    before = gc.get_threshold()
    with command_collection():
        assert gc.get_threshold() == (max(COMMAND_YOUNG_COLLECTION, before[0]), *before[1:])
    assert gc.get_threshold() == before
    assert CliRunner().invoke(main, ["--help"]).exit_code == 0
    assert gc.get_threshold() == before
