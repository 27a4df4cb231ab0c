"""The house (issue 11): engine/ is laid out as the design's sections, no two modules import each
other in a circle (imports inside functions count: a cycle is a cycle of the design, whenever it
runs; so does a package's __init__, which runs when any module below it is first imported), and
nothing below the command line imports it. The walker reads the source with `ast`; each check is
also run on a small package of its own that has the fault."""
import ast
from pathlib import Path

import engine
import importers

DESIGN_FOLDERS = ("templates", "library", "gears", "hobbing", "turning", "programs", "db", "cli")
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
    return import_graph((Path(engine.__file__).parent, "engine"), (Path(importers.__file__).parent, "importers"))


def test_no_import_cycle_in_the_package():
    graph = engine_graph()
    assert len(graph) > 80          # the walk read the whole package
    assert cycles(graph) == []


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
    assert loose_modules(folder) == ["csv_reader.py", "errors.py", "memory.py", "names.py", "paths.py", "pictures.py"]


def test_every_module_says_what_it_is_in_its_first_line():
    for package in (engine, importers):
        assert modules_not_saying_what_they_are(Path(package.__file__).parent) == []


def test_the_layout_checks_find_a_missing_folder_a_loose_module_and_a_silent_module(tmp_path):
    for name in DESIGN_FOLDERS[1:]:
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text(f'"""The {name} section."""\n')
    (tmp_path / "gear_import.py").write_text('# a comment first\n"""Gears from CSV."""\n')
    (tmp_path / "db" / "seed.py").write_text("import csv\n")
    assert missing_design_folders(tmp_path) == ["templates"]
    assert loose_modules(tmp_path) == ["gear_import.py"]
    assert modules_not_saying_what_they_are(tmp_path) == ["db/seed.py", "gear_import.py"]


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
