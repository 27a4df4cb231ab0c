"""Attacks on the promises of issue 17 (adversary review): each test states the behaviour a
user relies on, and fails while the engine breaks it."""
from __future__ import annotations

import csv
import hashlib
import io
import json
import re

import psycopg
import pytest
from shared_data import shared_data

from engine.library.nc_import import import_nc
from engine.templates.decision_table import compiled_template
from engine.templates.store import load_template

NC = shared_data() / "nc"
DEMO = NC / "linuxcnc" / "lathe_g70_71_demo.ngc"          # G71/G70 call the contour O100 by Q100
CAM = NC / "sinumerik" / "cam_840dsl" / "CAM_TEST.MPF"     # Siemens: D1 (tool edge), SETMS(1) (spindle)
CRLF, LF = "\r\n", "\n"



def one_line_error(result) -> bool:
    return result.exit_code == 1 and result.stderr.startswith("error: ") and result.stderr.count("\n") == 1


def made(result) -> dict:
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


# --- 1. the layout a program is written with ------------------------------------------------

def with_layout_columns(exported: str, ending: str, final_newline: str) -> str:
    """The exported CSV with the two layout columns added to every row (rows unchanged)."""
    rows = list(csv.reader(io.StringIO(exported, newline="")))
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(rows[0] + ["line_ending", "final_newline"])
    writer.writerows(row + [ending, final_newline] for row in rows[1:])
    return buffer.getvalue()


def test_a_csv_import_does_not_change_the_bytes_of_released_programs_without_a_release(engine, tmp_path):
    """`template import` is a draft until a releaser releases it (engine_releaser, not the
    editor). A CSV with the very rows of the released version and the layout columns crlf,no
    says 'unchanged (identical rows)', makes no version, and yet every released program of the
    class is from then on written CR LF without a final newline: the bytes that reach the
    machine changed with nobody releasing anything."""
    before = tmp_path / "before.MPF"
    made(engine("instantiate", "--gear", 42, "--out", before, "--json"))
    edited = tmp_path / "spur.csv"
    edited.write_text(with_layout_columns(engine("template", "export", "--class", "spur").stdout, "crlf", "no"))
    imported = engine("template", "import", "--class", "spur", edited)
    assert imported.exit_code == 0, imported.output
    after = tmp_path / "after.MPF"
    program = made(engine("instantiate", "--gear", 42, "--out", after, "--json"))   # released, not --draft
    assert program["template_version"] == 1
    assert b"\r" not in after.read_bytes() and after.read_bytes().endswith(b"\n")


def test_programs_show_gives_the_bytes_its_file_was_written_with(engine, tmp_path):
    """A stored program is a record nobody rewrites: `programs show` joins its lines with the
    class's layout of today, so after an editor changes the class's layout (one UPDATE, granted
    to engine_editor) the program shows CR LF without a final newline, while the file the
    control holds, written when it was stored, is LF with one."""
    target = tmp_path / "GEAR42.MPF"
    program = made(engine("instantiate", "--gear", 42, "--out", target, "--json"))
    written = target.read_bytes()
    with psycopg.connect(engine.url) as conn:
        conn.execute("UPDATE gear_class SET line_ending = %s, final_newline = false WHERE name = 'spur'", (CRLF,))
    shown = engine("programs", "show", program["program_id"])
    assert shown.exit_code == 0, shown.output
    assert shown.stdout_bytes.endswith(written)
    record = made(engine("programs", "show", program["program_id"], "--json"))["programs"][0]
    assert (record["line_ending"], record["final_newline"]) == ("lf", True)


# --- 2. --params address binding -------------------------------------------------------------

def instantiated(conn, gear_class: str, params: dict) -> list[str]:
    return compiled_template(load_template(conn, gear_class)).run(params).lines


def test_a_plain_parameter_does_not_turn_the_contour_a_g71_calls_into_a_quantity(conn):
    """LinuxCNC's G71/G70 name the contour subroutine by Q (`G71.1 Q100` runs `O100 SUB`): Q100
    is a program number, like the O it names. A plain parameter whose value is 100 (a depth, a
    speed) binds those Q words, not the O100 label, so the class made with another value calls a
    subroutine the program does not have (or another contour)."""
    subs = {match for line in DEMO.read_text().splitlines() for match in re.findall(r"^\s*O(\d+)\s+SUB", line)}
    assert subs == {"100"}
    import_nc(conn, DEMO, "nc_q", {"depth": 100, "feed": 400})
    lines = instantiated(conn, "nc_q", {"depth": 200, "feed": 400})
    called = {match for line in lines for match in re.findall(r"^\s*G7[01][.\d]*\s+Q(\d+)", line)}
    defined = {match for line in lines for match in re.findall(r"^\s*O(\d+)\s+SUB", line)}
    assert called and called <= defined, \
        f"the G70/G71 lines call O{sorted(called)}, the program defines O{sorted(defined)}"


def test_a_plain_parameter_does_not_rebind_the_tool_edge_or_the_spindle_number(conn):
    """On the 840D, D1 selects the tool's cutting edge (as T selects the tool) and SETMS(1) the
    master spindle: numbers that are codes. A plain parameter of value 1 (passes, a count) binds
    every D1 and the SETMS argument of Siemens' CAM_TEST.MPF, so the class made with passes=2
    cuts with edge D2's offsets on spindle 2."""
    original = CAM.read_text().splitlines()
    edges = [line for line in original if re.search(r"\bD1\b", line)]
    assert edges and any("SETMS(1)" in line for line in original)
    import_nc(conn, CAM, "nc_d", {"passes": 1})
    lines = instantiated(conn, "nc_d", {"passes": 2})
    assert [line for line in lines if re.search(r"\bD1\b", line)] == edges
    assert any("SETMS(1)" in line for line in lines)


@pytest.mark.parametrize("value", ['{"a": 1}', "[400]", "true", "null", '"F400"'])
def test_a_bound_parameter_whose_value_is_no_number_is_refused(engine, tmp_path, value):
    """Only a number binds a word: `{"feed": {"value": true, "addresses": ["F"]}}` asks for F to
    be bound and binds nothing, F400 stays literal, no warning, exit 0; the user believes the
    feed is a parameter of the class."""
    params = tmp_path / "p.json"
    params.write_text(f'{{"feed": {{"value": {value}, "addresses": ["F"]}}}}')
    result = engine("import-nc", DEMO, "--class", "nc_nonumber", "--params", params)
    assert one_line_error(result) and "feed" in result.stderr, result.output


def test_a_json_parameter_given_twice_is_refused_as_the_csv_one_is(engine, tmp_path):
    """A CSV naming a parameter twice is refused; the JSON form silently keeps the last value
    ({"feed": 400, "feed": 3.0} binds 3.0 at I3.0 and leaves the feed F400 literal)."""
    params = tmp_path / "p.json"
    params.write_text('{"feed": 400, "feed": 3.0}')
    result = engine("import-nc", DEMO, "--class", "nc_twice", "--params", params)
    assert one_line_error(result) and "feed" in result.stderr, result.output


# --- 3. refactor families --------------------------------------------------------------------

def key_before_issue_17(t: str, a: str, b: str) -> str:
    """The key `engine refactor intend` stored for a pair before issue 17: sha256 of
    [t, the two full texts sorted] as JSON (the texts with their block numbers)."""
    return hashlib.sha256(json.dumps([t, *sorted((a, b))], ensure_ascii=True).encode("ascii")).hexdigest()


def members(entry: dict) -> set:
    """The texts a report entry lists: a family's members, or both sides of a pair."""
    return set(entry.get("members") or entry["members_a"] + entry["members_b"])


def test_a_pair_marked_intended_before_the_upgrade_stays_intended(engine):
    """A shop marked `N90 SUPA … D1` / `N140 SUPA … D1` intended (homing twice is meant) before
    issue 17. Since block numbers are left out of the keys, the mark's key matches nothing:
    the two lines come back in the nightly report, flagged NEW, as if nobody had decided."""
    imported = engine("import-nc", CAM, "--class", "cam")
    assert imported.exit_code == 0, imported.output
    a = '"N90 SUPA X=_X_HOME Y=_Y_HOME A=_A_HOME C=_C_HOME D1"'
    b = '"N140 SUPA X=_X_HOME Y=_Y_HOME A=_A_HOME C=_C_HOME D1"'
    with psycopg.connect(engine.url) as conn:
        assert conn.execute("SELECT count(DISTINCT o) FROM component WHERE o IN (%s, %s)", (a, b)).fetchone()[0] == 2
        conn.execute("INSERT INTO near_duplicate_intended (pair_key, t, a, b, why) VALUES (%s, 'prep', %s, %s, "
                     "'homing twice is meant')", (key_before_issue_17("prep", a, b), *sorted((a, b))))
    report = made(engine("refactor", "--threshold", "0.6", "--json"))
    listed = [entry for entry in report["near_duplicates"] if {a, b} <= members(entry)]
    assert listed == [] and report["intended"] >= 1


# --- 4. pictures -------------------------------------------------------------------------------

def test_a_picture_with_a_long_file_name_is_not_a_bug(engine, tmp_path):
    """A name of 249 characters is a valid file name (Linux allows 255); the picture is written
    beside it under `.NAME.<random>.png` first, which is too long: OSError, exit 2."""
    program = made(engine("instantiate", "--gear", 42, "--json"))
    target = tmp_path / ("p" * 245 + ".png")
    result = engine("plot", "--program", program["program_id"], "-o", target)
    assert result.exit_code != 2, result.output
    assert (result.exit_code == 0 and target.is_file()) or one_line_error(result)
    assert [path.name for path in tmp_path.iterdir() if path.suffix == ".png"] in ([], [target.name])


def test_a_cut_comment_with_dollar_signs_is_drawn_not_a_bug(engine, tmp_path):
    """The picture's legend takes a cut's label from the program's `; CUT …` comment; matplotlib
    reads text between two $ as TeX, so a draft whose comment says `$\\frac$` stores a program
    (the simulation proves it) that `engine plot` cannot draw: ValueError, exit 2."""
    exported = engine("template", "export", "--class", "spur").stdout
    assert exported.count("; CUT {cut_name}") == 2
    edited = tmp_path / "spur.csv"
    edited.write_text(exported.replace("; CUT {cut_name}", "; CUT {cut_name} $\\\\frac$"))
    assert engine("template", "import", "--class", "spur", edited).exit_code == 0
    program = made(engine("instantiate", "--gear", 42, "--draft", "--json"))
    target = tmp_path / "draft.png"
    result = engine("plot", "--program", program["program_id"], "-o", target)
    assert result.exit_code == 0 and target.is_file(), result.output


def test_the_picture_of_a_job_is_of_the_program_that_reaches_the_machine(engine, tmp_path):
    """`engine plot --job ID` draws the job's newest program. After an editor tries a draft on
    the job (`instantiate --job ID --draft`), that is the draft's program: the operator's picture
    of the job shows a program that never reaches the machine, and nothing in it says draft."""
    released = made(engine("instantiate", "--gear", 45, "--json"))
    exported = engine("template", "export", "--class", "spur").stdout
    edited = tmp_path / "spur.csv"
    edited.write_text(exported.replace("; CUT {cut_name}", "; CUT {cut_name} TRIAL"))
    assert engine("template", "import", "--class", "spur", edited).exit_code == 0
    draft = made(engine("instantiate", "--job", released["job_id"], "--draft", "--json"))
    assert draft["program_id"] != released["program_id"]
    drawn = made(engine("plot", "--job", released["job_id"], "-o", tmp_path / "job.png", "--json"))["drawn"]
    assert drawn[0].startswith(f"program {released['program_id']} ") or "draft" in " ".join(drawn).lower(), drawn


def figure_texts(figure) -> str:
    """Every text a reader of the picture sees: titles, legends, annotations."""
    texts = [figure._suptitle.get_text() if figure._suptitle else "", *(t.get_text() for t in figure.texts)]
    for legend in figure.legends:
        texts += [t.get_text() for t in legend.get_texts()]
    for axes in figure.axes:
        texts += [axes.get_title(), *(t.get_text() for t in axes.texts)]
        if axes.get_legend():
            texts += [t.get_text() for t in axes.get_legend().get_texts()]
    return " ".join(texts)


def test_the_picture_of_a_program_the_simulation_refuses_says_so(engine):
    """A picture is passed around without the command's output: when the simulation refuses the
    program now (its gear's face width was corrected after it was stored), only stdout says so,
    and the picture looks like that of a proved program."""
    from engine.hobbing.program_plot import load_scene, program_figure

    program = made(engine("instantiate", "--gear", 42, "--json"))
    with psycopg.connect(engine.url) as conn:
        conn.execute("UPDATE gear SET face_width = 40 WHERE id = 42")
        figure, drawn = program_figure(load_scene(conn, program["program_id"]))
    assert "refuses" in drawn[-1]
    assert "refus" in figure_texts(figure).lower()


@pytest.mark.parametrize("breaking", ["\r", "\f", "\u0085", "\u2028"], ids=["CR", "FF", "NEL", "LS"])
def test_an_nc_file_with_a_line_break_inside_a_line_is_refused_at_import(engine, tmp_path, breaking):
    """`G1 X10<CR>G0 X0` in an LF file is one line to the import (one row, its module decided by
    G0, one text to the refactor) and two blocks to a control or editor that breaks lines at a
    bare CR; the database refuses such a line in every program (migration 0009), so the class
    the import stores and calls a draft can never give a program. It should be refused naming
    the line, as a control character is, with nothing stored."""
    nc = tmp_path / "broken.nc"
    nc.write_bytes(f"G1 X10{breaking}G0 X0\nM30\n".encode())
    result = engine("import-nc", nc, "--class", "nc_broken")
    assert one_line_error(result) and "line 1" in result.stderr, result.output
    with psycopg.connect(engine.url) as conn:
        assert conn.execute("SELECT count(*) FROM gear_class WHERE name = 'nc_broken'").fetchone()[0] == 0


def test_a_params_file_nested_too_deep_is_bad_input_not_a_bug(engine, tmp_path):
    """A parameters file of 100,000 nested brackets (a generator gone wrong) is bad input:
    json.loads raises RecursionError, exit 2."""
    params = tmp_path / "deep.json"
    params.write_text('{"feed": ' + "[" * 100_000 + "]" * 100_000 + "}")
    result = engine("import-nc", DEMO, "--class", "nc_deep", "--params", params)
    assert one_line_error(result) and str(params) in result.stderr, result.output
