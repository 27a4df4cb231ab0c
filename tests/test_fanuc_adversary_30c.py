"""Adversary checks of the Fanuc hobbing programs (issue 30): ways a wrong program could reach a
Fanuc hobber, each shown refused in one line with nothing stored.

A Fanuc control stores a program by its O number, not by its name, so the O number is the
program's identity on the machine: reference docs/reference/fanuc-egb.md §F7 states a gear's
program is O<program_number_base + gear id> on the machine (O1043 for gear 43 at base 1000).
A program of gear 43 written as O1044 would replace gear 44's program when it is read in.

A stored job made again (`engine instantiate --job N`) is held to what a new job is refused for on
a Fanuc hobber (engine.hobbing.dialects.FANUC_REFUSALS): the record may have changed since
(orient_before_coupling set, program_number_base cleared), or the job may have been written in
SQL (shift per part on a Fanuc job)."""
from __future__ import annotations

import math

import pytest
from helpers.releases import release_draft
from psycopg import sql

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear
from engine.programs.remake import instantiate_job
from engine.release.gate import release
from engine.templates.versions import released_version

FANUC = "hobber-fanuc"
NO_TAILSTOCK = Choices(tailstock=False)
PROGRAMS = "SELECT count(*) FROM program"
BASE = 1000            # the seeded hobber-fanuc's program_number_base (seed data, fanuc-egb.md §F7)
HEADER_ROW = 201       # seed_templates/classes/helical.csv: the Fanuc O line
G81_ROW = 1501         # seed_templates/classes/helical.csv: the Fanuc G81
EDIT = sql.SQL("UPDATE template_view SET {} = %s WHERE gear_class = %s AND id = %s")


def edit_and_release(conn, gear_class: str, row_id: int, output: str) -> None:
    """A DBA's edit of one row's output through template_view, released."""
    assert conn.execute(EDIT.format(sql.Identifier("o")), (output, gear_class, row_id)).rowcount == 1
    release_draft(conn, gear_class)


def o_line(gear_id: int) -> str:
    """The O line a gear's program must carry on the seeded Fanuc hobber (§F7)."""
    return f"O{BASE + gear_id:04d} (GEAR{gear_id})"


def refused_and_nothing_stored(conn, make, *words: str) -> str:
    before = conn.execute(PROGRAMS).fetchone()[0]
    with pytest.raises(EngineError) as refused:
        make()
    message = str(refused.value)
    assert all(word in message for word in words), message
    assert "\n" not in message and "nothing stored" in message
    assert conn.execute(PROGRAMS).fetchone()[0] == before
    return message


@pytest.mark.parametrize("written", ['f"O{program_number + 1:04d} ({program_name})"',   # O1044: gear 44's
                                     'f"O{gear_id} ({program_name})"',                      # O43: base dropped
                                     '"O1000 (" + program_name + ")"'])                    # the base alone
def test_a_template_row_writing_another_o_number_is_refused(conn, written):
    assert o_line(43) == "O1043 (GEAR43)"
    assert instantiate_gear(conn, 43, machine=FANUC, choices=NO_TAILSTOCK).lines[1] == o_line(43)
    edit_and_release(conn, "helical", HEADER_ROW, written)
    refused_and_nothing_stored(conn, lambda: instantiate_gear(conn, 43, machine=FANUC, choices=NO_TAILSTOCK),
                               "O1043", "program_number_base")


def test_the_release_gate_refuses_a_draft_that_renumbers_a_stored_fanuc_jobs_program(conn):
    """The impact proves the stored Fanuc job's program the draft changes: O1044 for gear 43 is refused."""
    stored_fanuc_job(conn)
    before = released_version(conn, "helical")
    assert conn.execute(EDIT.format(sql.Identifier("o")),
                        ('f"O{program_number + 1:04d} ({program_name})"', "helical", HEADER_ROW)).rowcount == 1
    with pytest.raises(EngineError) as refused:
        release(conn, "helical", dry_run=True)
    assert "O1044" in str(refused.value) and "O1043" in str(refused.value)
    assert released_version(conn, "helical") == before


def test_a_template_writing_the_o_number_without_a_name_still_carries_the_gears_number(conn):
    """`O1043` alone names no program, but its number is the gear's: accepted (the comment is optional)."""
    edit_and_release(conn, "helical", HEADER_ROW, 'f"O{program_number:04d}"')
    assert instantiate_gear(conn, 43, machine=FANUC, choices=NO_TAILSTOCK).lines[1] == "O1043"


def stored_fanuc_job(conn, gear_id: int = 43) -> int:
    return instantiate_gear(conn, gear_id, machine=FANUC, choices=NO_TAILSTOCK).job_id


def test_a_stored_job_made_again_after_the_record_orients_before_coupling_is_refused(conn):
    """The record now says the spindle is oriented before coupling (840D SPOS), which a new Fanuc
    job is refused for: the job made again must not drop the orientation silently."""
    job_id = stored_fanuc_job(conn)
    conn.execute("UPDATE machine SET orient_before_coupling = true WHERE name = %s", (FANUC,))
    refused_and_nothing_stored(conn, lambda: instantiate_job(conn, job_id), "orient")


def test_a_stored_job_made_again_after_the_record_drops_its_program_number_base_is_refused(conn):
    """Without program_number_base the program has no O number (§F7): not O0043."""
    job_id = stored_fanuc_job(conn)
    conn.execute("UPDATE machine SET program_number_base = NULL WHERE name = %s", (FANUC,))
    refused_and_nothing_stored(conn, lambda: instantiate_job(conn, job_id), "program_number_base")


def test_a_fanuc_job_given_a_shift_per_part_in_sql_is_made_again_with_the_macro_clamp(conn):
    """Hob shift per part is written on Fanuc (the #500 clamp, fanuc-egb.md §F9): the job made
    again carries it, proved like a new job's, not the stray refusal "G81 before Y" it met before."""
    job_id = stored_fanuc_job(conn)
    conn.execute("UPDATE job SET params = params || '{\"shift_per_part\": 0.5}' WHERE id = %s", (job_id,))
    lines = instantiate_job(conn, job_id).lines
    assert "#500=#500+0.500 (HOB SHIFT PER PART)" in lines and "G0 Y#500" in lines


def test_a_stored_job_made_again_after_the_records_helix_sign_flipped_follows_the_record(conn):
    """egb_helix_sign −1 after the job was stored: the program made again has P = +β for the
    right-hand gear 43 (P = −h_gear·c·z·s·β = −(+1)(+1)(+1)(−1)·15 = +15, §F5), and is proved so."""
    job_id = stored_fanuc_job(conn)
    conn.execute("UPDATE machine SET egb_helix_sign = -1 WHERE name = %s", (FANUC,))
    lines = instantiate_job(conn, job_id).lines
    assert [line for line in lines if line.startswith("G81")] == ["G81 T41 L-1 Q3. P15.0000"]


# G81's words are the gear's and the hob's themselves (fanuc-egb.md §F5, §F6): T = z2, |L| = z0,
# Q = m_n, |P| = β. Gear 43: m_n 3, z2 41, β 15° right hand, a 1-start right-hand hob; L = −1 and
# P = −15 on the seeded DIN record (egb_helix_sign +1). Each pair below gives the same ratio
# |L|/T = 1/41 and the same sin P/(T·Q) = sin 15°/123 as the right words, so only the words
# themselves tell them apart; §F4's arrangement of the control's formula is derived, not read, so
# a program must not rest on it being exactly right.
Z2, Z0, MN, BETA = 41, 1, 3.0, 15.0
SAME_RATIO_AND_TERM = [
    f"G81 T{2 * Z2} L-{2 * Z0} Q{MN / 2:g} P-{BETA:.4f}",                                # T82 L-2 Q1.5
    f"G81 T{3 * Z2} L-{3 * Z0} Q{MN / 3:g}. P-{BETA:.4f}",                               # T123 L-3 Q1.
    f"G81 T{Z2} L-{Z0} Q{MN / math.sin(math.radians(BETA)):.5f} P-90.",                  # Q11.59111 P-90.
]


@pytest.mark.parametrize("written", SAME_RATIO_AND_TERM)
def test_a_g81_whose_words_are_not_the_gears_and_hobs_is_refused(conn, written):
    right = f"G81 T{Z2} L-{Z0} Q{MN:g}. P-{BETA:.4f}"
    assert right == "G81 T41 L-1 Q3. P-15.0000"
    assert [line for line in instantiate_gear(conn, 43, machine=FANUC, choices=NO_TAILSTOCK).lines
            if line.startswith("G81")] == [right]
    edit_and_release(conn, "helical", G81_ROW, f'"{written}"')
    refused_and_nothing_stored(conn, lambda: instantiate_gear(conn, 43, machine=FANUC, choices=NO_TAILSTOCK),
                               written.split()[1])
