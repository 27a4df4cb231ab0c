"""The lineage line every stored program carries (design notes §7, issue 15):
`; PROGRAM <id> TEMPLATE <class> v<version> <hash8> INPUT <hash8>` (` DRAFT` appended for a
program made from a draft, then ` UNVERIFIED` for one no verifier read: `engine instantiate --class
--unverified`), so an operator can match a file on the control to its record.

The engine writes it, not a template row: every program has it, whatever its template says.
Its row id is -1 (no template row). The database checks it against the program, its template
version and the hash of its job's stored parameters (check_program_release, job_input_hash).
read_lineage reads it back, from the writer's own WORDS and comment forms: exactly as stored (the
simulation's header rule), or as pasted off a control (the web view's look-up)."""
from __future__ import annotations

import re
from functools import cache
from typing import NamedTuple

from ..errors import EngineError
from ..names import NAME_RULES, shown

LINEAGE_ROW_ID = -1
UNVERIFIED = "UNVERIFIED"   # the word of a program no verifier read, in its lineage line and listings
DRAFT = "DRAFT"             # the word of a program made from a draft version
DRY_RUN_ID = "DRY-RUN"      # where a dry run's line has the program id: it draws none (engine.programs.batches)
# The words in the order the database's program_lineage() writes them. The writer (lineage_words)
# fills them in and the reader (read_lineage) is built from them, each field's text as FIELDS spells
# it: ids are bigints (19 digits at most), the class a class name (engine.names: no `;`, `=` or `(`,
# so no header claim rides in it), versions integers (10), the hashes' first 8 hex digits.
WORDS = "PROGRAM {program_id} TEMPLATE {gear_class} v{version} {template_hash} INPUT {input_hash}"
CLASS_NAME = NAME_RULES["class"].pattern
FIELDS = {"program_id": f"[0-9]{{1,19}}|{DRY_RUN_ID}", "gear_class": CLASS_NAME, "version": "[0-9]{1,10}",
          "template_hash": "[0-9a-f]{8}", "input_hash": "[0-9a-f]{8}"}
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


def lineage_words(program_id: int | str, gear_class: str, version: int, template_hash: str, input_hash: str,
                  draft: bool, unverified: bool = False) -> str:
    """The words of the line, as the database's program_lineage() writes them (`program_id`
    DRY_RUN_ID for a dry run's)."""
    words = WORDS.format(program_id=program_id, gear_class=gear_class, version=version,
                         template_hash=template_hash[:8], input_hash=input_hash[:8])
    return words + (f" {DRAFT}" if draft else "") + (f" {UNVERIFIED}" if unverified else "")


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


class LineageRecord(NamedTuple):
    """What a lineage line says of its program."""
    program_id: int | str    # DRY_RUN_ID on a dry run's line
    gear_class: str
    version: int
    template_hash: str       # 8 hex digits, lower case
    input_hash: str          # 8 hex digits, lower case ("" on a pasted line without it)
    draft: bool
    unverified: bool


def read_lineage(text: str, pasted: bool = False) -> LineageRecord | None:
    """What the lineage line `text` says, or None for any other text.

    As stored (the default): exactly as lineage_line writes it in one of the comment forms, each
    word spelt and spaced as written, nothing before or after. The simulation reads a stored
    program so (engine.simulation.hobbing.headers): the line it lets name a class is the engine's,
    which the database held to the record, never one with a header claim added or respelt.

    `pasted`: as an operator copies it off a control into the web view's look-up: either comment
    form, closed or not, after a block number (`N10 `), in any case, words apart by any spaces,
    the INPUT hash left out (a record without one: its line ends `INPUT`). The look-up holds what
    the line says to the record its id names, so the leniency leads to no other program."""
    found = _pasted_pattern().fullmatch(text) if pasted else _stored_match(text)
    if found is None:
        return None
    said = found.groupdict()
    number = said["program_id"]
    return LineageRecord(int(number) if number.isdigit() else DRY_RUN_ID, said["gear_class"], int(said["version"]),
                         said["template_hash"].lower(), (said["input_hash"] or "").lower(),
                         said["draft"] is not None, said["unverified"] is not None)


def _stored_match(text: str) -> re.Match | None:
    """The words matched inside the first comment form that encloses them exactly."""
    for opening, closing in _comment_forms():
        if text.startswith(opening) and text.endswith(closing) and len(text) >= len(opening) + len(closing):
            found = _stored_pattern().fullmatch(text, len(opening), len(text) - len(closing))
            if found is not None:
                return found
    return None


@cache
def _comment_forms() -> tuple[tuple[str, str], ...]:
    """(opening, closing) of every dialect's comment form: `(` and `)`, `; ` and nothing."""
    forms = {*COMMENT_FORMS.values(), DEFAULT_COMMENT_FORM}
    return tuple(sorted((opening, closing) for opening, closing in (form.split("{}") for form in forms)))


@cache
def _pasted_pattern() -> re.Pattern:
    """Any comment form's opening after an optional block number, the words, any closing or none."""
    forms = _comment_forms()
    openings = "".join(re.escape(opening.strip()) for opening, _ in forms)
    closings = "|".join(re.escape(closing) for _, closing in forms if closing)
    return re.compile(rf"(?:N[0-9]+\s*)?[{openings}]\s*{_words(True)}\s*(?:{closings})?", re.IGNORECASE)


@cache
def _stored_pattern() -> re.Pattern:
    """The words as written, inside a comment form (_stored_match)."""
    return re.compile(_words(False))


def _words(pasted: bool) -> str:
    """WORDS with each field a named group of its FIELDS text, then DRAFT, then UNVERIFIED, each
    optional. Stored: one space apart, as written; pasted: any spaces, the INPUT hash optional."""
    space = r"\s+" if pasted else " "
    tokens = WORDS.split(" ")
    pattern = _token_pattern(tokens[0])
    for token in tokens[1:]:
        piece = space + _token_pattern(token)
        pattern += f"(?:{piece})?" if pasted and token == "{input_hash}" else piece
    return pattern + "".join(f"(?:{space}(?P<{word.lower()}>{word}))?" for word in (DRAFT, UNVERIFIED))


def _token_pattern(token: str) -> str:
    """One word of WORDS: its text as written, a `{field}` in it a named group (`v{version}`)."""
    before, brace, rest = token.partition("{")
    if not brace:
        return re.escape(token)
    name, _, after = rest.partition("}")
    return f"{re.escape(before)}(?P<{name}>{FIELDS[name]}){re.escape(after)}"
