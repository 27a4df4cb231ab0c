"""How an imported NC file ends its lines (issue 17): LF or CRLF, and whether its last line ends
with one. The rows hold the lines without their endings, so `M17` of a CRLF file and of an LF
file is one component; the class keeps the layout (gear_class.line_ending, .final_newline) and
its program is written back with it, byte for byte. The layout is part of the template: each
stored version records it (template_version_rows), a change of it is a new draft
version, and a program is written with its version's layout."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec
from msgspec.structs import replace

from ..errors import EngineError
from ..names import line_breaking, shown

if TYPE_CHECKING:
    from ..db.connection import Connection

LF, CRLF = "\n", "\r\n"
ENDING_NAMES = {LF: "lf", CRLF: "crlf"}   # as the config file and a template CSV write them


class NcLayout(msgspec.Struct, frozen=True):
    """LF with a final newline is what the engine's own classes write; an imported class keeps its file's."""
    line_ending: str = LF
    final_newline: bool = True

    @property
    def said(self) -> str:
        """"CRLF, no final newline": the layout in words, for reports."""
        ending = ENDING_NAMES[self.line_ending].upper()
        return f"{ending}, {'final newline' if self.final_newline else 'no final newline'}"

    def ending_from(self, ending: str | None) -> NcLayout:
        """This layout with another line ending, if one is given (a machine's, from the config
        file); the final newline stays the class's."""
        return self if ending is None else replace(self, line_ending=ending)


def split_nc_text(path, text: str) -> tuple[list[str], NcLayout]:
    """The lines of `text` without their endings, and its layout. A file mixing LF and CRLF is
    refused: one ending per class is what the program is written back with."""
    final_newline = text.endswith("\n")
    lines = text.split("\n")
    if final_newline:
        lines.pop()
    ended = lines if final_newline else lines[:-1]   # lines followed by "\n"
    crlf = bool(ended) and ended[0].endswith("\r")
    other = next((number for number, line in enumerate(ended, start=1) if line.endswith("\r") != crlf), None)
    if other is not None:
        names = ("CRLF", "LF") if crlf else ("LF", "CRLF")
        raise EngineError(f"{path} mixes line endings: line 1 ends with {names[0]}, line {other} "
                          f"{shown(lines[other - 1])} with {names[1]}; convert the file to one line ending")
    if crlf:
        lines = [line[:-1] for line in ended] + lines[len(ended):]
    refuse_broken_lines(path, lines)
    return lines, NcLayout(CRLF if crlf else LF, final_newline)


def refuse_broken_lines(path, lines: list[str]) -> None:
    """A line holding a character that ends a line elsewhere (a CR alone, FF, NEL, LS, PS) is one
    line here and two on a control or editor: no program may hold it (program_lines_unbroken)."""
    for number, line in enumerate(lines, start=1):
        breaking = line_breaking(line)
        if breaking is not None:
            raise EngineError(f"{path} line {number} {shown(line)} holds U+{ord(breaking):04X}, which breaks an NC "
                              "line on a control; remove it or make it a line ending")


def nc_text(lines: list[str], layout: NcLayout) -> str:
    """The lines as the imported file wrote them."""
    text = layout.line_ending.join(lines)
    return text + layout.line_ending if layout.final_newline else text


def store_layout(conn: Connection, gear_class: str, layout: NcLayout) -> bool:
    """Give the class this layout; True if that changed it. A change is a change of the class's
    template: the database makes it a new version (a draft until released; version_layout_change),
    unless this transaction made one already."""
    changed = conn.execute("UPDATE gear_class SET line_ending = %s, final_newline = %s WHERE name = %s "
                           "AND (line_ending, final_newline) IS DISTINCT FROM (%s, %s) RETURNING name",
                           (layout.line_ending, layout.final_newline, gear_class,
                            layout.line_ending, layout.final_newline)).fetchone()
    return changed is not None


# The version's recorded layout; the class's own for its current version not stored yet.
LAYOUT = """
SELECT coalesce(v.line_ending, g.line_ending), coalesce(v.final_newline, g.final_newline)
FROM gear_class g LEFT JOIN template_version_rows v ON v.gear_class = g.name AND v.version = %s
WHERE g.name = %s"""


def class_layout(conn: Connection, gear_class: str, version: int | None = None) -> NcLayout:
    """The layout the class's template `version` writes (its current version if None): what
    its programs of that version are written with, LF with a final newline for a class not imported."""
    row = conn.execute(LAYOUT, (version, gear_class)).fetchone()
    if row is None:
        raise EngineError(f"class {gear_class!r} does not exist; see `engine template list`")
    return NcLayout(row[0], row[1])
