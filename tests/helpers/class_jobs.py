"""A class made from a real program (issue 17): the engine's own Emco lathe program imported as
class emco_neg with its speed and feed bound, the LinuxCNC pawn, and the stored record read back."""
from __future__ import annotations

import json
import re

import psycopg

from helpers.shared_data import shared_data

DATA = shared_data()
EMCO_DRAWING = DATA / "dxf" / "emco_lathe_testNegDXF_R14.dxf"
PAWN = DATA / "nc" / "linuxcnc" / "lathe_pawn.ngc"          # LinuxCNC lathe program

# A shop's lathe program of one rough pass at Ø36 from the face (Z2) to Z-40, approached from X44
# (tests/test_turning_class_jobs.py; the adversary of issue 32 sends it as a class job): the largest
# radius a feed runs at is 22 (its start), over Z-40…2, so the blank assumed is Ø44 Z-40…2.
SHAFT_PROGRAM = """%
O0001 (SHAFT)
G21 G18 G40 G90
G00 X124.000 Z50.000
T0101
G97 S600 M03
G98 F150.000
G00 X44.000 Z2.000
G01 X36.000 Z2.000
G01 X36.000 Z-40.000
G00 X44.000 Z-40.000
G00 X44.000 Z2.000
G00 X124.000 Z50.000
M05
M30
%
"""


def ok(result):
    assert result.exit_code == 0, result.output
    return result


def refused(result) -> str:
    assert result.exit_code == 1, result.output
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output, result.stderr
    return result.stderr.strip()


def stored_program(url, program_id: int) -> tuple[list[str], list[str], bool]:
    """(the lines its template made, its lineage lines, its record's unverified)."""
    with psycopg.connect(url) as conn:
        lines, row_ids, unverified = conn.execute("SELECT lines, row_ids, unverified FROM program WHERE id = %s",
                                                  (program_id,)).fetchone()
    made = [text for text, row in zip(lines, row_ids) if row != LINEAGE_ROW]
    return made, [text for text, row in zip(lines, row_ids) if row == LINEAGE_ROW], unverified


def import_emco(run, tmp_path):
    """The engine's program imported as class emco_neg, its speed and feed parameters: (file, lines)."""
    source, feed = engine_program_file(run, tmp_path)
    lines = source.read_text().splitlines()
    bound = {word for line in lines for word in line.split() if re.fullmatch(rf"[A-Z]?0*({SPEED}|150)(\.0*)?", word)}
    assert feed == 150 and bound == {f"S{SPEED}", "F150.000"}   # so each value is bound at one address only
    params = tmp_path / "params.json"
    params.write_text(json.dumps({"program_name": "EMCO_NEG", "speed": SPEED, "feed": feed}))
    ok(run("import-nc", source, "--class", "emco_neg", "--params", params))
    return source, lines


SPEED = 600
LINEAGE_ROW = -1


def engine_program_file(run, tmp_path):
    """A program the ISO lathe's verifier reads, made from a real drawing and written to a file;
    imported as it is, its lineage line is refused, and it is taken out as the refusal says.
    Returns the file and the feed of the drawing's operations."""
    job = json.loads(ok(run("import-dxf", EMCO_DRAWING, "--speed", SPEED, "--program-name", "EMCO_NEG",
                            "--json")).stdout)
    written = tmp_path / "EMCO_NEG.NC"
    ok(run("instantiate", "--job", job["job_id"], "--out", written))
    refusal = refused(run("import-nc", written, "--class", "emco_neg"))
    number = int(re.search(r" line (\d+) is a lineage line", refusal)[1])
    lines = written.read_text().splitlines()
    del lines[number - 1]
    source = tmp_path / "emco_neg.nc"
    source.write_text("\n".join(lines) + "\n")
    return source, job["operations"][0]["feed"]
