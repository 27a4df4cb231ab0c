"""The lineage line every stored program carries (design notes §7, issue 15):
`; PROGRAM <id> TEMPLATE <class> v<version> <hash8> INPUT <hash8>` (` DRAFT` appended for a
program made from a draft, then ` UNVERIFIED` for one no verifier read: `engine instantiate --class
--unverified`), so an operator can match a file on the control to its record.

The engine writes it, not a template row: every program has it, whatever its template says.
Its row id is -1 (no template row). The database checks it against the program, its template
version and the hash of its job's stored parameters (check_program_release, job_input_hash)."""
from __future__ import annotations

import re

from ..errors import EngineError
from ..names import shown

LINEAGE_ROW_ID = -1
UNVERIFIED = "UNVERIFIED"   # the word of a program no verifier read, in its lineage line and listings
# Comment forms by dialect: ISO/Fanuc comments are in parentheses, 840D ones follow `;`.
COMMENT_FORMS = {"iso": "({})", "fanuc": "({})", "fanuc-g81.4": "({})"}
DEFAULT_COMMENT_FORM = "; {}"
# The line a template writes its version on (the lineage follows it), and the program header
# lines it must not come before when a template writes none.
TEMPLATE_LINE = re.compile(r"^\s*[;(]\s*TEMPLATE\s", re.IGNORECASE)
HEADER_LINE = re.compile(r"^\s*(%|;\$PATH|O\d)")
SEARCHED_LINES = 40
# What reads as a lineage line at the machine, in either comment form, whatever its id (a dry
# run's says DRY-RUN): a template row must never write one, or the program would carry a second
# lineage naming another program (check_program_lines refuses it in the database too).
# The comment may follow a block number or a move (`N10 ; PROGRAM 1 TEMPLATE …`): it reads the
# same at the control. Only an id or DRY-RUN makes one (`; program from template of spur` is a
# shop's comment). The spaces are spelled out, not \s, so the database's check (lineage_shaped,
# whose \s depends on the server's locale) reads exactly the same lines.
SPACE = "[ \t\v\f\r\n\u0085\u00a0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000\u001c-\u001f]"
LINEAGE_SHAPE = re.compile(rf"[;(]{SPACE}*PROGRAM{SPACE}+([0-9]+|DRY-RUN){SPACE}+TEMPLATE", re.IGNORECASE)
ENGINES_LINE = "the engine writes the lineage line into every program it stores"


def lineage_shaped(text: str) -> bool:
    """True for a line that reads as a lineage line (`; PROGRAM 812 TEMPLATE …`, `(PROGRAM …)`)."""
    return LINEAGE_SHAPE.search(text) is not None


def first_lineage_shaped(lines: list[str]) -> int | None:
    """The 1-based number of the first lineage-shaped line, or None."""
    return next((number for number, text in enumerate(lines, 1) if lineage_shaped(text)), None)


def refuse_lineage_shaped(name: str, lines: list[str]) -> None:
    """A template line that reads as a lineage line would give the program a second lineage,
    naming another program or version, to whoever matches the file at the machine. Checked
    where every program is made (engine.programs.verified_run), so golden tests, dry runs and
    the release gate refuse such a template, not only storing."""
    number = first_lineage_shaped(lines)
    if number is not None:
        raise EngineError(f"program {name} line {number} {shown(lines[number - 1])} reads as a lineage line, "
                          "which only the engine writes: nothing stored; remove the template row that writes it")


def lineage_words(program_id: int, gear_class: str, version: int, template_hash: str, input_hash: str,
                  draft: bool, unverified: bool = False) -> str:
    """The words of the line, as the database's program_lineage() writes them."""
    words = f"PROGRAM {program_id} TEMPLATE {gear_class} v{version} {template_hash[:8]} INPUT {input_hash[:8]}"
    return words + (" DRAFT" if draft else "") + (f" {UNVERIFIED}" if unverified else "")


def lineage_line(words: str, dialect: str) -> str:
    return COMMENT_FORMS.get(dialect, DEFAULT_COMMENT_FORM).format(words)


def with_lineage(lines: list[str], row_ids: list[int], line: str) -> tuple[list[str], list[int]]:
    """The program's lines and row ids with the lineage line after the template-version line (or,
    without one, after the program header lines)."""
    at = _position(lines)
    return lines[:at] + [line] + lines[at:], row_ids[:at] + [LINEAGE_ROW_ID] + row_ids[at:]


def _position(lines: list[str]) -> int:
    head = lines[:SEARCHED_LINES]
    found = next((number for number, text in enumerate(head) if TEMPLATE_LINE.match(text)), None)
    if found is not None:
        return found + 1
    headers = 0
    while headers < len(head) and HEADER_LINE.match(head[headers]):
        headers += 1
    return headers


def without_lineage(lines: list[str], row_ids: list[int]) -> list[str]:
    """The lines a template made (the lineage line left out): what two versions' programs compare on."""
    return [text for text, row_id in zip(lines, row_ids) if row_id != LINEAGE_ROW_ID]
