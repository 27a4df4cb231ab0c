"""The fail-closed verifier (issue 13): every golden program is read whole and accepted; every
840D form that slipped past the regex checkers is refused with its reason; a control or
non-ASCII character is refused wherever it stands (comment, header, block); S and F of 0 or
below, inf and nan are refused; and, end to end on a real database, a newline or carriage return
put into a template row or a stored job's program name, or a hob speed of 0 or below, stores no
program and writes no file, with one line and exit 1.

The preludes below are written here, with their numbers: the limits they set are what the
expected outcomes are computed from."""
from __future__ import annotations

import re
from pathlib import Path

import psycopg
import pytest
from helpers.drawings import seed_drawing
from helpers.golden_cases import TURNING_CASES
from helpers.verifier_programs import (
    HOBBING,
    LATHE_ISO,
    PRELUDES,
    accepted,
    one_line_exit_1,
    program,
    programs,
    refusal,
)
from msgspec.structs import replace

from engine.machines.records import load_machine
from engine.verifier import LimitError, verify_program

GOLDEN = Path(__file__).resolve().parent / "golden"

# A hobbing prelude: the working area X 50…62, Y −30…30, Z −25…20 (inside hobber-840d's travel
# X 20…320, Y −80…80, Z −350…150, seed_templates/machines.csv).
AREA = {"X": (50.0, 62.0), "Y": (-30.0, 30.0), "Z": (-25.0, 20.0)}


# ---------------------------------------------------------------- golden programs

def golden_programs() -> list:
    return ([pytest.param(path, "hobber-840d", id=path.name) for path in sorted((GOLDEN / "hobbing").glob("*.MPF"))]
            + [pytest.param(path, path.stem.rpartition("_")[2], id=path.name)
               for path in sorted((GOLDEN / "turning").glob("*.NC"))])


def program_name(path: Path) -> str:
    """The name the job gives the golden program: GEAR<id> for a gear (the hobbing models), for
    a drawing the name its case gives, else its file name in upper case with - as _."""
    if path.suffix == ".MPF":
        return path.stem.partition("_")[0]
    case = path.stem.rpartition("_")[0]
    options = next(options for name, _, options, _ in TURNING_CASES if name == case)
    return options.get("program_name", case.upper().replace("-", "_"))


@pytest.mark.parametrize("path, machine", golden_programs())
def test_every_golden_program_is_accepted(conn, path, machine):
    lines = path.read_text().splitlines()
    assert len(lines) > 10
    verify_program(lines, load_machine(conn, machine), program_name(path))


def test_the_golden_programs_cover_every_dialect_and_the_shift_clamp():
    names = [param.values[1] for param in golden_programs()]
    assert {"hobber-840d", "lathe-840d", "lathe-iso"} <= set(names)
    assert any("R11=R11+" in path.read_text() for path in (GOLDEN / "hobbing").glob("*.MPF"))
    assert any("#500=#500+" in path.read_text() for path in (GOLDEN / "hobbing_fanuc").glob("*.NC"))


# ---------------------------------------------------------------- the 840D forms of issue 13

def test_the_prelude_with_a_plain_move_inside_the_machine_is_accepted(conn):
    assert accepted(conn, "hobber-840d", program("hobber-840d", ["G0 X55.000 Z10.000", "G0 X=55 Y=0", "M3 S500",
                                                                 "G1 Z-20.000 F100.0"]))


@pytest.mark.parametrize("block, reason", [
    ("G0 X=55+99999", r"X=55\+99999: an address expression"),
    ("R1=99999", r"R1=99999: an R-parameter"),
    ("G0 X=R1", r"X=R1: an R-parameter"),
    ("G0 X55EX3", r"X55EX3: an exponent"),
    ("G0 X5.5E1", r"X5\.5E1: an exponent"),
    ("G0 AX[X]=99999", r"AX\[X\]=99999: an indirect address"),
    ("G0 X=IC(5)", r"X=IC\(5\): IC\(…\)/AC\(…\)"),
    ("G0 X=AC(55)", r"X=AC\(55\): IC\(…\)/AC\(…\)"),
    ("G26 X=62+99999 Y30 Z20", r"X=62\+99999: an address expression"),
    ("G26 X99999 Y30 Z20", r"working-area limit X99999 exceeds the travel of hobber-840d \(X 20…320\)"),
    ("M3 S=0+5000", r"S=0\+5000: an address expression"),
    ("G0 Xinf", r"Xinf: inf/nan"),
    ("G0 Xnan", r"Xnan: inf/nan"),
    ("G1 Z-inf F100", r"Z-inf: inf/nan"),
    ("G0 X=$AA_IM[X]", r"an indirect address|an R-parameter or system variable"),
    ("G91 G0 X1", r"incremental G91"),
    ("G58", r"G58 shifts every position by a work offset"),
    ("WALIMOF", r"WALIMOF: not a word of the 840D hobbing grammar"),
    ("GOTOF END", r"GOTOF: not a word"),
    ("X55.000", r"a move without its G0/G1"),
    ("G0 G1 X55.000", r"G0 and G1 in one block are both motion"),
    ("G0 X55 X56", r"X twice in one block"),
    ("G0 Y=R11", r"the hob-shift clamp must read exactly"),
])
def test_each_840d_form_the_regex_checkers_missed_is_refused_with_its_reason(conn, block, reason):
    message = refusal(conn, "hobber-840d", HOBBING + [block])
    assert f"TEST line {len(HOBBING) + 1} {block!r}" in message
    assert re.search(reason, message), message


def test_an_r_parameter_set_and_then_used_is_refused_where_it_is_set(conn):
    message = refusal(conn, "hobber-840d", HOBBING + ["R1=99999", "G0 X=R1"])
    assert f"line {len(HOBBING) + 1} 'R1=99999'" in message


@pytest.mark.parametrize("block, axis, value", [("G0 X62.001", "X", 62.001), ("G0 Y-30.5", "Y", -30.5),
                                                ("G1 Z20.5 F100", "Z", 20.5)])
def test_a_move_outside_the_working_area_is_refused(conn, block, axis, value):
    low, high = AREA[axis]
    assert not low <= value <= high
    assert f"{axis}{value:g} lies outside the working area G25/G26 {axis} {low:g}…{high:g}" in \
        refusal(conn, "hobber-840d", program("hobber-840d", [block]))


@pytest.mark.parametrize("before", [["G25 X50 Y-30 Z-25", "G26 X62 Y30 Z20"], ["G25 X50 Y-30 Z-25", "WALIMON"],
                                    ["G26 X62 Y30 Z20", "WALIMON"], []])
def test_motion_before_g25_g26_and_walimon_is_refused(conn, before):
    lines = ["%_N_TEST_MPF", ";$PATH=/_N_MPF_DIR", *before, "G0 X55", "M30"]
    assert "motion before G25/G26 and WALIMON" in refusal(conn, "hobber-840d", lines)


def test_a_working_area_must_bound_every_axis_and_lie_within_the_travel(conn):
    machine = load_machine(conn, "hobber-840d")
    assert "must give each of X, Y, Z" in refusal(conn, "hobber-840d", HOBBING[:2] + ["G25 X50 Z-25"])
    widened = f"G26 X{machine.x_max + 1:g} Y30 Z20"
    assert f"working-area limit X{machine.x_max + 1:g} exceeds the travel" in \
        refusal(conn, "hobber-840d", HOBBING[:2] + ["G25 X50 Y-30 Z-25", widened])


def test_a_later_g26_is_checked_against_the_travel_too(conn):
    assert "working-area limit Y81 exceeds the travel" in \
        refusal(conn, "hobber-840d", HOBBING + ["G0 X55", "G26 X62 Y81 Z20"])


# ---------------------------------------------------------------- the hob-shift clamp

def clamp(low: float, high: float, reset: float, step: float = 0.5) -> list[str]:
    return [f"R11=R11+{step:.3f} ; HOB SHIFT PER PART", f"IF (R11<{low:.3f}) OR (R11>{high:.3f})",
            f"R11={reset:.3f}", "ENDIF", "G0 Y=R11"]


def test_the_clamp_inside_the_working_area_is_accepted(conn):
    low, high = AREA["Y"]
    assert accepted(conn, "hobber-840d", program("hobber-840d", clamp(low + 1, high - 1, low + 1) + ["M3 S300"]))
    assert accepted(conn, "hobber-840d", program("hobber-840d", clamp(low, high, high)))


@pytest.mark.parametrize("low, high, reset, message", [
    (-31.0, 29.0, -31.0, "Y-31 lies outside the working area"),   # the lower end of R11
    (-29.0, 31.0, -29.0, "Y31 lies outside the working area"),    # the upper end, never reset to
    (-29.0, 29.0, 29.5, "R11=29.5 lies outside the interval -29 … 29"),
    (5.0, -5.0, 0.0, "the clamp interval 5 … -5 is empty"),
])
def test_the_clamp_is_checked_at_both_ends_of_its_interval(conn, low, high, reset, message):
    assert message in refusal(conn, "hobber-840d", HOBBING + clamp(low, high, reset))


@pytest.mark.parametrize("lines", [
    clamp(-5, 5, -5)[:4] + ["G0 X55"] + clamp(-5, 5, -5)[4:],    # a line between
    clamp(-5, 5, -5)[:3],                                         # the program ends inside it
    [clamp(-5, 5, -5)[0], clamp(-5, 5, -5)[2], clamp(-5, 5, -5)[1]] + clamp(-5, 5, -5)[3:],
    ["R11=R11-0.5", "IF (R11<-5) OR (R11>5)", "R11=-5", "ENDIF", "G0 Y=R11"],
    ["R12=R12+0.5", "IF (R12<-5) OR (R12>5)", "R12=-5", "ENDIF", "G0 Y=R12"],
    ["R11=R11+0.5", "IF (R11<-5) OR (R11>5)", "R11=-5", "ENDIF", "G1 Y=R11 F100"],
    ["R11=R11+0.5", "IF (R11<-5) AND (R11>5)", "R11=-5", "ENDIF", "G0 Y=R11"],
])
def test_any_other_r_parameter_use_is_refused(conn, lines):
    message = refusal(conn, "hobber-840d", program("hobber-840d", lines))
    assert any(reason in message for reason in ("clamp", "R-parameter", "IF: not a word")), message


# ---------------------------------------------------------------- characters

CHARACTERS = [("\n", "line feed"), ("\r", "carriage return"), ("\x00", "NUL"), ("\x7f", "DEL"),
              ("\t", "tab"), ("\x1b", "control character U+001B"), ("é", "non-ASCII character U+00E9"),
              ("\u2028", "U+2028"), ("\x85", "U+0085")]


@pytest.mark.parametrize("character, named", CHARACTERS)
@pytest.mark.parametrize("machine, where, line", [
    ("hobber-840d", 0, "%_N_GEAR{c}42_MPF"), ("hobber-840d", 2, "; GEAR 42{c}G0 X9999 Z-9999"),
    ("hobber-840d", 7, "G0 X55.000{c}"), ("hobber-840d", 7, "M20 ; TAILSTOCK{c}CLAMP"),
    ("lathe-840d", 2, "; DRAWING a{c}G0 X9999.dxf"), ("lathe-iso", 1, "O0001 (PART{c}G00 X9999)"),
    ("lathe-iso", 2, "(DRAWING part{c}.dxf)"), ("lathe-iso", 4, "G00 X10.000 Z5.000{c}"),
])
def test_a_control_or_non_ascii_character_is_refused_wherever_it_stands(conn, character, named, machine,
                                                                        where, line):
    lines = list(PRELUDES[machine]) + (["G0 X55 Z10"] if machine == "hobber-840d" else [])
    lines[where:where + 1] = [line.format(c=character)]
    if machine == "lathe-840d" and character.isprintable():
        # 840D lathe comments hold any printable text (issue 27): "é" is text, not a block
        assert accepted(conn, machine, [*lines, "M30"])
        return
    message = refusal(conn, machine, lines)
    assert f"line {where + 1} " in message and named in message


@pytest.mark.parametrize("comment", ["; DRAWING Läufer-Welle é ß", "G0 X40 Z2 ; Schrupp-Außen ÄÖÜ"])
def test_a_non_ascii_comment_of_the_840d_lathe_is_read(conn, comment):
    """Programs as stored on the control carry their writer's language in comments (issue 27):
    an umlaut there is text, not a block; in the code it is still refused."""
    assert accepted(conn, "lathe-840d", [*PRELUDES["lathe-840d"], "T1 D1", comment, "M30"])
    code = comment.replace(";", "X", 1) if comment.startswith(";") else comment.replace(" ;", "", 1)
    message = refusal(conn, "lathe-840d", [*PRELUDES["lathe-840d"], "T1 D1", code, "M30"])
    assert "non-ASCII character" in message


def test_an_iso_comment_cannot_close_early_and_hide_a_block(conn):
    message = refusal(conn, "lathe-iso", LATHE_ISO + ["(DRAWING a) G00 X9999 (b)"])
    assert "a comment is one (…) at the end of the block" in message


def test_a_header_stands_only_where_it_belongs(conn):
    assert "belongs only in the first line" in refusal(conn, "hobber-840d", HOBBING + ["%_N_OTHER_MPF"])
    assert "belongs only in the second line" in refusal(conn, "hobber-840d", HOBBING + [";$PATH=/_N_MPF_DIR"])
    assert "a ;$ directive" in refusal(conn, "hobber-840d", HOBBING + ["; X", ";$PATH=/_N_SPF_DIR"])
    assert "belongs only in the first or last line" in refusal(conn, "lathe-iso", LATHE_ISO + ["%", "M30"])


# ---------------------------------------------------------------- S, F and the machine

@pytest.mark.parametrize("machine, block, reason", [
    ("hobber-840d", "M3 S0", "S0 must be above 0"), ("hobber-840d", "M3 S-5", "S-5 must be above 0"),
    ("hobber-840d", "G1 X55 F0.0", "F0.0 must be above 0"), ("hobber-840d", "G1 X55 F-0.7", "F-0.7 must be above 0"),
    ("hobber-840d", "G4 F0", "F0 must be above 0"), ("hobber-840d", "M3 Snan", "Snan: inf/nan"),
    ("hobber-840d", "G1 Z10 Finf", "Finf: inf/nan"),
    ("lathe-840d", "G97 S0 M3", "S0 must be above 0"), ("lathe-840d", "G94 F-1", "F-1 must be above 0"),
    ("lathe-iso", "G97 S-0.0 M03", "S-0.0 must be above 0"), ("lathe-iso", "G98 F0", "F0 must be above 0"),
    ("lathe-iso", "G98 F20000.1", "feed F20000.1 exceeds 20000"),
])
def test_speeds_and_feeds_of_0_or_below_or_not_numbers_are_refused(conn, machine, block, reason):
    assert reason in refusal(conn, machine, program(machine, [block]))


def test_the_spindle_and_the_table_are_bounded_by_the_machine_record(conn):
    machine = load_machine(conn, "hobber-840d")
    teeth = 5
    fastest = machine.table_speed_max * teeth      # S at which C turns at the table's maximum
    assert fastest < machine.spindle_max
    coupled = ["G0 Y0.000", "EGDEF(C,B,1)", f'EGON(C,"FINE",B,-1,{teeth})']
    assert accepted(conn, "hobber-840d", program("hobber-840d", coupled + [f"M3 S{fastest:g}"], ready=False))
    assert "above hobber-840d's 120 r/min" in \
        refusal(conn, "hobber-840d", program("hobber-840d", coupled + [f"M3 S{fastest + 5:g}"], ready=False))
    assert f"exceeds hobber-840d's {machine.spindle_max:g} r/min" in \
        refusal(conn, "hobber-840d", program("hobber-840d", [f"M3 S{machine.spindle_max + 1:g}"], ready=False))


def test_an_840d_lathe_moves_only_after_diamon(conn):
    assert "motion before DIAMON" in refusal(conn, "lathe-840d", ["%_N_TEST_MPF", "G0 X50 Z5", "M30"])
    assert accepted(conn, "lathe-840d", program("lathe-840d", ["G0 X50 Z5", "G3 X50 Z-5 CR=5", "G33 Z-10 K1.5"]))


def test_a_lathe_arc_needs_its_start_and_its_radius(conn):
    assert "an arc from an unknown start point" in \
        refusal(conn, "lathe-iso", program("lathe-iso", ["G02 X10. Z-5. R5."]))
    assert "G2 without its R" in refusal(conn, "lathe-iso", program("lathe-iso", ["G00 X10. Z5.", "G02 X10. Z-5."]))
    assert "CR belongs to G2/G3" in refusal(conn, "lathe-840d", program("lathe-840d", ["G1 X10 Z5 CR=5"]))


def test_a_machine_without_a_grammar_makes_no_program(conn):
    machine = load_machine(conn, "hobber-840d")
    iso_hobber = replace(machine, dialect="iso")
    with pytest.raises(LimitError, match="no verifier grammar for a hobber with dialect 'iso'"):
        verify_program(["%", "M30", "%"], iso_hobber, "TEST")


# ---------------------------------------------------------------- end to end, on a real database


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("escape, named", [("\\n", "line feed"), ("\\r", "carriage return")])
def test_a_template_row_with_a_line_break_stores_and_writes_nothing(run, tmp_path, escape, named):
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = 300",
                     (f'f"; GEAR {{gear_id}}{escape}G0 X9999 Z-9999"',))
    before = programs(run.url)
    for args in (("--gear", 42), ("--gears", "42-43"), ("--gears", "42-43", "--workers", "2")):
        message = one_line_exit_1(run("instantiate", *args, "--draft"))   # the editor tries it (a draft: no file)
        assert "line 3 '; GEAR 42" in message and named in message and "nothing stored" in message
        assert programs(run.url) == before and list(tmp_path.iterdir()) == []


def runner_sets_program_name(url: str, job: int, name: str) -> bool:
    """As engine_runner (runners may write jobs): False if the database refuses the name itself."""
    with psycopg.connect(url) as conn:
        conn.execute("SET ROLE engine_runner")
        try:
            conn.execute("UPDATE job SET params = jsonb_set(params, '{program_name}', to_jsonb(%s::text)) "
                         "WHERE id = %s", (name, job))
        except (psycopg.errors.IntegrityError, psycopg.errors.RaiseException):
            return False
    return True


@pytest.mark.parametrize("name", ["X\nG0 X9999 Z-9999", "X\rG0 X9999 Z-9999", "X\\nG0 X9999 Z-9999"])
def test_a_stored_job_whose_program_name_holds_a_line_break_is_not_made_again(run, tmp_path, name):
    made = run("instantiate", "--gear", 42, "--json")
    assert made.exit_code == 0, made.output
    with psycopg.connect(run.url) as conn:
        job = conn.execute("SELECT max(id) FROM job").fetchone()[0]
    assert not runner_sets_program_name(run.url, job, name)   # the database refuses it where it enters
    with psycopg.connect(run.url) as conn:   # as in a database where it got in before that check existed
        conn.execute("ALTER TABLE job DROP CONSTRAINT job_safe_params")
    assert runner_sets_program_name(run.url, job, name)
    before = programs(run.url)
    for args in (("--job", job), ("--jobs", f"{job}-{job}")):
        message = one_line_exit_1(run("instantiate", *args, "--out", tmp_path))
        assert "nothing stored" in message or "program name" in message, message
        assert programs(run.url) == before and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("speed", ["0", "-5"])
def test_a_hob_speed_of_0_or_below_is_refused_as_it_is_given(read_only_run, tmp_path, speed):
    before = programs(read_only_run.url)
    message = one_line_exit_1(read_only_run("instantiate", "--gear", 42, "--hob-speed", speed, "--out", tmp_path))
    assert "--hob-speed" in message and speed in message
    assert programs(read_only_run.url) == before and list(tmp_path.iterdir()) == []


def test_a_drawing_whose_file_name_holds_a_line_break_makes_no_job(read_only_run, tmp_path):
    drawing = tmp_path / "part\nG0 X9999 Z-9999.dxf"
    seed_drawing(drawing)
    with psycopg.connect(read_only_run.url) as conn:
        jobs = conn.execute("SELECT count(*) FROM job").fetchone()[0]
    before = programs(read_only_run.url)
    one_line_exit_1(read_only_run("import-dxf", drawing))
    with psycopg.connect(read_only_run.url) as conn:
        assert conn.execute("SELECT count(*) FROM job").fetchone()[0] == jobs
    assert programs(read_only_run.url) == before
