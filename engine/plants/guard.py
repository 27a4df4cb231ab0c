"""What a plant refuses before it starts: drafts and releases are the head office's (docs/design.md
§12). The database refuses every write to the head office's tables at a plant too (the trigger
head_office_writes_it, schema/schema.sql section plants); this check says it before a long gate runs."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..db.connection import scalar
from ..errors import EngineError

if TYPE_CHECKING:
    from ..db.connection import Connection


def refuse_at_a_plant(conn: Connection, doing: str) -> None:
    """One line naming the plant and where to do it, if this database is a plant."""
    number = int(scalar(conn.execute("SELECT plant_number()")))
    if number > 0:
        raise EngineError(f"{doing}: this database is plant {number}; templates are edited and released at the head "
                          "office only, and its released versions are replicated here: do it there")
