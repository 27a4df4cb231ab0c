"""840D lathe programs as stored on the control (issue 27): the expander "840d-lathe" runs R-parameters,
DEF variables and their arithmetic, jumps, loops and section repetitions into the plain blocks
the 840D lathe grammar reads, and the verifier proves them on a lathe-840d record. What cannot be
turned into plain moves is refused naming the line and the construct.

Every expected number is computed here from the reference's rule (docs/reference/sinumerik-lathe.md §S), not copied
from the expander: SIN in degrees, DIAMOF radii doubled, an arc's CR from its centre by Pythagoras,
a G4 S dwell as turns × 60 / (r/min)."""
from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from helpers.class_jobs import ok, stored_program

from engine.machines.records import Machine, load_machine
from engine.programs.remake import instantiate_job
from engine.simulation.turning.run import simulate_turning
from engine.verifier import LimitError, expansion, verify_program
from engine.verifier.expansion import expand
from importers.dxf import import_dxf

DATA = Path(__file__).resolve().parent / "data" / "nc"
GOLDEN = Path(__file__).resolve().parent / "golden" / "turning"
# lathe-840d of seed_templates/machines.csv: X 0…400 (diameter), Z -600…200, 4000 r/min, G54
LATHE = Machine("lathe-840d", "lathe", "840d", 0.0, 400.0, 0.0, 0.0, -600.0, 200.0, 4000.0, None, None)
READY = ["G18 G71 G90 G40 DIAMON", "T1 D1", "G97 S800 M3", "G94 F150"]


def plain(lines: list[str]) -> list[str]:
    return [line.text for line in expand("840d-lathe", lines, LATHE)]


def blocks(lines: list[str]) -> list[str]:
    return [text for text in plain(lines) if not text.startswith(";")]


def refused(lines: list[str], name: str | None = "TEST") -> str:
    with pytest.raises(LimitError) as raised:
        verify_program(lines, LATHE, name)
    return str(raised.value)


def words_of(text: str) -> dict[str, float]:
    return {word[0]: float(word[1:]) for word in text.split() if word[0] in "XZF" and "=" not in word}


# ------------------------------------------------------------------ the program as stored

def test_a_program_without_the_header_is_verified():
    verify_program([*READY, "G0 X50 Z2", "G1 Z-20", "M30"], LATHE, "TEST")


def test_a_header_must_still_name_the_program_itself():
    message = refused(["%_N_OTHER_MPF", ";$PATH=/_N_WKS_DIR/_N_SHAFT_WPD", *READY, "M30"])
    assert "line 1" in message and "OTHER" in message and "TEST" in message


def test_the_workpiece_path_line_is_read_in_the_second_line():
    verify_program(["%_N_TEST_MPF", ";$PATH=/_N_WKS_DIR/_N_SHAFT_WPD", *READY, "M30"], LATHE, "TEST")


def test_block_numbers_labels_and_comments_with_umlauts_are_read():
    lines = ["N10 G18 G71 G90 G40 DIAMON ; Außendrehen", "; Schruppen – Stahl", "N20 T1 D1",
             "N30 G97 S800 M3", "N40 G94 F150", "ANFANG: N50 G0 X50 Z2", "N60 G1 Z-20", "N70 M30"]
    verify_program(lines, LATHE, "TEST")
    assert "G1 Z-20" in blocks(lines)


# ------------------------------------------------------------------ parameters and arithmetic

def test_r_parameters_and_def_variables_are_evaluated_in_degrees():
    lines = [*READY, "R1=25", "DEF REAL WINKEL=30, TIEFE", "TIEFE=R1*SIN(WINKEL)+SQRT(16)-ABS(-1)",
             "G0 X=2*R1 Z=TIEFE", "G1 Z=-(R1+POT(2))/2", "M30"]
    expected_z = 25 * math.sin(math.radians(30)) + 4 - 1
    moves = [words_of(text) for text in blocks(lines) if text.startswith(("G0 X", "G1 Z"))]
    assert moves[0]["X"] == 50 and moves[0]["Z"] == pytest.approx(expected_z, abs=1e-6)
    assert moves[1]["Z"] == pytest.approx(-(25 + 4) / 2, abs=1e-6)
    verify_program(lines, LATHE, "TEST")


def test_an_int_variable_holds_a_whole_number():
    lines = [*READY, "DEF INT N=7/2", "G0 X=N*10 Z2", "M30"]
    assert "G0 X40 Z2" in blocks(lines)     # 3.5 rounds to 4 (reference sinumerik-lathe §S2)


def test_an_r_parameter_read_before_the_program_sets_it_is_refused():
    message = refused([*READY, "G0 X=R7 Z2", "M30"])
    assert "R7 is read before the program sets it" in message and "line 5" in message


@pytest.mark.parametrize("speed", [["S0"], ["G96 S0 LIMS=3000"], ["R1=0", "S=R1"]], ids=" ".join)
def test_a_cut_after_a_spindle_speed_of_0_is_refused(speed):
    """S0 (or a cutting speed of 0 m/min under G96) stops the spindle: the cut after it would meet a
    standing bar."""
    message = refused([*READY, "G0 X50 Z2", *speed, "G1 Z-20", "M30"])
    assert "S0" in message and "above 0" in message, message


def test_a_system_variable_is_refused():
    assert "system variable" in refused([*READY, "R1=$AA_IM[X]", "M30"]) + refused([*READY, "R1=$P_EP", "M30"])


# ------------------------------------------------------------------ jumps and loops

def test_if_gotof_skips_the_blocks_between():
    lines = [*READY, "R1=1", "IF R1==1 GOTOF WEITER", "G0 X999 Z999", "WEITER:", "G0 X60 Z2", "M30"]
    assert "G0 X999 Z999" not in blocks(lines) and "G0 X60 Z2" in blocks(lines)
    verify_program(lines, LATHE, "TEST")


def test_a_gotob_loop_cuts_each_pass():
    """Three roughing passes from Ø48 down by 2 mm each: X 48, 46, 44."""
    lines = [*READY, "R1=48", "G0 X50 Z2", "SCHLEIFE:", "G1 X=R1 Z2", "G1 Z-30", "G0 X50 Z2", "R1=R1-2",
             "IF R1>=44 GOTOB SCHLEIFE", "M30"]
    cuts = [words_of(text)["X"] for text in blocks(lines) if text.startswith("G1 X")]
    assert cuts == [48, 46, 44]
    verify_program(lines, LATHE, "TEST")


def test_while_for_and_repeat_loops_run_their_passes():
    lines = [*READY, "DEF INT I", "R2=0", "WHILE R2<3", "R2=R2+1", "G0 X=40+R2 Z2", "ENDWHILE",
             "FOR I=1 TO 2", "G0 X=60+I Z2", "ENDFOR", "REPEAT", "R2=R2-1", "G0 X=80+R2 Z2", "UNTIL R2<=1", "M30"]
    xs = [words_of(text)["X"] for text in blocks(lines) if text.startswith("G0 X")]
    assert xs == [41, 42, 43, 61, 62, 82, 81]


def test_a_section_of_the_file_repeats_as_a_subprogram_call():
    lines = [*READY, "R1=50", "ANF: G0 X=R1 Z2", "R1=R1-4", "ENDE: G1 Z-10", "REPEAT ANF ENDE P=2", "M30"]
    xs = [words_of(text)["X"] for text in blocks(lines) if text.startswith("G0 X")]
    assert xs == [50, 46, 42]        # the section once as written, then P=2 more passes


def test_repeat_with_one_label_runs_up_to_the_repeat_and_repeatb_one_block():
    lines = [*READY, "R1=30", "ANF: G0 X=R1 Z2", "R1=R1+2", "REPEAT ANF P=1", "EINS: G0 X70 Z2", "REPEATB EINS P=2",
             "M30"]
    xs = [words_of(text)["X"] for text in blocks(lines) if text.startswith("G0 X")]
    assert xs == [30, 32, 70, 70, 70]


def test_if_else_endif_runs_one_branch():
    lines = [*READY, "R1=0", "IF R1>0", "G0 X90 Z2", "ELSE", "G0 X70 Z2", "ENDIF", "M30"]
    assert "G0 X70 Z2" in blocks(lines) and "G0 X90 Z2" not in blocks(lines)


def test_a_loop_that_never_ends_is_refused_at_the_step_bound(monkeypatch):
    monkeypatch.setattr(expansion, "MAX_STEPS", 5_000)
    message = refused([*READY, "MARKE:", "G0 X50 Z2", "GOTOB MARKE", "M30"])
    assert "more than 5,000 lines run" in message and "a loop that does not end" in message


def test_a_jump_to_a_label_not_in_the_file_is_refused():
    assert "not in the file" in refused([*READY, "GOTOF NIRGENDS", "M30"])


# ------------------------------------------------------------------ what cannot be expanded

@pytest.mark.parametrize("line, construct", [
    ("L4000", "L4000 calls an external subprogram"),
    ("L4000 P2", "L4000 calls an external subprogram"),
    ("ABSTECHEN", "ABSTECHEN calls a subprogram that is not in the file"),
    ('CYCLE95("KONTUR",2,0.2,0.1,,0.3,0.2,0.1,9)', "CYCLE95 is a vendor cycle without a model"),
    ("CYCLE97(1.5,,0,-20,40,40,3,2,0.92,0.1,0,0,5,1,3,1)", "CYCLE97 is a vendor cycle without a model"),
    ("G0 SUPA X200 Z100", "SUPA moves in the machine frame"),
    ("G53 G0 X200", "G53 moves in the machine frame"),
    ("G91 G0 X10", "incremental G91"),
    ("G0 X=IC(10)", "incremental value"),
    ("G42 G1 X40 Z0", "tool-nose radius compensation"),
    ("G1 X40 Z0 RND=2", "RND= rounds the corner"),
    ("CASE R1 OF 1 GOTOF A DEFAULT GOTOF B", "CASE"),
    ("G55", "G55 is not the work offset of machine lathe-840d (G54)"),
    ("G0 Y10", "Y is no axis of a lathe"),
    ("/G0 X10 Z2", "skip switch"),
])
def test_a_construct_that_cannot_be_expanded_is_refused_naming_it(line, construct):
    message = refused([*READY, line, "M30"])
    assert "line 5" in message and construct in message, message


def test_the_milling_program_of_the_sinumerik_data_is_no_lathe_program():
    """CAM_TEST.MPF (840D sl CAM output, CYCLE800, Y and A axes) is refused at its milling plane G17."""
    lines = (DATA / "sinumerik" / "cam_840dsl" / "CAM_TEST.MPF").read_text(encoding="utf-8").splitlines()
    message = refused(lines, "CAM_TEST")
    assert "line 6 'N60 G17 G710 G94 G90 FNORM'" in message and "milling program" in message


# ------------------------------------------------------------------ the words of real lathe programs

def test_g96_is_bounded_by_its_clamp_and_g95_feeds_per_turn():
    lines = ["G18 G71 G90 G40 DIAMON", "T=\"SCHRUPP_80\" D1", "G96 S200 LIMS=3000 M4", "G95 F0.25", "G0 X50 Z2",
             "G1 Z-20", "G96 S180", "G1 X40", "M30"]
    verify_program(lines, LATHE, "TEST")
    assert "G96 S180 LIMS=3000" in blocks(lines)      # the modal clamp written into the later G96


def test_g96_without_a_clamp_is_refused():
    lines = ["G18 G71 G90 G40 DIAMON", "T1 D1", "G96 S200 M4", "G95 F0.25", "G0 X50 Z2", "G1 Z-20", "M30"]
    assert "LIMS" in refused(lines) and "line 6" in refused(lines)


def test_a_clamp_above_the_spindle_maximum_is_refused():
    message = refused(["G18 G71 G90 G40 DIAMON", "T1 D1", "G96 S200 LIMS=5000 M4", "M30"])
    assert "LIMS=5000 exceeds lathe-840d's 4000 r/min" in message


def test_diamof_radii_are_read_as_diameters():
    lines = [*READY, "DIAMOF", "G0 X30 Z2", "DIAMON", "G0 X30 Z2", "M30"]
    xs = [words_of(text)["X"] for text in blocks(lines) if text.startswith("G0 X")]
    assert xs == [60, 30]


def test_an_arc_by_its_centre_gets_the_radius_to_both_ends():
    """G3 from Ø40 Z0 to Ø50 Z-5 around the centre 5 mm back in Z (K-5, I0 radial): a quarter circle."""
    lines = [*READY, "G0 X40 Z0", "G3 X50 Z-5 I0 K-5", "G2 X60 Z-10 I=AC(50) K=AC(-10)", "M30"]
    arcs = [text for text in blocks(lines) if text.startswith(("G3", "G2"))]
    radius = math.hypot(0 - 0, 0 - (-5))          # start (Z0, r20) to centre (Z-5, r20)
    assert arcs[0].endswith(f"CR={radius:g}")
    # G2 from (Z-5, r25) to (Z-10, r30) around (Z-10, r25): clockwise from 0° to 90° is 270°, more than
    # half a circle, so CR is negative (reference sinumerik-lathe §S7)
    assert arcs[1].endswith(f"CR={-math.hypot(-5 - (-10), 25 - 25):g}")
    verify_program(lines, LATHE, "TEST")


def test_a_centre_not_equally_far_from_both_ends_is_refused():
    assert "no arc of one radius" in refused([*READY, "G0 X40 Z0", "G3 X50 Z-5 I0 K-7", "M30"])


def test_a_dwell_in_spindle_turns_becomes_seconds():
    lines = [*READY, "G0 X50 Z2", "G4 S10", "G4 F1.5", "M30"]
    assert f"G4 F{10 * 60 / 800:g}" in blocks(lines)
    verify_program(lines, LATHE, "TEST")


def test_a_thread_is_cut_with_its_lead_k():
    lines = [*READY, "G0 X24 Z5", "G33 Z-30 K1.5 SF=0", "G0 X26", "M30"]
    assert "G33 Z-30 K1.5" in blocks(lines)
    verify_program(lines, LATHE, "TEST")


# ------------------------------------------------------------------ the engine's own programs

@pytest.mark.parametrize("path", sorted(GOLDEN.glob("*_lathe-840d.NC")), ids=lambda path: path.stem)
def test_the_engine_s_own_840d_lathe_programs_pass_unchanged(path):
    lines = path.read_text(encoding="ascii").splitlines()
    name = lines[0][len("%_N_"):-len("_MPF")]
    verify_program(lines, LATHE, name)
    moving = [text for text in plain(lines) if text.startswith(("G0", "G1", "G2", "G3", "G33"))]
    written = [line for line in lines if line.startswith(("G0", "G1", "G2", "G3", "G33"))]
    assert [words_of(text) for text in moving] == [words_of(line) for line in written]


# ------------------------------------------------------------------ attack forms in the control's own words
# The seeded sample drawing's 840D program (the engine's own), with an attack written the way a
# program on the control writes it (R-parameters, a jump, a named tool): the expander turns it into
# the plain moves, and the turning simulation follows them against the job's records.

def _sample(conn):
    sample = Path(__file__).resolve().parent.parent / "seed_templates" / "drawings" / "sample_shaft.dxf"
    job_id = import_dxf(conn, sample, "lathe-840d").job_id
    lines = instantiate_job(conn, job_id).lines
    params, modules = conn.execute("SELECT params, module_params FROM job WHERE id = %s", (job_id,)).fetchone()
    return lines, params, modules


def _after_first_cut(lines: list[str], attack: list[str]) -> list[str]:
    cut = next(index for index, line in enumerate(lines) if line.startswith("G1 "))
    return [*lines[:cut + 1], *attack, *lines[cut + 1:]]


@pytest.mark.parametrize("attack, reason", [
    (["R5=0", "G0 X=R5 Z=R5-10"], "a rapid through material"),
    (["DEF REAL TIEF=2*0", "G1 X=TIEF Z-10"], "a cut into the finished part"),
    (['T="T2" D1'], "tool change"),
    (["R7=1.5", "G33 Z-20 K=R7"], "a thread pass in operation 1 ROUGH"),
])
def test_an_attack_written_in_the_control_s_forms_is_refused_by_the_simulation(conn, attack, reason):
    lines, params, modules = _sample(conn)
    report = simulate_turning(lines, params, modules, load_machine(conn, "lathe-840d"))
    assert not report.refused, report.lines()       # the program as made is clean
    attacked = simulate_turning(_after_first_cut(lines, attack), params, modules, load_machine(conn, "lathe-840d"))
    assert attacked.refused and any(reason in refusal.message for refusal in attacked.refusals), attacked.lines()


@pytest.mark.parametrize("attack, reason", [
    (["G97 S5000 M3"], "S5000 exceeds lathe-840d's 4000 r/min"),
    (["G96 S200 M3", "G95 F0.2", "G1 X30 Z-5"], "G96 with its clamp LIMS"),
    (["G1 X=2*R9 Z-5"], "R9 is read before the program sets it"),
    (["R1=1", "SCHLEIFE:", "R1=R1+1", "GOTOB SCHLEIFE"], "more than 5,000 lines run"),
    (["L4000"], "L4000 calls an external subprogram"),
    (["G1 X500"], "X500 exceeds the travel of lathe-840d"),
])
def test_an_attack_in_the_engine_s_own_program_is_refused_by_the_verifier(conn, monkeypatch, attack, reason):
    monkeypatch.setattr(expansion, "MAX_STEPS", 5_000)
    lines, _, _ = _sample(conn)
    name = lines[0][len("%_N_"):-len("_MPF")]
    with pytest.raises(LimitError, match=reason):
        verify_program(_after_first_cut(lines, attack), LATHE, name)


# ------------------------------------------------------------------ import-nc and new values

STORED_FORM = ["; WELLE D40 - Außendrehen, Schruppen in drei Schnitten", "N10 G18 G71 G90 G40 DIAMON",
               'N20 T="SCHRUPP" D1', "N30 G96 S180 LIMS=2500 M4", "N40 G95 F0.25", "N50 R1=38",
               "N60 G0 X42 Z2", "SCHNITT: N70 G1 X=R1 Z2", "N80 G1 Z-30", "N90 G0 X42 Z2", "N100 R1=R1-2",
               "N110 IF R1>=34 GOTOB SCHNITT", "N120 G0 X100 Z100", "N130 M30"]


def test_a_program_as_stored_is_imported_and_made_with_new_values_that_change_only_its_bound_words(run, tmp_path):
    """import-nc of an 840D lathe program in the control's own form, then a class job with a new
    surface speed and feed: verified on lathe-840d, and only S180 and F0.25 change, to the values given."""
    source = tmp_path / "SHAFT.MPF"
    source.write_text("\n".join(STORED_FORM) + "\n", encoding="utf-8")
    verify_program(STORED_FORM, LATHE, "SHAFT")
    params = tmp_path / "params.json"
    params.write_text(json.dumps({"program_name": "SHAFT", "speed": 180, "feed": 0.25}))
    ok(run("import-nc", source, "--class", "shaft", "--params", params))
    new = tmp_path / "new.json"
    new.write_text(json.dumps({"speed": 200, "feed": 0.2}))
    made = json.loads(ok(run("instantiate", "--class", "shaft", "--machine", "lathe-840d", "--params", new,
                             "--draft", "--json")).stdout)
    lines, _, unverified = stored_program(run.url, made["program_id"])
    assert not unverified
    changed = [(old, line) for old, line in zip(STORED_FORM, lines) if old != line]
    assert len(lines) == len(STORED_FORM) and [old for old, _ in changed] == [STORED_FORM[3], STORED_FORM[4]]
    speed = next(word for word in changed[0][1].split() if word.startswith("S"))
    feed = next(word for word in changed[1][1].split() if word.startswith("F"))
    assert float(speed[1:]) == 200 and float(feed[1:]) == 0.2
    assert changed[0][1].replace(speed, "S180") == STORED_FORM[3]
    assert changed[1][1].replace(feed, "F0.25") == STORED_FORM[4]


def test_a_plain_move_reads_the_same_by_the_quick_pattern_and_word_by_word():
    """The moves of the engine's own programs are passed on by one pattern; numbered (N…), the same
    lines go word by word: both give the same motions and end points."""
    lines = (GOLDEN / "shaft-profile_lathe-840d.NC").read_text(encoding="ascii").splitlines()
    numbered = [line if line.startswith((";", "%")) else f"N{index} {line}" for index, line in enumerate(lines)]
    quick = [words_of(text) for text in blocks(lines) if text.startswith(("G0", "G1", "G2", "G3"))]
    word_by_word = [words_of(text) for text in blocks(numbered) if text.startswith(("G0", "G1", "G2", "G3"))]
    assert quick == word_by_word and len(quick) > 50
