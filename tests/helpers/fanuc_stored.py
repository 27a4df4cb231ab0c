"""A stored 840D hobbing program's Fanuc twin, stored beside it (issue 30): a Fanuc hobber record
(the 840D program's machine record with dialect "fanuc", and an egb_helix_sign where given), a
copy of the program's job on it, and the program rewritten line by line by
tests/helpers/fanuc_programs.py (each Fanuc line keeps the template row id of the 840D line it
comes from; the header names the Fanuc machine, the lineage line the new id). The plot tests
(tests/test_fanuc_hobbing_plot.py) read it through the library: it carries what no template
writes (a line left in 840D form, Q/P on a record without egb_helix_sign). It is no rendering
of a template version, so a command that renders stored programs again
(engine.programs.rendering) finds it a MISMATCH: a CLI test plots the program
`engine instantiate --machine hobber-fanuc` makes instead."""
from __future__ import annotations

import json

from engine.gears.records import load_gear, load_hobs
from engine.machines.records import load_machine
from helpers.fanuc_programs import fanuc_program

FANUC_HOBBER = "hobber-fanuc-twin"
COPY_MACHINE = """
INSERT INTO machine
SELECT (jsonb_populate_record(NULL::machine, to_jsonb(m) || %s::jsonb)).* FROM machine m WHERE m.name = %s"""
COPY_JOB = """
INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params, cutting, work_holding_id)
SELECT gear_id, gear_class, %s, hob_id, params, module_params, cutting, work_holding_id FROM job WHERE id = %s
RETURNING id"""
PROGRAM = """
SELECT p.lines, p.row_ids, p.trace, p.job_id, p.gear_class, p.template_version, p.template_hash, p.name,
       j.machine, j.gear_id, j.hob_id
FROM program p JOIN job j ON j.id = p.job_id WHERE p.id = %s"""
SUBMIT = """
INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace)
VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s)"""


def fanuc_hobber(conn, like: str, helix_sign: int | None = None) -> str:
    """The record `like` as a Fanuc hobber (once per transaction); → its name."""
    found = conn.execute("SELECT 1 FROM machine WHERE name = %s", (FANUC_HOBBER,)).fetchone()
    if found is None:
        changes = {"name": FANUC_HOBBER, "dialect": "fanuc", "egb_helix_sign": helix_sign}
        conn.execute(COPY_MACHINE, (json.dumps(changes), like))
    return FANUC_HOBBER


def fanuc_twin(conn, program_id: int, helix_sign: int | None = None, mistake: tuple = ()) -> tuple[int, int]:
    """Store the program's Fanuc twin on the Fanuc hobber; → (its job id, its program id).
    `mistake`: (line, written instead) to store a line other than the translation's."""
    lines, row_ids, trace, job_id, gear_class, version, digest, name, like, gear_id, hob_id = \
        conn.execute(PROGRAM, (program_id,)).fetchone()
    machine = load_machine(conn, fanuc_hobber(conn, like, helix_sign))
    gear, hob = load_gear(conn, gear_id), next(h for h in load_hobs(conn) if h.id == hob_id)
    new_job = conn.execute(COPY_JOB, (machine.name, job_id)).fetchone()[0]
    new_id = conn.execute("SELECT nextval('program_id_seq')").fetchone()[0]
    fanuc, ids = ["%"], [row_ids[0]]
    for line, row_id in zip(lines, row_ids):
        translated = fanuc_program([line], gear, hob, machine)[1:-1]
        fanuc += [renamed(text, program_id, new_id, like, machine.name) for text in translated]
        ids += [row_id] * len(translated)
    fanuc, ids = [*fanuc, "%"], [*ids, row_ids[-1]]
    fanuc = [dict([mistake]).get(text, text) if mistake else text for text in fanuc]
    conn.execute(SUBMIT, (new_id, new_job, gear_class, version, digest, name, fanuc, ids, json.dumps(trace)))
    return new_job, new_id


def renamed(text: str, old_id: int, new_id: int, old_machine: str, new_machine: str) -> str:
    """The header's machine and the lineage line's program id, the twin's."""
    if text == f"(MACHINE {old_machine})":
        return f"(MACHINE {new_machine})"
    return text.replace(f"(PROGRAM {old_id} ", f"(PROGRAM {new_id} ", 1)
