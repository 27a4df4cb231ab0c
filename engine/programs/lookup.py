"""A stored program found from what an operator has in hand (`engine programs show`): its id, or
the hash on its lineage line (engine.programs.lineage) read off a file on the control, the INPUT
hash of the job's parameters or the TEMPLATE hash of the version it was made from."""
from __future__ import annotations

import re
from dataclasses import asdict, dataclass
from datetime import datetime

from ..errors import EngineError

MIN_HASH_DIGITS = 8   # what the lineage line shows
HASH_PREFIX = re.compile(r"[0-9a-f]{8,64}")
RECORD = """
SELECT p.id, p.job_id, j.gear_id, p.gear_class, p.template_version, p.draft, p.template_hash, p.input_hash,
       p.stored_by, p.created_at, p.name, p.lines
FROM program p JOIN job j ON j.id = p.job_id"""
BY_ID = RECORD + " WHERE p.id = %s"
# left(…, 8) is what the indexes of migration 0015 hold; the LIKE then checks the longer prefix.
BY_HASH = RECORD + """
WHERE (left(p.input_hash, 8) = left(%(prefix)s, 8) AND p.input_hash LIKE %(prefix)s || '%%')
   OR (left(p.template_hash, 8) = left(%(prefix)s, 8) AND p.template_hash LIKE %(prefix)s || '%%')
ORDER BY p.id"""


@dataclass(frozen=True)
class ProgramRecord:
    """What the database records of one program, and its lines as stored (lineage line included)."""
    id: int
    job_id: int
    gear_id: int | None
    gear_class: str
    template_version: int
    draft: bool
    template_hash: str
    input_hash: str | None
    stored_by: str | None
    created_at: datetime
    name: str
    lines: list[str]

    def as_dict(self) -> dict:
        """Under the key names of every --json: program_id, job_id, gear_id, class."""
        record = asdict(self)
        return {"program_id": record.pop("id"), "class": record.pop("gear_class"), **record,
                "created_at": self.created_at.isoformat()}


def find_programs(conn, program_id: int | None = None, prefix: str | None = None) -> list[ProgramRecord]:
    """The program with this id, or every program matching the hash prefix (one of the two)."""
    if (program_id is None) == (prefix is None):
        raise EngineError("give a program id or --hash H (8 or more hex digits of its lineage line), one of the two")
    return [program_record(conn, program_id)] if program_id is not None else programs_with_hash(conn, prefix)


def program_record(conn, program_id: int) -> ProgramRecord:
    """The program with this id; EngineError if there is none."""
    found = conn.execute(BY_ID, (program_id,)).fetchone()
    if found is None:
        raise EngineError(f"program {program_id} does not exist; find it by its lineage line with "
                          "`engine programs show --hash H`")
    return ProgramRecord(*found)


def programs_with_hash(conn, prefix: str) -> list[ProgramRecord]:
    """Every program whose INPUT hash or TEMPLATE hash starts with `prefix` (8 or more hex digits,
    as on the lineage line); EngineError if none does."""
    prefix = checked_prefix(prefix)
    found = [ProgramRecord(*row) for row in conn.execute(BY_HASH, {"prefix": prefix})]
    if not found:
        raise EngineError(f"no program has an input or template hash starting with {prefix}")
    return found


def checked_prefix(text: str) -> str:
    """The hash as typed (any case), or EngineError if it cannot be a lineage hash."""
    prefix = text.strip().lower()
    if not HASH_PREFIX.fullmatch(prefix):
        raise EngineError(f"--hash {text!r}: give {MIN_HASH_DIGITS} or more hex digits, as on the program's "
                          "lineage line (`; PROGRAM <id> TEMPLATE <class> v<n> <hash8> INPUT <hash8>`)")
    return prefix
