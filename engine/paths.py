"""Where the project's data folders are: migrations/, schema/ and seed_templates/ (design
notes §3: top level of the checkout, where DBAs and reviewers read them).

A checkout (an editable install, or PYTHONPATH on a worktree) reads them beside the `engine`
package. A wheel ships the same folders as the package `engine_data` (setup.py maps them),
found by importlib (a namespace package: its search locations), so `pip install .` is not an
empty install."""
from importlib.util import find_spec
from pathlib import Path

SOURCE_ROOT = Path(__file__).resolve().parent.parent
DATA_PACKAGE = "engine_data"


def _is_checkout(root: Path) -> bool:
    """The project's own tree, not site-packages (which may hold some other `migrations/`)."""
    return (root / "pyproject.toml").is_file() and (root / "schema" / "schema.sql").is_file()


def data_folder(name: str) -> Path:
    """The folder `name` (migrations, schema, seed_templates) of this installation."""
    if _is_checkout(SOURCE_ROOT):
        return SOURCE_ROOT / name
    spec = find_spec(f"{DATA_PACKAGE}.{name}")
    folders = [Path(location) for location in (spec.submodule_search_locations if spec else ())]
    return next((folder for folder in folders if folder.is_dir()), SOURCE_ROOT / name)


MIGRATIONS_DIR = data_folder("migrations")
SCHEMA_DIR = data_folder("schema")
SEED_DIR = data_folder("seed_templates")
