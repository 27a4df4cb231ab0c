"""The Fanuc hobbing grammar (issue 30): a hobber whose record says dialect "fanuc" has its
programs read with the electronic gear box's "command compatible with hobbing machine" (Fanuc
15i/150i-MA operator's manual §19.9.2): `G81 T<teeth> L<±threads> [Q<module> P<helix>]` starts
the table's synchronisation with the hob, a second G81 while on changes its ratio, `G80`
cancels it. The program below is written by hand from those rules; each refusal is one line
that names the block. The record is the seeded hobber-840d's with dialect "fanuc" (its travel,
spindle maximum 1000 r/min and table maximum 120 r/min, seed_templates/machines.csv), so the
expected table speeds are S·|L|/T against the record's own maximum."""
from __future__ import annotations

import psycopg
import pytest
from helpers.verifier_programs import verifier_refusal, with_line_replaced
from msgspec.structs import replace

from engine.machines.records import Machine, load_machine
from engine.nc.lineage import lineage_line, lineage_words
from engine.verifier import verify_program
from engine.verifier.grammar import HOBBING_FANUC, HOBBING_FANUC_G81_4
from engine.verifier.lines import read_line
from engine.verifier.statements import GearBox

NAME = "GEAR42"
SPEED = 246                                   # r/min of the hob: S246
SYNC = "G81 T40 L-1 Q2.5 P15."          # 40 teeth, one left-turning thread, module 2.5 mm, helix 15°
PROGRAM = ["%", f"O1234 ({NAME})", "(GEAR 42 HELICAL)", "G21 G90 G94 G54", "T1", "G0 X61.000 Y0.000",
           "G0 Z19.576 A1.763", f"M3 S{SPEED}", "M8", SYNC, "G0 X52.500", "G1 X51.500 F13.3",
           "G1 Z-23.380 F29.7", "G0 X61.000", "G80", "M9", "M5", "G0 Z100.000", "M30", "%"]


@pytest.fixture
def fanuc(conn) -> Machine:
    """The seeded hobber's record, read in the Fanuc dialect."""
    return replace(load_machine(conn, "hobber-840d"), name="hobber-fanuc", dialect="fanuc")


def replaced(old: str, *new: str, lines: list[str] = PROGRAM) -> list[str]:
    return with_line_replaced(lines, old, *new)


def refusal(machine: Machine, lines: list[str]) -> str:
    return verifier_refusal(machine, lines, NAME)


def test_a_hand_written_fanuc_hobbing_program_is_accepted(fanuc):
    verify_program(PROGRAM, fanuc, NAME)
    verify_program(replaced(SYNC, "G81 T40 L-1"), fanuc, NAME)     # no helical compensation: neither Q nor P
    verify_program([line.replace("G0 ", "G00 ").replace("G1 ", "G01 ").replace("M3 ", "M03 ") for line in PROGRAM],
                   fanuc, NAME)


@pytest.mark.parametrize("lines, block, reason", [
    (replaced(SYNC, "G81 T40 L-1 Q2.5"), "G81 T40 L-1 Q2.5", "with Q but without P"),
    (replaced(SYNC, "G81 T40 L-1 P15."), "G81 T40 L-1 P15.", "with P but without Q"),
    (replaced(SYNC, "G81 T40 L0"), "G81 T40 L0", "a hob has at least one thread"),
    (replaced(SYNC, "G81 T0 L-1"), "G81 T0 L-1", "T0 is outside 1 … 1000"),
    (replaced(SYNC, "G81 T1001 L-1"), "G81 T1001 L-1", "T1001 is outside 1 … 1000"),
    (replaced("G80", "G80", "G1 Z-24.000 F29.7"), "G1 Z-24.000 F29.7", "no G80 since"),
    (replaced("G80"), "M30", "M30 while the table is synchronised to the hob: G80 first"),
    (replaced(SYNC), "G1 X51.500 F13.3", "a cut with the table not synchronised to the hob: G81 T… L… first"),
    (replaced("G0 Z100.000", "G0 Z100"), "G0 Z100", "Z100 needs a decimal point"),
])
def test_each_rule_refuses_its_block_in_one_line(fanuc, lines, block, reason):
    message = refusal(fanuc, lines)
    assert f"line {lines.index(block) + 1} {block!r}" in message and reason in message


@pytest.mark.parametrize("sync, reason", [
    ("G81 T40", "without L (the hob's threads)"),
    ("G81 L-1", "without T (the gear's number of teeth)"),
    ("G81 T40 L22", "L22 is outside -21 … +21, not 0"),
    ("G81 T40 L-22", "L-22 is outside -21 … +21, not 0"),
    ("G81 T40. L-1", "T is a whole count, without a decimal point"),
    ("G81 T40 L-1 Q250000 P150000", "Q250000 needs a decimal point"),
    ("G81 T40 L-1 Q2.5 P15", "P15 needs a decimal point"),
    ("G81 T40 L-1 Q30. P15.", "the module Q must be within 0.1 … 25 mm"),
    ("G81 T40 L-1 Q2.5 P-91.", "the helix angle P must be within -90 … 90°"),
    ("G81 T+40 L-1", "the number of teeth has no sign"),
    ("G81 T40 L-1 Q0. P15.", "the module Q must be within 0.1 … 25 mm"),
    ("G81 T40 L-1 X52.500", "a G81 block holds only T, L, Q, P"),
    ("G0 G81 T40 L-1", "a G81 block holds only T, L, Q, P"),
    ("G81 G80", "G81 and G80 in one block"),
    ("G81 T40 L-1 T40", "T twice in one block"),
    ("G81.4 R40 L-1", "G81.4 is not a G code"),
])
def test_a_g81_block_is_the_command_alone_with_whole_counts_in_range(fanuc, sync, reason):
    assert reason in refusal(fanuc, replaced(SYNC, sync))


@pytest.mark.parametrize("threads", [-21, 21])
def test_the_most_threads_either_way_are_accepted(fanuc, threads):
    verify_program(replaced(SYNC, f"G81 T1000 L{threads}"), fanuc, NAME)


def test_a_second_g81_while_on_replaces_the_ratio_and_the_table_speed_follows(fanuc):
    """S·|L|/T: 246·1/40 = 6.2 r/min, then 246·2/4 = 123 r/min, above the record's 120. The second
    gear is spur, P0. (the manual's helical then spur gear in succession, fanuc-egb.md §F2)."""
    assert SPEED * 2 / 4 > fanuc.table_speed_max > SPEED * 2 / 5
    cut = "G1 Z-23.380 F29.7"
    verify_program(replaced(cut, cut, "G81 T5 L-2 Q2.5 P0.", "G1 Z-24.000 F29.7"), fanuc, NAME)
    message = refusal(fanuc, replaced(cut, cut, "G81 T4 L-2 Q2.5 P0.", "G1 Z-24.000 F29.7"))
    assert "line 14 'G81 T4 L-2 Q2.5 P0.'" in message and f"the table turns at {SPEED * 2 / 4:.1f} r/min" in message


@pytest.mark.parametrize("lines, reason", [
    ([line.replace("G94", "G95") for line in PROGRAM], "G95 feeds per revolution"),
    ([line.replace("G21 ", "") for line in PROGRAM], "motion before G21 (mm) is stated"),
    ([line.replace("G90 ", "") for line in PROGRAM], "motion before G90 (absolute positions) is stated"),
    ([line.replace(" G54", "") for line in PROGRAM], "before a work offset (G54…G57) is selected"),
    (replaced("G0 X61.000 Y0.000", "G0 X61.000"), "G81 before Y (the hob shift) is positioned"),
    (replaced(f"M3 S{SPEED}", f"S{SPEED}"), "a cut with the spindle stopped"),
    (PROGRAM[1:], "the first line must be the tape mark %"),
    (PROGRAM[:-1], "the last line must be the tape mark %"),
    (replaced(f"O1234 ({NAME})", f"O9001 ({NAME})"), "O9000 … O9999 hold the machine builder's macros"),
    (replaced(f"O1234 ({NAME})", "O1234 (OTHER)"), "the header names program OTHER"),
    (replaced("G0 Z19.576 A1.763", "G0 Z19.576 A1"), "A1 needs a decimal point"),
    (replaced("G1 X51.500 F13.3", "G1 X51.500 F13"), "F13 needs a decimal point"),
    (replaced("M8", "M8 ; COOLANT"), "not a word of the Fanuc hobbing in G54 grammar"),
    (replaced("M8", "M22"), "M22 is not an M code of the Fanuc hobbing in G54 grammar"),
    (replaced("G80", "G80", "EGOFS(C)"), "EGOFS: not a word of the Fanuc hobbing in G54 grammar"),   # (C) a comment
])
def test_fanuc_framing_units_and_modes_are_those_of_the_rules(fanuc, lines, reason):
    assert reason in refusal(fanuc, lines)


def test_a_z_move_under_helical_compensation_turns_the_table_by_q_and_p(fanuc):
    """§F4: C turns Z·sin P·360/(π·T·Q)° with every Z move after G81, rapid ones too (§F7): for T10
    Q1. P30. 5.73°/mm, so G0 Z at the record's 8,000 mm/min adds 127.3 r/min to 246·1/10 = 24.6,
    above the 120 r/min table (it was accepted: the verifier bounded S·|L|/T only). The same G0 Z
    is accepted without Q and P, and the cut at F29.7 with them."""
    small = replaced(SYNC, "G81 T10 L-1 Q1. P30.")
    rapid = replaced("G1 Z-23.380 F29.7", "G0 Z-23.380", lines=small)
    message = refusal(fanuc, rapid)
    assert "line 13 'G0 Z-23.380'" in message and "the table turns at 151.9 r/min" in message
    assert "G0 Z 5.72958°/mm × 8000 mm/min" in message
    verify_program(replaced("G81 T10 L-1 Q1. P30.", "G81 T10 L-1", lines=rapid), fanuc, NAME)
    verify_program(small, fanuc, NAME)


CUT = "G1 Z-23.380 F29.7"


@pytest.mark.parametrize("after_cut, reason, after_g80", [
    ("G0 Y5.", "a Y move (hob shift) while the table is synchronised to the hob (G81, no G80 since)", "G0 Y5."),
    ("G1 Y5. Z-24.000 F29.7", "G81 has no Y term", "G0 Y5. Z-24.000"),
    ("G0 Y0.000", "a Y move (hob shift) while", "G0 Y0.000"),       # at the Y held: refused all the same
    ("G0 A2.000", "an A move (swivel) while the table is synchronised", "G0 A2.000"),
    ("T2", "a tool call T while the table is synchronised", None),
    ("G81 T40 L-1", "G81 without Q and P after a G81 that gave them", None),
])
def test_what_g81_cannot_follow_waits_for_g80(fanuc, after_cut, reason, after_g80):
    """fanuc-egb.md §F6: G81 has no Y term, so a hob shift while synchronised slides the thread
    against the teeth; a swivel or a hob change under it likewise; a re-rating G81 without Q and P
    leaves the compensation to what the manual does not say. Each was accepted before; the move
    after G80 is."""
    message = refusal(fanuc, replaced(CUT, CUT, after_cut))
    assert f"line 14 {after_cut!r}" in message and reason in message
    if after_g80 is not None:
        verify_program(replaced("G80", "G80", after_g80), fanuc, NAME)


def test_a_tool_call_waits_for_g80_and_the_hob_to_stop(fanuc):
    assert "a tool call T with the hob turning" in refusal(fanuc, replaced("G80", "G80", "T2"))
    verify_program(replaced("G0 Z100.000", "G0 Z100.000", "T2"), fanuc, NAME)


def test_a_blocks_own_m_codes_may_come_before_its_motion(fanuc):
    """When a block's M code is output, before or after its motion, is the builder's choice: `G1 Z…
    M5` may feed the hob stopping (the table stops with it, Z does not) and `T1 M3` may start the
    hob under a tool change. Both were accepted; a cut's M3 in its own block is not counted on."""
    assert "a cut with the spindle stopped" in refusal(fanuc, replaced(CUT, f"{CUT} M5"))
    assert "a tool call T with the hob turning" in refusal(fanuc, replaced("T1", lines=replaced(
        f"M3 S{SPEED}", f"T1 M3 S{SPEED}")))
    verify_program(replaced("M5", lines=replaced("G0 X61.000", "G0 X61.000 M5")), fanuc, NAME)


def test_a_semicolon_in_a_comment_is_refused(fanuc):
    """Fanuc prints ; for the end of block: `(GEAR;G1 Z-300.)` would hide a block from the verifier
    from a reader taking it so (it was read as a comment)."""
    message = refusal(fanuc, replaced("(GEAR 42 HELICAL)", "(GEAR;G0 Z-300.)"))
    assert "line 3 '(GEAR;G0 Z-300.)': a ; in a comment" in message


@pytest.mark.parametrize("lines", [
    replaced(SYNC, "G81.0 T40 L-1"), replaced(SYNC, "g81 T40 L-1"), replaced(SYNC, "G 81 T40 L-1"),
    replaced(SYNC, "G81T40L-1"), replaced(SYNC, "/G81 T40 L-1"), replaced(SYNC, "N10 G81 T40 L-1"),
    replaced(SYNC, "G81 T40 L-0"), replaced(SYNC, "G81 T40 L-1 Q2E1 P15."), replaced(SYNC, "G81 T40 L-1 Q2.5.5 P15."),
    replaced(SYNC, "G81 T40 L-1 Q2.5 P15.;"), replaced(SYNC, "G81 (X) T40 L-1"), replaced(CUT, CUT, "G81 Q2.5 P15."),
    replaced("G80", "G80 X61."), replaced("G80", "N20 G80"), replaced("G80", "M99", "G80"), replaced("G80", "%", "G80"),
    replaced("G80", "O1235", "G80"), replaced(CUT, CUT, "G28 Z100."), replaced(CUT, "G1 Z-23.380 F29.7 x5."),
    replaced(CUT, "Z-23.380 F29.7"), replaced("(GEAR 42 HELICAL)", "(GEAR % 42)"),
], ids=lambda lines: next(line for line, old in zip(lines, PROGRAM) if line != old))
def test_attacks_on_the_g81_grammar_stay_refused(fanuc, lines):
    """Spellings a Fanuc would read otherwise, or that hide words or end the program: all refused."""
    refusal(fanuc, lines)


def test_only_the_records_work_offset_is_read(fanuc):
    """The travel is stated in the record's work offset (machine.work_offset, G54 for the seeded
    hobber); another of G54…G57 would shift every position by an offset the verifier cannot see."""
    in_g55 = [line.replace("G54", "G55") for line in PROGRAM]
    assert "G55 shifts every position by a work offset" in refusal(fanuc, in_g55)
    verify_program(in_g55, replace(fanuc, work_offset="G55"), NAME)
    assert "G54 shifts every position by a work offset" in refusal(replace(fanuc, work_offset="G55"), PROGRAM)


def test_the_m_series_form_g81_4_is_its_own_dialect(fanuc):
    """dialect "fanuc-g81.4": G81.4 R<teeth 1…500> L<±threads 1…30> [Q P] and G80.4; G81 is the
    drilling cycle there, not in the table."""
    m_series = replace(fanuc, dialect="fanuc-g81.4")
    lines = replaced("G80", "G80.4", lines=replaced(SYNC, "G81.4 R40 L-1 Q2.5 P15."))
    verify_program(lines, m_series, NAME)
    verify_program(replaced("G81.4 R40 L-1 Q2.5 P15.", "G81.4 R500 L30", lines=lines), m_series, NAME)
    for sync, reason in (("G81.4 R501 L-1", "R501 is outside 1 … 500"), ("G81.4 R40 L31", "L31 is outside -30 … +30"),
                         ("G81.4 R40 L-1 Q2.5", "with Q but without P"),
                         ("G81", "G81 is not a G code of the Fanuc hobbing G81.4 in G54 grammar"),
                         ("G81 T40 L-1", "line 10 'G81 T40 L-1'")):
        assert reason in refusal(m_series, replaced("G81.4 R40 L-1 Q2.5 P15.", sync, lines=lines))
    assert "M30 while the table is synchronised to the hob: G80.4 first" in refusal(m_series, replaced("G80.4",
                                                                                                       lines=lines))


def test_an_840d_program_is_refused_on_a_fanuc_hobber(fanuc):
    lines = ["%_N_GEAR42_MPF", ";$PATH=/_N_MPF_DIR", "G90 G71 G94", "M30"]
    message = refusal(fanuc, lines)
    assert "line 1 '%_N_GEAR42_MPF': %_N_GEAR42_MPF: not a word of the Fanuc hobbing in G54 grammar" in message


def test_a_fanuc_hobbers_lineage_line_is_a_comment_its_grammar_reads(fanuc):
    """The engine's lineage line (engine.nc.lineage) stands in parentheses on a Fanuc hobber, so
    the grammar reads it as a comment and the control skips it."""
    words = lineage_words(7, "spur", 1, "7d5cca25" * 8, "80c6b886" * 8, draft=False)
    lines = {dialect: lineage_line(words, dialect) for dialect in ("fanuc", "fanuc-g81.4")}
    assert set(lines.values()) == {"(PROGRAM 7 TEMPLATE spur v1 7d5cca25 INPUT 80c6b886)"}
    verify_program(replaced("(GEAR 42 HELICAL)", lines["fanuc"]), fanuc, NAME)


def test_instantiate_on_a_fanuc_hobber_without_an_o_number_rule_is_refused_and_stores_nothing(run):
    """The class templates emit Fanuc (issue 30), but a Fanuc hobber's record must say how its
    programs are numbered (program_number_base, migration 0038): one without is refused in one
    line naming the machine and the column, before any program is planned, and nothing is stored."""
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE machine SET dialect = 'fanuc' WHERE name = 'hobber-840d'")
        before = conn.execute("SELECT count(*) FROM program").fetchone()[0]
    result = run("instantiate", "--gear", 42)
    assert result.exit_code == 1, result.output
    assert result.stderr.strip().splitlines() == [
        "error: gear 42 on hobber-840d (Fanuc): machine hobber-840d states no program_number_base, so its programs "
        "have no O number; set machine.program_number_base; nothing stored"]
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT count(*) FROM program").fetchone()[0] == before


def test_a_g81_statement_carries_its_terms_with_their_signs():
    """The simulation proves the hand and the helix from the signs of L and P: the verifier's
    reading keeps them (and the words as written, for the findings), so no second reader parses
    the block again."""
    start = read_line(HOBBING_FANUC, "G81 T41 L-2 Q3. P-15. (START)")
    assert start.gear_box == GearBox(41, -2, 3.0, -15.0, "T41", "L-2", "Q3. P-15.")
    assert start.ratio == 2 / 41 and start.gear_box.ratio_words == "L-2 T41"
    assert read_line(HOBBING_FANUC_G81_4, "G81.4 R40 L3").gear_box == GearBox(40, 3, None, None, "R40", "L3")
    assert read_line(HOBBING_FANUC, "G80").gear_box is None
