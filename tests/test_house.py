"""The house (issues 11, 25): engine/ is laid out as the design's sections, stacked in LAYERS so a
folder imports only folders in lower layers, no two modules import each other in a circle (imports
inside functions count: a cycle is a cycle of the design, whenever it runs; so does a package's
__init__, which runs when any module below it is first imported), and nothing below the command
line imports it. The walker reads the source with `ast`; each check is also run on a small package
of its own that has the fault."""
import ast
from pathlib import Path

import pytest

import engine

# engine/'s folders, bottom to top: a folder may import only folders of a lower entry, never one in
# its own entry nor above. "top" is engine's loose modules (errors, names, notes, paths, json_text,
# memory, csv_reader, quantities, pictures) and its __init__: they import nothing of the engine but each other.
LAYERS = [
    ("top",),
    ("db",),                                  # connection, embedded server, migrations, records
    ("nc",),                                  # NC text primitives: tokens, layout, lineage, words
    ("machines",),                            # the machine record
    ("gears",),                               # gears and hobs, classes, cutting data, model registry
    ("verifier",),                            # the fail-closed reader of every program
    ("templates", "simulation", "drawings"),  # decision table; hobbing simulation; DXF reading
    ("library", "hobbing", "turning"),        # module library and seed; the models
    ("programs",),                            # instantiation, storage, jobs
    ("release",),                             # golden tests, impact, the release gate
    ("service", "plants"),                    # engine serve: delivery to the controls, the web view; plants
    ("cli",),                                 # the command line (and engine/__main__.py)
]
# Rules beyond the order, kept if the order ever changes: (importer, imported) -> why not.
FORBIDDEN = {
    ("simulation", "hobbing"): "the simulation never imports the models that made the program",
    ("simulation", "turning"): "the simulation never imports the models that made the program",
}
DESIGN_FOLDERS = tuple(folder for layer in LAYERS[1:] for folder in layer)
CLI = "engine.cli"
CLI_ENTRY_POINTS = {"engine.__main__"}     # `python -m engine` is the command line itself


def modules_under(folder: Path, package: str) -> dict[str, Path]:
    """Dotted module name -> file, for every .py file of the package folder."""
    found = {}
    for path in folder.rglob("*.py"):
        parts = [package, *path.relative_to(folder).with_suffix("").parts]
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


def imported_modules(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The modules of `modules` that `name` imports anywhere in its file."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    targets = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(package, node.module, node.level)
            for alias in node.names:   # `from pkg import submodule` imports the submodule
                targets.add(f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base)
    known = {found for found in (_known(target, modules) for target in targets) if found not in (None, name)}
    return known | {package for target in known for package in _outer_packages(target, name, modules)}


def _outer_packages(target: str, importer: str, modules) -> set[str]:
    """The packages whose __init__ importing `target` runs first: those above it that are not
    also above the importer (those are running already)."""
    parts = target.split(".")
    above = {".".join(parts[:length]) for length in range(1, len(parts))}
    return {package for package in above
            if package in modules and importer != package and not importer.startswith(package + ".")}


def _absolute(package: str, module: str | None, level: int) -> str:
    if not level:
        return module or ""
    parts = package.split(".")[:len(package.split(".")) - level + 1]
    return ".".join(parts + ([module] if module else []))


def _known(target: str, modules) -> str | None:
    """The deepest module of ours that `target` names (a name imported from a module is the module)."""
    while target and target not in modules:
        target = target.rpartition(".")[0]
    return target or None


def import_graph(*packages) -> dict[str, set[str]]:
    modules = {}
    for folder, name in packages:
        modules.update(modules_under(folder, name))
    return {name: imported_modules(name, path, modules) for name, path in modules.items()}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Every import cycle found by depth-first search, each as the path that closes it."""
    found, state, path = [], {}, []

    def visit(module):
        state[module] = "open"
        path.append(module)
        for target in sorted(graph[module]):
            if state.get(target) == "open":
                found.append(path[path.index(target):] + [target])
            elif target not in state:
                visit(target)
        path.pop()
        state[module] = "done"

    for module in sorted(graph):
        if module not in state:
            visit(module)
    return found


def cli_importers(graph: dict[str, set[str]]) -> list[str]:
    """`module -> cli module` for every module outside the CLI that imports it."""
    def in_cli(module):
        return module == CLI or module.startswith(CLI + ".")
    return sorted(f"{module} -> {target}" for module, targets in graph.items() for target in targets
                  if in_cli(target) and not in_cli(module) and module not in CLI_ENTRY_POINTS)


def engine_graph():
    return import_graph((Path(engine.__file__).parent, "engine"))


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_no_import_cycle_in_the_package():
    graph = engine_graph()
    assert len(graph) > 80          # the walk read the whole package
    assert cycles(graph) == []


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_nothing_below_the_command_line_imports_it():
    graph = engine_graph()
    assert any(target.startswith(CLI + ".") for target in graph["engine.cli.app"])   # the walk sees CLI imports
    assert cli_importers(graph) == []


def missing_design_folders(folder: Path) -> list[str]:
    return [name for name in DESIGN_FOLDERS if not (folder / name / "__init__.py").is_file()]


def loose_modules(folder: Path) -> list[str]:
    return sorted(path.name for path in folder.glob("*.py") if path.name not in ("__init__.py", "__main__.py"))


def modules_not_saying_what_they_are(folder: Path) -> list[str]:
    """Modules whose first line is not the start of a docstring that says something."""
    def says(path):
        text = path.read_text("utf-8")
        return text.startswith('"' * 3) and bool((ast.get_docstring(ast.parse(text)) or "").strip())
    return sorted(str(path.relative_to(folder)) for path in folder.rglob("*.py") if not says(path))


def test_engine_is_laid_out_as_the_design_s_sections():
    folder = Path(engine.__file__).parent
    assert missing_design_folders(folder) == []
    # below every section
    assert loose_modules(folder) == ["csv_reader.py", "errors.py", "json_text.py", "memory.py", "names.py", "notes.py",
                                     "paths.py", "pictures.py", "quantities.py"]


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_every_module_says_what_it_is_in_its_first_line():
    assert modules_not_saying_what_they_are(Path(engine.__file__).parent) == []


def test_the_layout_checks_find_a_missing_folder_a_loose_module_and_a_silent_module(tmp_path):
    for name in DESIGN_FOLDERS[1:]:
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text(f'"""The {name} section."""\n')
    (tmp_path / "gear_import.py").write_text('# a comment first\n"""Gears from CSV."""\n')
    (tmp_path / "library" / "seed.py").write_text("import csv\n")
    assert missing_design_folders(tmp_path) == [DESIGN_FOLDERS[0]]
    assert loose_modules(tmp_path) == ["gear_import.py"]
    assert modules_not_saying_what_they_are(tmp_path) == ["gear_import.py", "library/seed.py"]


def _package(tmp_path, files: dict[str, str]):
    for relative, text in files.items():
        path = tmp_path / "pkg" / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return import_graph((tmp_path / "pkg", "pkg"))


def test_the_walker_finds_a_cycle_through_an_import_inside_a_function(tmp_path):
    graph = _package(tmp_path, {
        "__init__.py": "",
        "a.py": "def f():\n    from .sub import b\n    return b\n",
        "sub/__init__.py": "",
        "sub/b.py": "from ..a import f\n",
        "c.py": "import pkg.a\n",
    })
    assert graph["pkg.a"] == {"pkg.sub.b", "pkg.sub"} and graph["pkg.c"] == {"pkg.a"}
    assert cycles(graph) == [["pkg.a", "pkg.sub.b", "pkg.a"]]


def test_the_walker_finds_a_cycle_through_a_package_s_init(tmp_path):
    graph = _package(tmp_path, {
        "__init__.py": "",
        "a.py": "from .sub.c import x\n",
        "sub/__init__.py": "from .b import y\n",
        "sub/b.py": "from ..a import z\n",
        "sub/c.py": "from .b import y\n",     # inside sub: importing b does not run sub's __init__ again
    })
    assert graph["pkg.a"] == {"pkg.sub.c", "pkg.sub"} and graph["pkg.sub.c"] == {"pkg.sub.b"}
    assert cycles(graph) == [["pkg.a", "pkg.sub", "pkg.sub.b", "pkg.a"]]


def test_the_walker_finds_a_module_outside_the_cli_that_imports_it(tmp_path):
    graph = _package(tmp_path, {
        "__init__.py": "",
        "cli/__init__.py": "from .app import main\n",
        "cli/app.py": "from ..lib import work\n",
        "lib.py": "def work():\n    from pkg.cli.app import main\n",
    })
    renamed = {name.replace("pkg", "engine", 1): {t.replace("pkg", "engine", 1) for t in targets}
               for name, targets in graph.items()}
    assert cli_importers(renamed) == ["engine.lib -> engine.cli", "engine.lib -> engine.cli.app"]
    assert cycles(renamed) == [["engine.cli", "engine.cli.app", "engine.lib", "engine.cli"],
                               ["engine.cli.app", "engine.lib", "engine.cli.app"]]


# --- layers (issue 25) -----------------------------------------------------------------------------

def folder_of(module: str, folders: set[str], root: str = "engine") -> str:
    """The section a module belongs to: its folder under `root`, "cli" for `root.__main__`, else
    "top" (the package's __init__ and its loose modules)."""
    parts = module.split(".")
    if module == f"{root}.__main__":
        return "cli"
    return parts[1] if len(parts) > 1 and parts[1] in folders else "top"


def folders_in(package: Path) -> set[str]:
    """The folders (packages) directly inside a package's folder."""
    return {path.parent.name for path in package.glob("*/__init__.py")}


ENGINE_FOLDERS = folders_in(Path(engine.__file__).parent)


def layer_problems(graph: dict[str, set[str]], folders=ENGINE_FOLDERS, layers=LAYERS, forbidden=FORBIDDEN,
                   root: str = "engine") -> list[str]:
    """`a -> b: why` for every import from a folder into one of the same or a higher layer, or that
    a rule of FORBIDDEN names."""
    rank = {folder: index for index, layer in enumerate(layers) for folder in layer}
    problems = []
    for module, targets in sorted(graph.items()):
        for target in sorted(targets):
            mine, theirs = folder_of(module, folders, root), folder_of(target, folders, root)
            if mine == theirs:
                continue
            if (mine, theirs) in forbidden:
                problems.append(f"{module} -> {target}: {forbidden[mine, theirs]}")
            elif rank[theirs] >= rank[mine]:
                where = "above it" if rank[theirs] > rank[mine] else "beside it, in the same layer"
                problems.append(f"{module} -> {target}: {mine} may not import {theirs} ({where})")
    return problems


def two_way_folder_pairs(graph: dict[str, set[str]], folders=ENGINE_FOLDERS,
                         root: str = "engine") -> list[tuple[str, str]]:
    """Pairs of folders that import each other, either way round through any modules."""
    edges = {(folder_of(module, folders, root), folder_of(target, folders, root))
             for module, targets in graph.items() for target in targets}
    return sorted({tuple(sorted(edge)) for edge in edges if edge[0] != edge[1] and edge[::-1] in edges})


def folders_missing_from_layers(folders=ENGINE_FOLDERS, layers=LAYERS) -> list[str]:
    return sorted(set(folders) - {folder for layer in layers for folder in layer})


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_every_folder_imports_only_folders_below_it():
    graph = engine_graph()
    assert "engine.machines.records" in graph["engine.gears.cases"]   # the walk sees imports between folders
    assert layer_problems(graph) == []


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_no_two_folders_import_each_other():
    assert two_way_folder_pairs(engine_graph()) == []


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_simulation_never_imports_the_models():
    graph = engine_graph()
    found = [f"{module} -> {target}" for module, targets in graph.items() if module.startswith("engine.simulation")
             for target in targets if target.startswith(("engine.hobbing", "engine.turning"))]
    assert any(target.startswith("engine.verifier") for target in graph["engine.simulation.hobbing.reading"])
    assert found == []


def test_every_folder_of_the_engine_has_its_layer():
    assert ENGINE_FOLDERS >= {"cli", "db", "verifier", "release"}   # the walk sees the folders
    assert folders_missing_from_layers() == []
    assert {folder for layer in LAYERS for folder in layer} - ENGINE_FOLDERS == {"top"}   # and no stale name


# --- importers/ (design notes §3, Contract: a top-level folder of importers that create jobs) ---------
# It stands between the engine's library and its command line: it imports the engine (drawings,
# turning, programs), only engine.cli imports it, and it never imports engine.cli.
IMPORTERS = "importers"


def importer_problems(graph: dict[str, set[str]]) -> list[str]:
    """`a -> b: why` for an engine module below the command line importing importers/, or an
    importer importing the command line."""
    def in_cli(module):
        return module == CLI or module.startswith(CLI + ".") or module in CLI_ENTRY_POINTS
    problems = []
    for module, targets in sorted(graph.items()):
        for target in sorted(targets):
            if target.split(".")[0] == IMPORTERS and module.startswith("engine.") and not in_cli(module):
                problems.append(f"{module} -> {target}: only the command line imports the importers")
            if module.split(".")[0] == IMPORTERS and in_cli(target):
                problems.append(f"{module} -> {target}: the importers stand below the command line")
    return problems


def engine_and_importers_graph():
    root = Path(engine.__file__).parent.parent
    return import_graph((Path(engine.__file__).parent, "engine"), (root / IMPORTERS, IMPORTERS))


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_importers_stand_between_the_library_and_the_command_line():
    graph = engine_and_importers_graph()
    assert "importers.dxf" in graph["engine.cli.turning"]              # the walk sees the CLI's import
    assert any(target.startswith("engine.programs") for target in graph["importers.dxf"])
    assert importer_problems(graph) == []
    assert cycles(graph) == []


def test_the_importer_check_finds_the_library_importing_an_importer():
    graph = {"engine.programs.demo": {"importers.sample"}, "importers.sample": {"engine.cli.db"},
             "engine.cli.db": {"importers.sample"}}
    assert importer_problems(graph) == [
        "engine.programs.demo -> importers.sample: only the command line imports the importers",
        "importers.sample -> engine.cli.db: the importers stand below the command line"]


FAKE_LAYERS = [("top",), ("db",), ("gears",), ("simulation",), ("hobbing", "turning"), ("cli",)]


def test_the_layer_check_finds_a_folder_importing_one_above_or_beside_it(tmp_path):
    graph = _package(tmp_path, {
        "__init__.py": "",
        "errors.py": "",
        "db/__init__.py": "from ..errors import x\n",      # down to the loose modules: allowed
        "gears/__init__.py": "",
        "gears/models.py": "def f():\n    from ..hobbing.crowned import Model\n",
        "hobbing/__init__.py": "",
        "hobbing/crowned.py": "from ..gears import models\nfrom ..turning import names\n",
        "turning/__init__.py": "",
        "turning/names.py": "from ..db import x\n",
        "tools/__init__.py": "",
    })
    folders = folders_in(tmp_path / "pkg")
    assert layer_problems(graph, folders, FAKE_LAYERS, {}, root="pkg") == [
        "pkg.gears.models -> pkg.hobbing: gears may not import hobbing (above it)",
        "pkg.gears.models -> pkg.hobbing.crowned: gears may not import hobbing (above it)",
        "pkg.hobbing.crowned -> pkg.turning: hobbing may not import turning (beside it, in the same layer)",
        "pkg.hobbing.crowned -> pkg.turning.names: hobbing may not import turning (beside it, in the same layer)",
    ]
    assert two_way_folder_pairs(graph, folders, root="pkg") == [("gears", "hobbing")]
    assert folders_missing_from_layers(folders, FAKE_LAYERS) == ["tools"]


def test_the_layer_check_finds_the_simulation_importing_a_model(tmp_path):
    graph = _package(tmp_path, {
        "__init__.py": "",
        "simulation/__init__.py": "",
        "simulation/walk.py": "from ..gears import records\n",
        "simulation/run.py": "from ..hobbing.cylindrical import Model\n",
        "gears/__init__.py": "",
        "gears/records.py": "",
        "hobbing/__init__.py": "",
        "hobbing/cylindrical.py": "from ..simulation.walk import x\n",
    })
    layers_allowing_it = [("top",), ("gears",), ("hobbing",), ("simulation",)]   # a reordered list
    folders = folders_in(tmp_path / "pkg")
    assert layer_problems(graph, folders, layers_allowing_it, root="pkg") == [
        "pkg.hobbing.cylindrical -> pkg.simulation: hobbing may not import simulation (above it)",
        "pkg.hobbing.cylindrical -> pkg.simulation.walk: hobbing may not import simulation (above it)",
        "pkg.simulation.run -> pkg.hobbing: the simulation never imports the models that made the program",
        "pkg.simulation.run -> pkg.hobbing.cylindrical: the simulation never imports the models that made the program",
    ]
    assert two_way_folder_pairs(graph, folders, root="pkg") == [("hobbing", "simulation")]


def test_the_model_registry_fails_closed_while_empty(monkeypatch):
    from engine.errors import EngineError
    from engine.gears import models
    monkeypatch.setattr(models, "MODELS", {})
    monkeypatch.setattr(models, "DEFERRED", {})   # nor any model's module waiting to be imported
    with pytest.raises(EngineError, match="gear models not registered: cylindrical, duplex"):
        models.model_for_class(None, "cylindrical")


def test_a_partly_filled_model_registry_is_refused_too():
    """A library user who imports one model module only must not get an ancestor's model for a
    class whose own model is missing (a taper gear planned as a cylindrical one): the registry
    is refused until every model node has registered. Run in a fresh interpreter, where nothing
    else has imported the models."""
    import subprocess
    import sys
    code = ("from engine.hobbing import cylindrical\n"
            "from engine.gears.models import registered_models\n"
            "registered_models()\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 1
    assert "gear models not registered: duplex, taper, crowned, worm_wheel, turning" in done.stderr


def test_every_model_node_is_registered_by_the_model_packages():
    from engine.errors import EngineError
    from engine.gears import models
    assert sorted(models.registered_models()) == sorted(models.MODEL_NODES)
    with pytest.raises(EngineError, match="'bevel' is not in MODEL_NODES"):
        models.register_model("bevel")
