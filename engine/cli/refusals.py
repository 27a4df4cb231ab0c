"""Which role may do what the database refused (SQLSTATE 42501, insufficient privilege): the
refusal names the object (`permission denied for table gear`), and each object the engine writes
is written by one role (docs/design.md §10, schema/schema.sql section roles). The user is told
that role, so they ask for the right one; an object not in the table (or a server speaking
another language) gets every role and what each does."""
from __future__ import annotations

import re

# What each role does, in the words a user asks for it with.
ROLE_DOES = {
    "engine_runner": "makes programs",
    "engine_editor": "edits templates and golden tests",
    "engine_releaser": "releases templates",
    "engine_planner": "imports gears, units, hobs, cases, work-holdings, machines and materials",
}
# The objects each role writes (tables, views, sequences, functions), by the name the server says.
WRITES = {
    "engine_planner": ("gear", "gear_unit", "hob", "cutting_case", "cutting_case_id_seq", "work_holding",
                       "machine", "material"),
    "engine_runner": ("job", "job_id_seq", "program", "program_id_seq", "program_submission", "store_program",
                      "confirm_job_cases", "drawing", "drawing_id_seq", "near_duplicate_seen"),
    "engine_editor": ("template_view", "gear_class", "replace_class_template", "template_test",
                      "template_test_id_seq", "near_duplicate_intended", "near_duplicate_intended_id_seq",
                      "sql_translation"),
    "engine_releaser": ("release_template", "template_release"),
}
ROLE_OF = {name: role for role, names in WRITES.items() for name in names}
REFUSED_OBJECT = re.compile(r"permission denied for (?:table|view|sequence|function|procedure) (\S+)")


def roles_that_may(message: str) -> str:
    """`engine_planner imports gears, …` for a refusal of an object one role writes; else every
    role with what it does."""
    found = REFUSED_OBJECT.search(message)
    role = ROLE_OF.get(found.group(1).strip('"')) if found else None
    if role is not None:
        return f"{role} {ROLE_DOES[role]}"
    return ", ".join(f"{name} {does}" for name, does in ROLE_DOES.items())


def refusal_line(first_line: str) -> str:
    """The one line of a refusal for the session's role: what the server said, that nothing was
    stored, and the role to ask for."""
    return (f"the database refused this for your role ({first_line}); its transaction was rolled back, "
            f"nothing stored: ask for the role that may do it ({roles_that_may(first_line)})")
