"""A batch reports, not floods (issue 31): its notes are counted by the kind given where each was
made (engine.notes), the first 3 of each kind shown, and one summary line says what was stored,
skipped and noted; --quiet prints the summary alone, --json keeps every note."""
from __future__ import annotations

import json
import math
import pickle
import random

import psycopg
import pytest

from engine.notes import OTHER, Note, kind_of, prefixed

FIRST, PER_KIND = 1000, 12   # gear ids of the batch; gears drawn of each pattern
SHOWN = 3                    # notes shown of each kind
INSERT = ("INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, helix_angle, face_width, tip_diameter, "
          "root_diameter, material, hardness, quality_grade) "
          "VALUES (%s, 'spur', %s, %s, 20, 0, %s, %s, %s, %s, %s, %s)")
# (module mm, face width mm, material, hardness HB, grade) of seeded gears 46 (m1.5, cut with a 2-start
# hob: an even tooth count has no hunting tooth) and 42 (m2 grade 7: its feeds are bounded)
PATTERNS = ((1.5, 12, "20CrMnTi", 180, 8), (2.0, 20, "40Cr", 250, 7))
HOBS_OF_BATCH = """SELECT g.teeth, h.starts FROM program p JOIN job j ON j.id = p.job_id
JOIN gear g ON g.id = j.gear_id JOIN hob h ON h.id = j.hob_id WHERE p.id BETWEEN %s AND %s"""


@pytest.fixture
def batch(run):
    """PER_KIND gears of each pattern with random tooth counts (even for the first), tip and root
    diameters m(z + 2) and m(z - 2.5); → the --gears range."""
    rng = random.Random(31)
    with psycopg.connect(run.url) as conn:
        for number in range(2 * PER_KIND):
            module, face, material, hardness, grade = PATTERNS[number // PER_KIND]
            teeth = 2 * rng.randint(12, 40) if number < PER_KIND else rng.randint(17, 60)
            conn.execute(INSERT, (FIRST + number, module, teeth, face, module * (teeth + 2), module * (teeth - 2.5),
                                  material, hardness, grade))
    return f"{FIRST}-{FIRST + 2 * PER_KIND - 1}"


def test_a_note_keeps_its_kind_when_said_of_a_program_and_sent_back_by_a_worker():
    note = prefixed("GEAR7: ", Note("rough: axial feed bounded to 3.00", "feed bounded"))
    assert note == "GEAR7: rough: axial feed bounded to 3.00" and kind_of(note) == "feed bounded"
    assert kind_of(pickle.loads(pickle.dumps(note))) == "feed bounded"
    assert kind_of("a plain string") == OTHER


def test_the_json_keeps_every_note_and_counts_them_by_kind(run, batch):
    made = run("instantiate", "--gears", batch, "--workers", 2, "--json")
    assert made.exit_code == 0, made.output
    report = json.loads(made.stdout)
    counts = report["note_kinds"]
    assert sum(counts.values()) == len(report["notes"]) and counts.get("feed bounded", 0) > 0
    with psycopg.connect(run.url) as conn:
        jobs = conn.execute(HOBS_OF_BATCH, report["program_ids"]).fetchall()
    sharing = sum(math.gcd(starts, teeth) > 1 for teeth, starts in jobs)   # no hunting tooth: gcd(z0, z2) > 1
    assert len(jobs) == 2 * PER_KIND and sharing > 0 and counts["no hunting tooth"] == sharing


def test_the_text_shows_the_first_notes_of_each_kind_and_one_summary_line(run, batch):
    dry = json.loads(run("instantiate", "--gears", batch, "--dry-run", "--json").stdout)
    counts = dry["note_kinds"]
    assert len(counts) >= 2
    made = run("instantiate", "--gears", batch, "--dry-run")
    assert made.exit_code == 0, made.output
    shown = [line for line in made.stderr.splitlines() if line.startswith("note: ")]
    assert len(shown) == sum(min(count, SHOWN) for count in counts.values())
    for kind, count in counts.items():
        assert f"{count} note(s) of kind {kind!r}" in made.stderr
    noted = ", ".join(f"{count} {kind}" for kind, count in counts.items())
    assert made.stdout.splitlines() == [f"dry run: would store {2 * PER_KIND} program(s), "
                                        f"{dry['lines']} lines; nothing stored; skipped none; notes: {noted}"]


def test_quiet_prints_the_summary_line_alone(run, batch):
    loud = run("instantiate", "--gears", batch, "--dry-run")
    quiet = run("instantiate", "--gears", batch, "--dry-run", "--quiet")
    assert quiet.exit_code == 0 and quiet.stderr == "" and quiet.stdout == loud.stdout, quiet.output
    alone = run("instantiate", "--gear", 42, "--dry-run", "--quiet")
    assert alone.exit_code == 1 and "--quiet shortens a batch's report" in alone.stderr
