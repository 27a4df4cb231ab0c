"""Where the project's data folders are (top level of the checkout, design notes §3)."""
from pathlib import Path

PROJECT_ROOT = Path(__file__).resolve().parent.parent
MIGRATIONS_DIR = PROJECT_ROOT / "migrations"
SCHEMA_DIR = PROJECT_ROOT / "schema"
SEED_DIR = PROJECT_ROOT / "seed_templates"
