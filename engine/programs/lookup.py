"""A stored program found from what an operator has in hand (`engine programs show`): its id, or
the hash on its lineage line (engine.nc.lineage) read off a file on the control, the INPUT
hash of the job's parameters or the TEMPLATE hash of the version it was made from; and the
programs stored, filtered (`engine programs list`). A program is shown with the layout (line
ending, final newline: engine.nc.layout) its template version records, the one its file was
written with: a later change of the class's layout is a later version and leaves it as it was."""
from __future__ import annotations

import re
from datetime import date, datetime
from typing import TYPE_CHECKING

import msgspec
from msgspec.structs import asdict, replace

from ..db.listing import day_range, records, require_class
from ..db.origin import GEAR_PLANT, MADE_AT_SQL, made_at, plant_name
from ..errors import EngineError
from ..nc.layout import ENDING_NAMES, NcLayout, nc_text
from ..nc.lineage import UNVERIFIED
from .rendering import LISTED_RENDERING, MATCH, NOT_RENDERED, PLANT, Renderer, Rendering, stored_rendering

if TYPE_CHECKING:
    from ..db.connection import Connection

MIN_HASH_DIGITS = 8   # what the lineage line shows
HASH_PREFIX = re.compile(r"[0-9a-f]{8,64}")
RECORD = """
SELECT p.id, p.job_id, j.gear_id, p.gear_class, p.template_version, p.draft, p.unverified, p.template_hash,
       p.input_hash, p.stored_by, p.created_at, p.name, p.lines, v.line_ending, v.final_newline
FROM program p JOIN job j ON j.id = p.job_id
JOIN template_version_rows v ON v.gear_class = p.gear_class AND v.version = p.template_version"""
BY_ID = RECORD + " WHERE p.id = %s"
# left(…, 8) is what the indexes program_input_hash, program_template_hash hold; the LIKE then checks the longer prefix.
BY_HASH = RECORD + """
WHERE (left(p.input_hash, 8) = left(%(prefix)s, 8) AND p.input_hash LIKE %(prefix)s || '%%')
   OR (left(p.template_hash, 8) = left(%(prefix)s, 8) AND p.template_hash LIKE %(prefix)s || '%%')
ORDER BY p.id"""


class ProgramRecord(msgspec.Struct, frozen=True):
    """What the database records of one program, and its lines as stored (lineage line included)."""
    id: int
    job_id: int
    gear_id: int | None
    gear_class: str
    template_version: int
    draft: bool
    unverified: bool   # no verifier read it (instantiate --class --unverified): never written to a file
    template_hash: str
    input_hash: str | None
    stored_by: str | None
    created_at: datetime
    name: str
    lines: list[str]
    layout: NcLayout = NcLayout()   # its template version's line ending and final newline
    rendering: Rendering | None = None   # MATCH, MISMATCH, UNCHECKED, REFUSED or PLANT (engine.programs.rendering);
    #                                      None: not checked

    @property
    def text(self) -> str:
        """The program with its version's line ending and final newline, as its file was written."""
        return nc_text(self.lines, self.layout)

    @property
    def plant(self) -> int:
        """The plant that made it (engine.db.origin): 0 the head office or a single database."""
        return made_at(self.id)

    @property
    def verifier_said(self) -> str:
        """Whether a verifier read the program: said only of one that is the rendering the engine
        made and stored (a MISMATCH is lines no verifier read; an UNCHECKED one cannot be told)."""
        if self.unverified:
            return f"{UNVERIFIED}: no verifier read it, never written to a file"
        if self.rendering is not None and self.rendering.status == PLANT:
            return f"stored as verified at {plant_name(self.plant)}: proved there when it was made, not re-read here"
        if self.rendering is None or not self.rendering.matches:
            status = self.rendering.status if self.rendering else "not checked"
            return f"{status}: not known to be the program the machine's verifier read (see rendering)"
        return "read by the machine's verifier"

    def as_dict(self) -> dict:
        """The record with the common key names (program_id, class), its lines and its version's
        layout as the config file and a template CSV name it (line_ending "lf" or "crlf")."""
        fields = asdict(self)
        del fields["layout"]
        fields["rendering"] = self.rendering.as_dict() if self.rendering else None
        return {"program_id": fields.pop("id"), "plant": self.plant, "class": fields.pop("gear_class"), **fields,
                "created_at": self.created_at.isoformat(), "line_ending": ENDING_NAMES[self.layout.line_ending],
                "final_newline": self.layout.final_newline}


def find_programs(conn: Connection, program_id: int | None = None, prefix: str | None = None) -> list[ProgramRecord]:
    """The program with this id, or every program matching the hash prefix (one of the two), each
    checked against its rendering (engine.programs.rendering): what a screen shows it with."""
    return [replace(record, rendering=stored_rendering(conn, record.id)) for record in _found(conn, program_id, prefix)]


def _found(conn: Connection, program_id: int | None, prefix: str | None) -> list[ProgramRecord]:
    if (program_id is None) == (prefix is None):
        raise EngineError("give a program id or --hash H (8 or more hex digits of its lineage line), one of the two")
    if program_id is not None:
        return [program_record(conn, program_id)]
    assert prefix is not None   # one of the two
    return programs_with_hash(conn, prefix)


def program_record(conn: Connection, program_id: int) -> ProgramRecord:
    """The program with this id; EngineError if there is none."""
    found = conn.execute(BY_ID, (program_id,)).fetchone()
    if found is None:
        raise EngineError(f"program {program_id} does not exist; find it by its lineage line with "
                          "`engine programs show --hash H`")
    return _record(found)


def programs_with_hash(conn: Connection, prefix: str) -> list[ProgramRecord]:
    """Every program whose INPUT hash or TEMPLATE hash starts with `prefix` (8 or more hex digits,
    as on the lineage line); EngineError if none does."""
    prefix = checked_prefix(prefix)
    found = [_record(row) for row in conn.execute(BY_HASH, {"prefix": prefix})]
    if not found:
        raise EngineError(f"no program has an input or template hash starting with {prefix}")
    return found


def _record(row: tuple) -> ProgramRecord:
    *fields, line_ending, final_newline = row
    # mypy counts *fields (of unknown length) as filling every field, the layout as one too many
    return ProgramRecord(*fields, NcLayout(line_ending, final_newline))   # type: ignore[call-arg]


def checked_prefix(text: str) -> str:
    """The hash as typed (any case), or EngineError if it cannot be a lineage hash."""
    prefix = text.strip().lower()
    if not HASH_PREFIX.fullmatch(prefix):
        raise EngineError(f"--hash {text!r}: give {MIN_HASH_DIGITS} or more hex digits, as on the program's "
                          "lineage line (`; PROGRAM <id> TEMPLATE <class> v<n> <hash8> INPUT <hash8>`)")
    return prefix


LIST_PROGRAMS = """
SELECT p.id AS program_id, """ + MADE_AT_SQL.format(id="p.id") + """ AS plant,
       p.name, p.job_id, j.gear_id, p.gear_class AS class, p.template_version, p.draft,
       p.unverified, p.template_hash, p.input_hash, cardinality(p.lines) AS line_count, p.stored_by, p.created_at,
       """ + LISTED_RENDERING + """ AS rendering
FROM program p JOIN job j ON j.id = p.job_id
WHERE (%(class)s::text IS NULL OR p.gear_class = %(class)s)
  AND (%(plant)s::int IS NULL OR """ + MADE_AT_SQL.format(id="p.id") + """ = %(plant)s)
  AND (%(gear)s::int IS NULL OR (j.gear_id = %(gear)s AND """ + GEAR_PLANT.format(id="p.id") + """))
  AND (%(job)s::bigint IS NULL OR p.job_id = %(job)s)
  AND (%(draft)s::boolean IS NULL OR p.draft = %(draft)s)
  AND (%(since)s::date IS NULL OR p.created_at >= %(since)s::date)
  AND (%(until)s::date IS NULL OR p.created_at < %(until)s::date + 1)
ORDER BY p.id"""


def list_programs(conn: Connection, gear_class: str | None = None, gear_id: int | None = None,
                  job_id: int | None = None, draft: bool | None = None, since: date | None = None,
                  until: date | None = None, check: bool = False, plant: int | None = None) -> list[dict]:
    """Every program matching all filters given (None: any), by id: its record without its lines.
    draft True: made from a draft version (for trying only); False: from a released one.
    `rendering`: UNCHECKED for a program that cannot be rendered again (its job edited since), else
    NOT_RENDERED, or with `check` MATCH, MISMATCH or REFUSED (engine.programs.rendering: milliseconds each, so
    a list renders only when asked). `verifier`: UNVERIFIED, "read" (checked now: MATCH),
    "stored as verified, unchecked" (not rendered in this list) or "-" (MISMATCH, REFUSED, UNCHECKED).
    `plant`: only the programs made at that plant (engine.db.origin; each says its `plant`); one made
    at another plant is listed as PLANT, "proved at plant N", never rendered here. A gear id is a gear
    of the plant named (this database's without one): gear ids of plants collide."""
    require_class(conn, gear_class)
    filters = {"class": gear_class, "gear": gear_id, "job": job_id, "draft": draft, "plant": plant,
               **day_range(since, until)}
    renderer = Renderer(conn)
    return [_listed(renderer, record, check) for record in records(conn.execute(LIST_PROGRAMS, filters))]


def _listed(renderer: Renderer, record: dict, check: bool) -> dict:
    if check and record["rendering"] == NOT_RENDERED:
        record["rendering"] = renderer.rendering(record["program_id"]).status
    return {**record, "verifier": listed_verifier(record["unverified"], record["rendering"])}


STORED_UNCHECKED = "stored as verified, unchecked"   # the record's word alone: no rendering, no proof now


def listed_verifier(unverified: bool, rendering: str) -> str:
    """What a list says of the verifier: "read" only of a program checked now (MATCH: its lines are
    the rendering and pass the proof); of one not checked, what the record alone says."""
    if unverified:
        return UNVERIFIED
    if rendering == MATCH:
        return "read"
    if rendering == PLANT:
        return "stored as verified at its plant"
    return STORED_UNCHECKED if rendering == NOT_RENDERED else "-"
