"""What is replicated, as data: the head office's tables a plant receives (with the row filter and
column list of each), and a plant's history the head office receives. The rules behind each line are
docs/design.md §12's; the database's own checks of these tables are schema/schema.sql's section plants."""
from __future__ import annotations

import msgspec

TEMPLATES_PUBLICATION = "engine_templates"   # at the head office
HISTORY_PUBLICATION = "engine_plant_history"   # at every plant


class Published(msgspec.Struct, frozen=True):
    """One table of a publication. row_filter: SQL of a WHERE on columns only ever set, never
    cleared (a filter a row can leave turns its UPDATE into a DELETE at the subscriber); columns:
    the columns sent (None: all)."""
    table: str
    row_filter: str | None = None
    columns: tuple[str, ...] | None = None


# The head office's: released versions only (released is set once by release_template, so a
# draft never passes and a retired version never leaves), their releases, the classes without the
# head office's draft counter (template_version: every draft edit would update every plant), the
# golden tests and the records a program is proved on. Deletions are not sent: a plant's history
# refers to what it ran.
HEAD_TABLES = (
    Published("gear_class", columns=("name", "parent", "description", "import_params", "line_ending",
                                     "final_newline")),
    Published("template_version_rows", row_filter="released"),
    Published("template_release"),
    Published("template_test"),
    Published("machine"),
    Published("hob"),
    Published("work_holding"),
)
HEAD_OPERATIONS = "insert, update"

# A plant's history: records, inserted once, never updated (program text stays out of UPDATEs).
HISTORY_TABLES = (Published("drawing"), Published("job"), Published("program"), Published("program_request"))
HISTORY_OPERATIONS = "insert"

# The sequences of the rows a plant makes: each plant's start at plant_first_id(number), so no two
# plants make one id (sequences are not replicated).
ID_SEQUENCES = ("drawing_id_seq", "job_id_seq", "program_id_seq", "program_request_id_seq")


def subscription_name(number: int, kind: str) -> str:
    """The subscription (and its slot at the publisher: one per plant, so plants never share one):
    engine_plant_3_templates at plant 3, engine_plant_3_history at the head office."""
    return f"engine_plant_{number}_{kind}"
