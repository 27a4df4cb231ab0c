"""Which hobbing model serves which gear class: the nearest ancestor that has one."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..hobbing.crowned import CrownedModel
from ..hobbing.cylindrical import CylindricalModel
from ..hobbing.duplex import DuplexModel
from ..hobbing.taper import TaperModel
from ..hobbing.worm_wheel import WormWheelModel
from ..turning.names import TurningModel

if TYPE_CHECKING:
    from ..db.connection import Connection

# The hobbing model of a node of the group-technology tree serves it and every class below
# it that has no model of its own.
MODELS = {
    "cylindrical": CylindricalModel(),
    "duplex": DuplexModel(),
    "taper": TaperModel(),
    "crowned": CrownedModel(),
    "worm_wheel": WormWheelModel(),
    "turning": TurningModel(),   # names only (for lint): turning jobs come from drawings
}

CLASS_ANCESTRY = """
WITH RECURSIVE up(name, parent, depth) AS (
    SELECT name, parent, 0 FROM gear_class WHERE name = %s
    UNION ALL
    SELECT g.name, g.parent, up.depth + 1 FROM gear_class g JOIN up ON g.name = up.parent
    WHERE up.depth < 50)
SELECT name FROM up ORDER BY depth"""


def ancestry(conn: Connection, gear_class: str) -> list[str]:
    """The class and its ancestors, nearest first."""
    return [row[0] for row in conn.execute(CLASS_ANCESTRY, (gear_class,))]


def model_for_class(conn: Connection, gear_class: str):
    for name in ancestry(conn, gear_class):
        if name in MODELS:
            return MODELS[name]
    return None
