"""A seeded database spoiled for the batch tests: five gears made bad each in its own way (no
class, other modules, a crowning on a 4 mm face, two teeth) and the hobbing machine's tailstock
widened to Ø45 mm with no work-holding of the library to clamp on instead (issue 29), so that a
batch has several different refusals to name."""
from __future__ import annotations

import psycopg


def spoil(url: str) -> None:
    with psycopg.connect(url) as conn:
        conn.execute("UPDATE machine SET tailstock_diameter = 45 WHERE name = 'hobber-840d'")
        conn.execute("DELETE FROM work_holding")   # else a gear the tailstock does not clear gets an arbor
        conn.execute("UPDATE gear SET gear_class = NULL WHERE id = 44")
        conn.execute("UPDATE gear SET module = 5, tip_diameter = 135, root_diameter = 112.5 WHERE id = 45")
        conn.execute("UPDATE gear SET module = 1.25, tip_diameter = 62.5, root_diameter = 56.875 WHERE id = 46")
        conn.execute("UPDATE gear SET crowning = 0.2, face_width = 4 WHERE id = 51")
        conn.execute("UPDATE gear SET teeth = 2, tip_diameter = NULL, root_diameter = NULL WHERE id = 47")
