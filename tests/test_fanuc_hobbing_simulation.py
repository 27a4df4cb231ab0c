"""The simulation proves a Fanuc hobbing program's coupling with the 840D's physics (issue 30;
docs/reference/fanuc-egb.md §F5, §F6): the seeded templates' 840D program for a spur gear,
rewritten in the test into the Fanuc form (tests/helpers/fanuc_programs.py: G81 T<z2> L<±z0>
with L = −h_hob·c_direction·b_direction·z0 from the reference), read on the seeded hobber's
record with dialect "fanuc", has the same findings as the 840D program (none). A wrong L sign
(the table turns the wrong way for the hob's hand), a wrong T (another number of teeth), Q/P on
a spur gear, a helical gear's Q/P on a record that does not state egb_helix_sign, and a C word
are refused, each with one line. On a record that states it (migration 0037), the helical
gear's Q/P is the coupling's Z term and is proved like the 840D's EGON Z term: the right P sign
passes, a flipped P, a flipped record sign or a wrong module Q cuts the wrong helix."""
from __future__ import annotations

import math
import re

import pytest
from helpers.fanuc_cases import twin
from helpers.fanuc_programs import fanuc_program, g81, threads_word
from msgspec.structs import replace

from engine.simulation import simulate_program
from engine.simulation.hobbing.recorded import record_program
from engine.simulation.hobbing.report import SimulationError

SPUR = 42                       # seeded spur gear: m 2, z 19, its hob one-start right hand
HELICAL = 43                    # seeded helical gear, right hand


@pytest.fixture
def case(conn, monkeypatch):
    """gear id, senses -> (840D lines, gear, hob, 840D machine, Fanuc machine), the tailstock
    clamped (M20 … M21, as the templates write by default)."""
    return lambda gear_id, **senses: twin(conn, monkeypatch, gear_id, **senses)


def refusals(lines, gear, hob, machine) -> list[str]:
    return [finding.message for finding in simulate_program(lines, gear, hob, machine).refusals]


def test_the_spur_program_in_fanuc_form_has_the_840d_findings_none(case):
    lines, gear, hob, siemens, fanuc = case(SPUR)
    assert refusals(lines, gear, hob, siemens) == []
    translated = fanuc_program(lines, gear, hob, fanuc)
    assert f"G81 T{gear.teeth} L{-hob.starts}" in translated        # DIN machine, right-hand hob: L < 0
    report = simulate_program(translated, gear, hob, fanuc)
    assert report.refusals == []
    assert report.teeth == [str(gear.teeth)] and report.helix == ["spur"]
    expected = simulate_program(lines, gear, hob, siemens)
    assert math.isclose(report.table_speed, expected.table_speed)
    assert math.isclose(report.cycle_time, expected.cycle_time)


@pytest.mark.parametrize("senses", [{"c_direction": -1}, {"b_direction": -1}, {"c_direction": -1, "b_direction": -1}])
def test_the_sign_of_l_follows_the_machine_senses(case, senses):
    """L = −h_hob·c·b·z0: a table or hob spindle turning the other way flips L, both flip it back."""
    lines, gear, hob, siemens, fanuc = case(SPUR, **senses)
    wanted = -1 * senses.get("c_direction", 1) * senses.get("b_direction", 1) * hob.starts   # right-hand hob
    assert threads_word(hob, fanuc) == wanted
    assert refusals(fanuc_program(lines, gear, hob, fanuc), gear, hob, fanuc) == []


def test_a_wrong_l_sign_turns_the_table_the_wrong_way_for_the_hob(case):
    lines, gear, hob, _, fanuc = case(SPUR)
    wrong = -threads_word(hob, fanuc)
    found = refusals(fanuc_program(lines, gear, hob, fanuc, threads=wrong), gear, hob, fanuc)
    assert found and "the table turns the wrong way for a right-hand hob" in found[0]
    k_b = wrong / gear.teeth                                           # c = b = +1: DIN k_B = L/T
    assert f"k_B is {k_b:+.6g}" in found[0] and f"needs {-k_b:+.6g}" in found[0]
    assert (f"G81 L{wrong} T{gear.teeth} turns it so; L = −h_hob·c_direction·b_direction·z0 is "
            f"L{threads_word(hob, fanuc)} on this machine") in found[0]      # the Fanuc words, not EGON's


def test_a_wrong_t_generates_another_number_of_teeth(case):
    lines, gear, hob, _, fanuc = case(SPUR)
    found = refusals(fanuc_program(lines, gear, hob, fanuc, teeth=gear.teeth + 1), gear, hob, fanuc)
    generated = hob.starts * (gear.teeth + 1) / hob.starts             # z0·T/|L|
    assert found and f"generates {generated:g} teeth; the gear has {gear.teeth}" in found[0]


def test_q_and_p_on_a_spur_gear_are_refused(case):
    lines, gear, hob, _, fanuc = case(SPUR)
    translated = fanuc_program(lines, gear, hob, fanuc, helix=" Q2. P15.")
    with pytest.raises(SimulationError, match=r"Q2\. P15\. on a spur gear: .* would cut a helix") as raised:
        simulate_program(translated, gear, hob, fanuc)
    assert "\n" not in str(raised.value)


def test_a_helical_gears_fanuc_program_is_refused_for_the_unknown_sign(case):
    lines, gear, hob, siemens, fanuc = case(HELICAL)
    assert gear.helix_angle and gear.hand == "R" and refusals(lines, gear, hob, siemens) == []
    translated = fanuc_program(lines, gear, hob, fanuc)
    helix = -1 * gear.helix_angle                                      # P = −h_gear·c·z·β on a DIN machine
    assert f"G81 T{gear.teeth} L{threads_word(hob, fanuc)} Q{gear.module:g}. P{helix:.3f}" in translated
    with pytest.raises(SimulationError, match="the sign of the Fanuc helical compensation is not stated on the "
                                              "machine record") as raised:
        simulate_program(translated, gear, hob, fanuc)
    assert "\n" not in str(raised.value)


def test_a_helical_gear_without_q_and_p_would_be_cut_straight(case):
    """§F6: a helical gear's G81 without Q and P gets no differential; the Z term the reference
    needs is −h_gear·360·sin β/(π·m_n·z2) degrees of C per mm of Z."""
    lines, gear, hob, _, fanuc = case(HELICAL)
    found = refusals(fanuc_program(lines, gear, hob, fanuc, helix=""), gear, hob, fanuc)
    k_z = -360 * math.sin(math.radians(gear.helix_angle)) / (math.pi * gear.module * gear.teeth)
    assert any(f"(DIN) of G81 without Q and P (no helical compensation) generates no helix (spur); the gear needs "
               f"{k_z:+.6f}°/mm" in message for message in found), found


def test_a_c_word_while_coupled_is_refused_it_would_add_the_motion_twice(case):
    lines, gear, hob, _, fanuc = case(SPUR)
    translated = fanuc_program(lines, gear, hob, fanuc)
    at = next(number for number, line in enumerate(translated) if line.startswith("G1 Z"))
    translated[at] += " C10."
    with pytest.raises(SimulationError, match=r"the program must not add it twice \(fanuc-egb.md §F6\)"):
        simulate_program(translated, gear, hob, fanuc)


def test_the_m_series_g81_4_form_is_proved_the_same(case):
    """G81.4 R<z2> L<±z0> … G80.4 (fanuc-egb.md §F3): the same pair, R for T."""
    lines, gear, hob, _, fanuc = case(SPUR)
    g81_4 = replace(fanuc, dialect="fanuc-g81.4")
    start = f"G81 T{gear.teeth} L{threads_word(hob, fanuc)}"
    translated = [{start: start.replace("G81 T", "G81.4 R"), "G80": "G80.4"}.get(line, line)
                  for line in fanuc_program(lines, gear, hob, fanuc)]
    assert f"G81.4 R{gear.teeth} L{-hob.starts}" in translated
    assert refusals(translated, gear, hob, g81_4) == []
    wrong = [line.replace(f"L{-hob.starts}", f"L{hob.starts}") for line in translated]
    found = refusals(wrong, gear, hob, g81_4)[0]
    assert "the table turns the wrong way" in found and f"G81.4 L{hob.starts} R{gear.teeth} turns it so" in found


def test_the_picture_follows_the_same_coupling_and_refuses_the_same_helix(case):
    """engine plot's recording walks the same coupling: k_B = −h_hob·z0/z2 in the DIN frame."""
    lines, gear, hob, _, fanuc = case(SPUR)
    recording = record_program(fanuc_program(lines, gear, hob, fanuc), gear, hob, fanuc)
    assert [coupling.k_b for coupling in recording.couplings] == [-hob.starts / gear.teeth]
    lines, gear, hob, _, fanuc = case(HELICAL)
    with pytest.raises(SimulationError, match="sign of the Fanuc helical compensation"):
        record_program(fanuc_program(lines, gear, hob, fanuc), gear, hob, fanuc)


def reference_k_z(gear, module: float | None = None) -> float:
    """k_Z = −h_gear·360·sin β/(π·m_n·z2), degrees of C per mm of Z in the DIN frame (fanuc-egb.md
    §F4, §F5; right hand here), with `module` for Q where a wrong one is written."""
    assert gear.hand == "R"
    return -360 * math.sin(math.radians(gear.helix_angle)) / (math.pi * (module or gear.module) * gear.teeth)


def reference_p(gear, machine) -> float:
    """P = −h_gear·c_direction·z_direction·egb_helix_sign·β (fanuc-egb.md §F5): the control's
    egb_helix_sign·sin P·360/(π·T·Q) per mm of programmed Z must be c·z·k_Z (DIN)."""
    return -1 * machine.c_direction * machine.z_direction * machine.egb_helix_sign * gear.helix_angle


def wrong_helix(found: float, gear, words: str) -> str:
    """The walk's words for a Z term `found` (DIN) that G81's Q and P (`words`) give on the gear:
    the hand, β and lead it cuts (sin β' = |k|·π·m_n·z2/360, lead 360/|k|, fanuc-egb.md §F4 turned
    round), named by the Fanuc words that give it."""
    beta = math.degrees(math.asin(abs(found) * math.pi * gear.module * gear.teeth / 360))
    hand = "right-hand" if found < 0 else "left-hand"
    return (f"the Z term {found:+.6f}°/mm (DIN) of G81's helical compensation {words} generates a {hand} helix of "
            f"β {beta:.3f}°, lead {360 / abs(found):.1f} mm; the gear needs {reference_k_z(gear):+.6f}°/mm")


@pytest.mark.parametrize("senses", [{"egb_helix_sign": 1}, {"egb_helix_sign": -1},
                                    {"egb_helix_sign": 1, "c_direction": -1},
                                    {"egb_helix_sign": -1, "c_direction": -1}])
def test_a_helical_gears_fanuc_program_is_proved_on_a_record_stating_the_sign(case, senses):
    """The 840D twin (made for the seeded DIN record) has no findings; the Fanuc form, L and P
    signed by the reference, the record's senses and its stated sign, has none either, with the
    same helix, lead and table speed. (A table turning the other way flips L and P; Z's sense
    would also move every Z the 840D program was written with, so it is not flipped here.)"""
    lines, gear, hob, siemens, fanuc = case(HELICAL, **senses)
    siemens = replace(siemens, c_direction=1)
    assert refusals(lines, gear, hob, siemens) == []
    translated = fanuc_program(lines, gear, hob, fanuc)
    assert f"Q{gear.module:g}. P{reference_p(gear, fanuc):.3f}" in g81(gear, hob, fanuc)
    report = simulate_program(translated, gear, hob, fanuc)
    assert report.refusals == [], report.lines()
    lead = math.pi * gear.module * gear.teeth / math.sin(math.radians(gear.helix_angle))   # p_z, §F4 (2)
    assert report.helix == [f"right-hand β {gear.helix_angle:.3f}° lead {lead:.1f} mm"]
    expected = simulate_program(lines, gear, hob, siemens)
    assert report.helix == expected.helix and report.teeth == expected.teeth
    assert math.isclose(report.table_speed, expected.table_speed, rel_tol=1e-5)


def test_a_flipped_p_cuts_the_other_hand(case):
    lines, gear, hob, _, fanuc = case(HELICAL, egb_helix_sign=1)
    flipped = f" Q{gear.module:g}. P{-reference_p(gear, fanuc):.3f}"
    found = refusals(fanuc_program(lines, gear, hob, fanuc, helix=flipped), gear, hob, fanuc)
    assert any(wrong_helix(-reference_k_z(gear), gear, flipped.strip()) in message for message in found), found


def test_the_same_program_on_a_record_of_the_other_sign_cuts_the_other_hand(case):
    lines, gear, hob, _, fanuc = case(HELICAL, egb_helix_sign=1)
    translated = fanuc_program(lines, gear, hob, fanuc)
    other = replace(fanuc, egb_helix_sign=-1)
    found = refusals(translated, gear, hob, other)
    words = f"Q{gear.module:g}. P{reference_p(gear, fanuc):.3f}"
    assert any(wrong_helix(-reference_k_z(gear), gear, words) in message for message in found), found


def test_a_wrong_module_q_cuts_the_wrong_lead(case):
    lines, gear, hob, _, fanuc = case(HELICAL, egb_helix_sign=1)
    wrong = gear.module + 1
    words = f"Q{wrong:g}. P{reference_p(gear, fanuc):.3f}"
    found = refusals(fanuc_program(lines, gear, hob, fanuc, helix=f" {words}"), gear, hob, fanuc)
    assert any(wrong_helix(reference_k_z(gear, wrong), gear, words) in message for message in found), found


def test_the_picture_follows_the_helical_coupling_on_a_record_stating_the_sign(case):
    lines, gear, hob, _, fanuc = case(HELICAL, egb_helix_sign=-1)
    recording = record_program(fanuc_program(lines, gear, hob, fanuc), gear, hob, fanuc)
    assert [round(coupling.factors["Z"], 9) for coupling in recording.couplings] == \
        [round(reference_k_z(gear), 9)] * len(recording.couplings)


def test_q_and_p_in_the_m_series_g81_4_are_refused_their_meaning_unconfirmed(case):
    """fanuc-egb.md §F3: G81.4's Q and P have no units or formula in the retrieved text; §F4's
    egb_helix_sign·sin P·360/(π·T·Q) is G81's. The same Q/P that G81 proves (P from the reference,
    §F5) is refused in G81.4 on a record stating the sign, for the simulation and the picture."""
    lines, gear, hob, _, fanuc = case(HELICAL, egb_helix_sign=1)
    translated = fanuc_program(lines, gear, hob, fanuc)
    assert simulate_program(translated, gear, hob, fanuc).refusals == []
    helical = f"Q{gear.module:g}. P{reference_p(gear, fanuc):.3f}"
    start = g81(gear, hob, fanuc)
    m_series = [{start: start.replace("G81 T", "G81.4 R"), "G80": "G80.4"}.get(line, line) for line in translated]
    assert f"G81.4 R{gear.teeth} L{threads_word(hob, fanuc)} {helical}" in m_series
    g81_4 = replace(fanuc, dialect="fanuc-g81.4")
    for prove in (simulate_program, record_program):
        with pytest.raises(SimulationError, match=rf"{re.escape(helical)} in G81.4: the M-series form's Q and P .* "
                                                  r"not in the retrieved manuals \(fanuc-egb.md §F3\)") as raised:
            prove(m_series, gear, hob, g81_4)
        assert "\n" not in str(raised.value)


def test_a_g81_with_the_hob_turning_is_refused_the_table_may_not_be_in_step(case):
    """fanuc-egb.md §F7 (egb_waits_for_sync, not known): with the hob already turning the table must
    catch up, and the next block may not wait for it. The same program with M5 before G81 and the
    hob started after it (the order the seeded templates write) is proved."""
    lines, gear, hob, _, fanuc = case(SPUR)
    translated = fanuc_program(lines, gear, hob, fanuc)
    at = translated.index(g81(gear, hob, fanuc))
    start = translated[at + 1]
    assert start.startswith("M3 S")
    early = [*translated[:at], start, translated[at], *translated[at + 2:]]
    for prove in (simulate_program, record_program):
        with pytest.raises(SimulationError, match=r"G81 with the hob spindle turning \(M3, no M5 since\): .* "
                                                  r"egb_waits_for_sync") as raised:
            prove(early, gear, hob, fanuc)
        assert "\n" not in str(raised.value)
    stopped = [*translated[:at], start, "M5", translated[at], *translated[at + 1:]]
    assert refusals(stopped, gear, hob, fanuc) == []


def test_a_shift_under_g81_is_named_in_the_fanuc_words(case):
    """§B15 with fanuc-egb.md §F6: G81 has no Y term, so a hob shift while synchronised slides the
    thread along the teeth; the finding names G81, not the 840D's EGON."""
    lines, gear, hob, _, fanuc = case(SPUR)
    translated = fanuc_program(lines, gear, hob, fanuc)
    at = next(number for number, line in enumerate(translated) if line.startswith("G1 Z"))
    shifted = [*translated[:at + 1], "G0 Y5.", *translated[at + 1:]]
    found = [message for message in refusals(shifted, gear, hob, fanuc) if "hob shift Y" in message]
    assert found and "synchronised by G81, which has no Y term" in found[0] and "EGON" not in found[0]
