"""The layout of the tests (issue 25): a test module imports no other test module (what tests
share lives in tests/helpers/, a package, or in a fixture plugin), and the top of tests/ holds
test modules and conftest.py only, so a newcomer tells a test from shared code by its place.
Each rule is also run on a fake tree that breaks it, to show the check can fail."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
TOP_LEVEL_ALLOWED = {"conftest.py"}   # besides test_*.py


def imported_modules(path: Path) -> set[str]:
    """Top-level names of every module `path` imports, at any depth (imports inside functions count)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module.split(".")[0])
    return names


def names_of_test_modules(folder: Path) -> set[str]:
    return {path.stem for path in folder.glob("test_*.py")}


def imports_of_test_modules(folder: Path) -> list[str]:
    """'importer -> imported' for every module of the tree that imports a test module of its top."""
    tests = names_of_test_modules(folder)
    return sorted(f"{path.relative_to(folder)} -> {name}" for path in folder.rglob("*.py")
                  for name in imported_modules(path) & tests)


def stray_modules(folder: Path) -> list[str]:
    """Modules at the top of the tree that are neither test modules nor conftest.py."""
    return sorted(path.name for path in folder.glob("*.py")
                  if not path.name.startswith("test_") and path.name not in TOP_LEVEL_ALLOWED)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_no_module_of_the_tests_imports_a_test_module():
    assert imports_of_test_modules(TESTS) == []


def test_the_top_of_tests_holds_test_modules_and_conftest_only():
    assert stray_modules(TESTS) == []


def test_helpers_is_a_package_the_tests_import_by_name():
    assert (TESTS / "helpers" / "__init__.py").is_file()
    assert any("helpers" in imported_modules(path) for path in TESTS.glob("test_*.py"))


def fake_tree(folder: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text, encoding="utf-8")
    return folder


def test_the_import_check_fails_on_a_test_module_importing_another(tmp_path):
    tree = fake_tree(tmp_path, {
        "test_a.py": "from test_b import shared\n",
        "test_b.py": "def shared():\n    return 1\n",
        "test_c.py": "def test_late():\n    import test_b.sub\n",
        "helpers/__init__.py": "",
        "helpers/reader.py": "import test_a\n",
        "test_d.py": "from helpers.reader import x\nfrom . import test_b\n",   # relative: a package's own
    })
    assert imports_of_test_modules(tree) == ["helpers/reader.py -> test_a", "test_a.py -> test_b",
                                             "test_c.py -> test_b"]


def test_the_top_level_check_fails_on_a_helper_beside_the_tests(tmp_path):
    tree = fake_tree(tmp_path, {"test_a.py": "", "conftest.py": "", "nc_reader.py": "", "helpers/nc.py": ""})
    assert stray_modules(tree) == ["nc_reader.py"]
