"""Where the project's data folders are: migrations/, schema/ and seed_templates/ (design
notes §3: top level of the checkout, where DBAs and reviewers read them).

A checkout (an editable install, or PYTHONPATH on a worktree) reads them beside the `engine`
package. A wheel ships the same folders as `engine_data/` beside the installed `engine` package
(setup.py maps them), so `pip install .` is not an empty install. The installed folder is taken
by its place, not looked up on sys.path: `python -m engine` puts the current folder first, and an
`engine_data/migrations/` there must not be applied."""
from pathlib import Path

SOURCE_ROOT = Path(__file__).resolve().parent.parent   # the checkout, or site-packages in a wheel install


def _is_checkout(root: Path) -> bool:
    """The project's own tree, not site-packages (which may hold some other `migrations/`)."""
    return (root / "pyproject.toml").is_file() and (root / "schema" / "schema.sql").is_file()


def data_folder(name: str, root: Path = SOURCE_ROOT) -> Path:
    """The folder `name` (migrations, schema, seed_templates) of the installation at `root`."""
    return root / name if _is_checkout(root) else root / "engine_data" / name


MIGRATIONS_DIR = data_folder("migrations")
SCHEMA_DIR = data_folder("schema")
SEED_DIR = data_folder("seed_templates")
# The project's sample turning drawing (seed-000 convention, design notes §8): users copy it.
SAMPLE_DRAWING = SEED_DIR / "drawings" / "sample_shaft.dxf"


def runtime_folder() -> Path:
    """Where a running `engine serve` leaves its pid file, for `engine serve stop` to find:
    ENGINE_RUNTIME_DIR if set, else run/ in the engine's per-user data folder (beside the
    embedded server's pgdata)."""
    import os

    override = os.environ.get("ENGINE_RUNTIME_DIR")
    if override:
        return Path(override).expanduser().resolve()
    import platformdirs

    return Path(platformdirs.user_data_dir("nc-template-engine")) / "run"
