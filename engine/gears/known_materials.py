"""The materials table material knows, and the one-line refusal of a gear whose material it lacks
(issue 31): read on every instantiate, so this module imports nothing of the CSV import's
(engine.gears.materials holds the list, show and import)."""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..db.connection import Connection

NAMES = 'SELECT name FROM material ORDER BY lower(name) COLLATE "C"'
SHOWN_NAMES = 5   # the known materials a refusal names, closest first


def material_names(conn: Connection) -> list[str]:
    return [row[0] for row in conn.execute(NAMES)]


def unknown_material(what: str, material: str, known: list[str]) -> str:
    """One line: the thing, that table material lacks its material, the known ones closest first
    (rapidfuzz's WRatio) and what to do. Its cutting speeds bound the hob's (§C): never guessed."""
    from rapidfuzz import process  # only for a refusal (issue 28: start-up)

    closest = [name for name, _, _ in process.extract(material, known, limit=SHOWN_NAMES)] if known else []
    more = f", and {len(known) - len(closest)} more: `engine materials list`" if len(known) > len(closest) else ""
    return (f"{what} is not a known material (known, closest first: {', '.join(closest) or 'none'}{more}); "
            "write one of them, or add it with its cutting speeds: `engine materials import FILE.csv`")
