"""Comparing two programs made from the same job and template: every line equal, the lineage
line's program id aside (each program names its own id; its version and hashes must be equal)."""
from __future__ import annotations

import re

PROGRAM_ID = re.compile(r"^([;(] ?PROGRAM )\d+(?= TEMPLATE )")
# A program's lines in SQL (alias p), the lineage line's id written as #.
LINES_ID_MASKED = r"""ARRAY(SELECT CASE WHEN l.row_id = -1 THEN regexp_replace(l.text, '^([;(] ?PROGRAM )\d+', '\1#')
                                  ELSE l.text END
                  FROM unnest(p.lines, p.row_ids) WITH ORDINALITY AS l (text, row_id, number) ORDER BY l.number)"""


def id_masked(lines: list[str]) -> list[str]:
    return [PROGRAM_ID.sub(r"\1#", line, count=1) for line in lines]
