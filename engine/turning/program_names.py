"""The name of a turning job's program, by the lathe's dialect (issue 27).

On an 840D lathe the name IS the program: `%_N_<name>_MPF`, the file `<name>.MPF`, so it must
fit the 840D rule (engine/names.py: two letters first, at most 24 characters). On an ISO
(Fanuc-type) lathe the program is its O number (O0001 … O8999, the job's) and the name only
the comment after it, `O0005 (NAME)`: a file name that does not make an 840D-style name is no
reason to refuse the drawing there. The stored name must still fit the engine's program-name
rule (the database checks it, schema/core.sql safe_name), so on ISO such a drawing's program is
named after its O number and the report says so; the drawing's file name stays in the
program's (DRAWING …) comment. A name given with --program-name is taken as given or refused,
never altered, on either lathe.
"""
from __future__ import annotations

from pathlib import Path

import msgspec

from ..errors import EngineError
from ..names import NAME_RULES, checked, is_safe, shown

# A program name made from a drawing's file name: upper case (the NC does not tell case), with
# the separators file names use where 840D names have _; nothing cut, nothing else replaced.
FILE_NAME_SEPARATORS = str.maketrans({"-": "_", ".": "_", " ": "_"})


class ProgramNaming(msgspec.Struct, frozen=True):
    """How a dialect names a program the user did not name."""
    dialect: str
    by_number: bool   # the program is its O number: a file name that makes no name gives way to it


NAMING = {"turning_840d": ProgramNaming("840D", False), "turning_iso": ProgramNaming("ISO", True)}


def made_from(file_name: str) -> str:
    """The file name in upper case, - . and spaces as _, without its extension."""
    return Path(file_name).stem.upper().translate(FILE_NAME_SEPARATORS)


def number_name(program_number: int) -> str:
    """The name of an ISO program known by its number: DXF_O0005 (fits the stored-name rule)."""
    return f"DXF_O{program_number:04d}"


def drawing_names(file_name: str, program_name: str | None, gear_class: str,
                  program_number: int) -> tuple[str, str, list[str]]:
    """(drawing, program name, notes) of the job: the file name as it is (printed in the program's
    comments) and the program name given, else made from the file name (ISO: else after the
    program number). EngineError when a given name does not fit, or a made one on 840D."""
    drawing = checked("drawing", file_name, "drawing file name", "rename the file")
    if program_name is not None:
        return drawing, checked("program", program_name, "--program-name"), []
    made, naming = made_from(file_name), NAMING.get(gear_class, NAMING["turning_840d"])
    if is_safe("program", made):
        return drawing, made, []
    why = f"the program name {shown(made)} made from its file name does not fit ({NAME_RULES['program'].rule})"
    if not naming.by_number:
        raise EngineError(f"drawing {file_name}: on an {naming.dialect} lathe the name is the program; {why}; "
                          "give one with --program-name NAME")
    name = number_name(program_number)
    return drawing, name, [f"program O{program_number:04d} ({name}): {why}; on an {naming.dialect} lathe the "
                           "program is its O number and the name a comment, so it is named after the number "
                           "(--program-name NAME names it)"]
