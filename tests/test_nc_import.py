"""Importing proven NC programs as standard code: the real files of tests/data/nc (LinuxCNC
plasmac imperial/metric pairs, lathe macros, a Sinumerik CAM program, EMCO tapes) come
back byte for byte after import → export → instantiate with the same parameters; numbers
equal to a parameter become references (never G/M numbers); lines get modules.

Newline convention: the instantiated lines are written joined by "\\n" with a final "\\n"
(engine.programs.records.Program.text); every real file ends with a newline, so the comparison
is of the exact bytes."""
from __future__ import annotations

import json
from decimal import Decimal

import pytest
from helpers.nc_files import DATA, FAMILY, MACROS, PARAMS, class_name, instantiate, real_files, stored, stored_at, write
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.errors import EngineError
from engine.library.nc_import import import_nc
from engine.library.nc_rows import number_field
from engine.nc.tokens import detokenise, tokenise
from engine.templates.evaluator import evaluate
from engine.templates.expressions import compile_expression
from engine.templates.store import ensure_class, load_template, replace_template
from engine.templates.template_csv import export_csv, parse_csv

# --- tokens ------------------------------------------------------------------------------

@pytest.mark.parametrize("relative", list(PARAMS))
def test_every_line_of_every_real_file_tokenises_back(relative):
    real_files()
    for line in (DATA / relative).read_text().split("\n"):
        tokens = tokenise(line)
        assert detokenise(tokens) == line and all(token.text for token in tokens)


@pytest.mark.parametrize("line, expected", [
    ("g0X-170", [("word", "g"), ("number", "0"), ("word", "X"), ("number", "-170")]),
    ("G01 F250. Z-.4", [("word", "G"), ("number", "01"), ("word", "F"), ("number", "250."),
                        ("word", "Z"), ("number", "-.4")]),
    ("X=R1+2", [("word", "X"), ("symbol", "="), ("param", "R1"), ("symbol", "+"), ("number", "2")]),
    ("((nested) comment) X1", [("comment", "((nested) comment)"), ("word", "X"), ("number", "1")]),
    ("%", [("symbol", "%")]),
    ("N10 G1", [("label", "N10"), ("word", "G"), ("number", "1")]),
    ("O<turning> sub", [("label", "O<turning>"), ("word", "sub")]),
    ("#14=[#14-#3 / 2]", [("param", "#14"), ("symbol", "="), ("symbol", "["), ("param", "#14"), ("symbol", "-"),
                          ("param", "#3"), ("symbol", "/"), ("number", "2"), ("symbol", "]")]),
    ('EGON(C,"FINE",B,-1,19)', [("word", "EGON"), ("symbol", "("), ("word", "C"), ("symbol", ","),
                                ("string", '"FINE"'), ("symbol", ","), ("word", "B"), ("symbol", ","),
                                ("number", "-1"), ("symbol", ","), ("number", "19"), ("symbol", ")")]),
    ("M3 (start) ; spindle", [("word", "M"), ("number", "3"), ("comment", "(start)"), ("comment", "; spindle")]),
    ("    01 25 -1000", [("number", "01"), ("number", "25"), ("number", "-1000")]),
])
def test_tokens_of_real_world_spellings(line, expected):
    tokens = tokenise(line)
    assert [(t.kind, t.text) for t in tokens if t.kind != "space"] == expected
    assert detokenise(tokens) == line


def test_numbers_know_their_address():
    numbers = {t.text: t.address for t in tokenise("G01 X-1.5 A=-1.763 M3 $0 q[2.5 / #<s>]") if t.kind == "number"}
    assert numbers == {"01": "G", "-1.5": "X", "-1.763": "A", "3": "M", "0": "$", "2.5": None}


NUMBER = st.from_regex(r"[+-]?([0-9]{1,5}\.?[0-9]{0,5}|\.[0-9]{1,5})", fullmatch=True)
FRAGMENT = st.one_of(
    st.sampled_from(["G", "g", "X", "Y", "z", "F", "M", "EGON", "IF", "sub", "$", "R1", "_X_HOME", "CYCLE800"]),
    NUMBER,
    st.from_regex(r"#([0-9]{1,3}|<[a-z_\[\].]{0,8}>?)", fullmatch=True),
    st.from_regex(r"\((\(?[ -~]{0,10}\)?)*\)?", fullmatch=True).filter(lambda s: "\n" not in s),
    st.from_regex(r";[ -~\t]{0,12}", fullmatch=True),
    st.from_regex(r'"[ -~]{0,6}"?', fullmatch=True),
    st.sampled_from([" ", "\t", "  ", "=", "[", "]", "(", ")", ",", "+", "-", "*", "/", "%", ":", "`", "\r",
                     "{", "}", "\\", "'", "N10", "O<x>", "O100"]),
)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=400, deadline=None)
@given(st.lists(FRAGMENT, max_size=25).map("".join))
def test_nc_like_lines_tokenise_back(line):
    tokens = tokenise(line)
    assert detokenise(tokens) == line
    assert all(token.text for token in tokens)
    assert all(Decimal(t.text) is not None for t in tokens if t.kind == "number")


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet=st.characters(blacklist_characters="\n"), max_size=60))
def test_any_text_tokenises_back(line):
    assert detokenise(tokenise(line)) == line


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=400, deadline=None)
@given(NUMBER)
def test_a_number_field_prints_the_original_value_as_written(spelling):
    value = float(spelling)
    digits = Decimal(spelling).normalize().as_tuple()
    significant = len(digits.digits) + max(int(digits.exponent), 0)
    if Decimal(str(value)) != Decimal(spelling) or (spelling.startswith("-") and value == 0) or significant > 8:
        return   # a float that cannot hold the digits, a negative zero, more digits than an NC word holds: literal
    compiled = compile_expression('f"' + number_field("p", spelling) + '"')
    assert evaluate(compiled, {"p": value}) == spelling


@pytest.mark.parametrize("spelling, value, printed", [
    ("250.", 300, "300."), ("-.4", -0.7, "-.7"), ("-.4", 1.5, "1.5"), (".3048", 0.5, ".5000"),
    ("0.0500", 0.125, "0.1250"), ("-00500", 42, "000042"), ("03000", -5, "-0005"), ("+5", 7, "+7"),
])
def test_other_values_print_in_the_style_of_the_original(spelling, value, printed):
    compiled = compile_expression('f"' + number_field("p", spelling) + '"')
    assert evaluate(compiled, {"p": value}) == printed


# --- the real programs ---------------------------------------------------------------------

@pytest.mark.parametrize("relative", list(PARAMS))
def test_real_file_round_trips_through_import_export_and_instantiation(real_library, real_conn, relative):
    real_files()
    conn, path, params = real_conn, DATA / relative, PARAMS[relative]
    report = real_library.imported(relative)   # import_nc, once per worker (ImportedLibrary)
    exported = export_csv(load_template(conn, class_name(relative)))

    copy = class_name(relative) + "_copy"
    ensure_class(conn, copy)
    replace_template(conn, copy, parse_csv(exported))
    # the copy is a new class: its lines are the file's, its layout the default (LF, a final
    # newline); the file's own CR LF and last line come back byte for byte from its own class
    # (tests/test_nc_line_endings.py)
    lines = path.read_text().splitlines()
    assert instantiate(conn, copy, params).encode() == ("\n".join(lines) + "\n").encode()
    assert report.rows == len(path.read_text().splitlines())
    assert sum(report.modules.values()) == report.rows


# Changing a parameter changes exactly the lines that hold its value, in the same style.
CHANGES = {
    FAMILY + "imperial_ramp_pierce.ngc": (
        {"scale": 10, "pierce_end_height": 3.2, "gouge_speed": 1000, "gouge_distance": 6, "cut_length": 75},
        {5: "#<scale> = 10.0"}),   # q[2.5 / #<scale>]: a number inside […] is never bound (issue 27)
    FAMILY + "metric_ramp_pierce.ngc": (
        {"pierce_end_height": 3.2, "gouge_speed": 1000, "gouge_distance": 6, "cut_length": 75,
         "path_tolerance": 0.3, "tracking_tolerance": 0.05},
        {13: " G64 P0.300 Q0.050 (tracking tolerances: 0.254mm)",
         17: " m159 p603 q3.2 (pierce end height)",
         19: " m159 p605 q1000 (gouge speed in units per min)",
         20: " m159 p606 q6   (Gouge distance in machine units)",
         34: " G1 X0 Y75"}),
    FAMILY + "metric_wrench.ngc": (
        {"holes": 6, "path_tolerance": 0.1, "hole_x": 150, "hole_y": 30},
        {3: "#<holes> = 6 (holes and arcs with overburn)",
         6: "G64 P0.100 (path tolerance)",
         12: "G0 X150.000 Y30.00",
         14: "G3 X150.000 Y30.00 I-2 J0"}),
    MACROS + "turning.ngc": (   # its conversions are constants of expressions `[#1 * 25.4]`: never bound
        {"mm_per_inch": 25, "m_per_ft": 0.5, "finish_fraction": 0.75}, {}),
}


@pytest.mark.parametrize("relative", list(CHANGES))
def test_parameter_references_sit_where_the_values_were(conn, relative):
    real_files()
    original = (DATA / relative).read_text().split("\n")
    changes, expected = CHANGES[relative]
    import_nc(conn, DATA / relative, class_name(relative), PARAMS[relative])
    produced = instantiate(conn, class_name(relative), {**PARAMS[relative], **changes}).split("\n")
    differing = {number: line for number, line in enumerate(produced, start=1) if line != original[number - 1]}
    assert differing == expected


def referenced(conn, gear_class: str) -> set[str]:
    return {name for row in load_template(conn, gear_class).rows for name in compile_expression(row.o).names}


@pytest.mark.parametrize("pair", ["wrench", "ramp_pierce"])
def test_imperial_and_metric_members_of_a_family_share_their_parameters(conn, pair):
    real_files()
    for unit in ("imperial", "metric"):
        relative = f"{FAMILY}{unit}_{pair}.ngc"
        import_nc(conn, DATA / relative, class_name(relative), PARAMS[relative])
    imperial, metric = (referenced(conn, f"nc_{unit}_{pair}") for unit in ("imperial", "metric"))
    assert imperial - {"scale"} <= metric - {"tracking_tolerance"}   # the imperial ramp's values sit inside […]
    assert {"path_tolerance"} <= metric & imperial


def test_g_and_m_numbers_stay_literal_and_others_become_references(conn, tmp_path):
    path = write(tmp_path, "G01 X1 F250.\nM3 S1 $1\nG1 Z-.4 (1 mm)\n")
    report = import_nc(conn, path, "nc_snippet", {"x": 1, "feed": 250, "depth": -0.4})
    rows = load_template(conn, "nc_snippet").rows
    assert rows[0].o == 'f"G01 X{x:~#} F{feed:~#.}"'
    assert rows[1].o == 'f"M3 S{x:~#} $1"'   # M3 and $1 are codes; S1 is a value
    assert "G1 Z" in rows[2].o and "(1 mm)" in rows[2].o and "depth" in rows[2].o
    assert report.parameterised == 4 and report.ambiguous == {}
    assert instantiate(conn, "nc_snippet", {"x": 2, "feed": 300, "depth": -0.75}) == \
        "G01 X2 F300.\nM3 S2 $1\nG1 Z-.75 (1 mm)\n"   # the value's own digits, never rounded


def test_a_value_two_parameters_share_uses_the_first_and_is_reported(conn, tmp_path):
    report = import_nc(conn, write(tmp_path, "G0 X5 Z5\n"), "nc_shared", {"x_start": 5, "z_start": 5})
    field = "{x_start:~#}"
    assert load_template(conn, "nc_shared").rows[0].o == f'f"G0 X{field} Z{field}"'
    assert report.ambiguous == {"5": ["x_start", "z_start"]}


def test_quotes_braces_and_backslashes_survive(conn, tmp_path):
    text = 'T="A{1}\\B" \'q\' X1\nMSG("50% {x}\\\\")\n \'only\' "both"\n'
    path = write(tmp_path, text)
    import_nc(conn, path, "nc_quotes", {"x": 1})
    assert instantiate(conn, "nc_quotes", {"x": 1}) == text
    assert instantiate(conn, "nc_quotes", {"x": 7}) == text.replace("X1", "X7")


# --- modules -------------------------------------------------------------------------------

# An 840D hobbing program in the order of design notes §7; the modules as the seeded spur
# template numbers them (M9 cutcond 2, EGOFS sync 2, M5 cutcond 3, M30 main 2).
HOBBING = [
    ("%_N_TEST_MPF", "main", 1), (";$PATH=/_N_MPF_DIR", "main", 1), ("; GEAR 1 CLASS spur", "main", 1),
    ("G90 G71 G94", "prep", 1), ("G25 X0 Y-50 Z-100", "prep", 1), ("G26 X200 Y50 Z50", "prep", 1),
    ("WALIMON", "prep", 1), ("T1 D1", "prep", 1), ("G0 X120 Z5", "prep", 1), ("G0 A=-1.763", "prep", 1),
    ("EGDEF(C,B,1)", "sync", 1), ('EGON(C,"FINE",B,-1,19)', "sync", 1), ("G0 Y10.5", "shift", 1),
    ("M3 S250", "cutcond", 1), ("M8", "cutcond", 1),
    ("G1 X42.5 F36", "cutmotion", 1), ("G1 Z-25 F105", "cutmotion", 1), ("G0 X120", "cutmotion", 1),
    ("M9", "cutcond", 2), ("EGOFS(C)", "sync", 2), ("M5", "cutcond", 3), ("M30", "main", 2),
]


def test_modules_of_an_840d_hobbing_program(conn, tmp_path):
    path = write(tmp_path, "".join(line + "\n" for line, _, _ in HOBBING))
    report = import_nc(conn, path, "nc_hobbing", {"z2": 19})
    rows = load_template(conn, "nc_hobbing").rows
    assert [(row.t, row.n) for row in rows] == [(t, n) for _, t, n in HOBBING]
    assert [row.id for row in rows] == list(range(10, 10 * len(HOBBING) + 1, 10))
    assert report.modules == {"main": 4, "prep": 7, "sync": 3, "shift": 1, "cutcond": 4, "cutmotion": 3}
    assert rows[11].o == """f'EGON(C,"FINE",B,-1,{z2:~#})'"""


def test_the_engineer_corrects_modules_and_following_lines_follow(conn, tmp_path):
    path = write(tmp_path, "".join(line + "\n" for line, _, _ in HOBBING))
    import_nc(conn, path, "nc_corrected", {}, modules={7: "main", 8: "prep"})
    rows = load_template(conn, "nc_corrected").rows
    assert [(row.t, row.n) for row in rows[3:9]] == [("prep", 1)] * 3 + [("main", 2), ("prep", 2), ("prep", 2)]


# --- refusals: all or nothing --------------------------------------------------------------


@pytest.mark.parametrize("content, words", [
    (b"", "is empty"),
    (b"  \n\n", "is empty"),
    (b"G1 X1\n\x00\x01\x02binary", "binary"),
    (b"G1 X1 (\xe9t\xe9)\n", "not UTF-8"),
])
def test_files_that_are_not_nc_text_are_refused(conn, tmp_path, content, words):
    path = tmp_path / "bad.nc"
    path.write_bytes(content)
    before = stored(conn)
    with pytest.raises(EngineError, match=words):
        import_nc(conn, path, "nc_bad", {})
    assert stored(conn) == before


def test_a_line_too_long_for_a_row_stores_nothing(conn, tmp_path):
    before = stored(conn)
    with pytest.raises(EngineError, match="line 2: 5000 characters"):
        import_nc(conn, write(tmp_path, "G1 X1\n" + "X" * 5000 + "\n"), "nc_long", {})
    assert stored(conn) == before


def test_a_parent_with_rows_of_its_own_is_refused(conn, tmp_path):
    before = stored(conn)
    with pytest.raises(EngineError, match="inherits rows"):
        import_nc(conn, write(tmp_path, "G1 X1\n"), "nc_child", {}, parent="spur")
    assert stored(conn) == before


def test_a_parent_without_rows_is_fine(conn, tmp_path):
    ensure_class(conn, "nc_family")
    import_nc(conn, write(tmp_path, "G1 X1\n"), "nc_member", {"x": 1}, parent="nc_family")
    assert conn.execute("SELECT parent FROM gear_class WHERE name = 'nc_member'").fetchone() == ("nc_family",)


# --- the command ---------------------------------------------------------------------------


def test_import_nc_command_reports_json_and_export_gives_the_rows(run, tmp_path):
    params = tmp_path / "params.csv"
    params.write_text("name,value\nfeed,250\nx,1\n")
    modules = tmp_path / "modules.csv"
    modules.write_text("line_no,t\n2,cutcond\n")
    path = write(tmp_path, "G01 X1\nF250.\nG1 Z-1\n")
    result = run("import-nc", path, "--class", "nc_cli", "--params", params, "--modules", modules, "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert report["rows"] == 3 and report["parameterised"] == 2 and report["created"] is True
    assert report["modules"] == {"cutcond": 1, "cutmotion": 2}
    exported = run("template", "export", "--class", "nc_cli")
    assert exported.stdout.splitlines()[1:] == [
        '10,cutmotion,1,,,"f""G01 X{x:~#}""",', '20,cutcond,1,,,"f""F{feed:~#.}""",',
        '30,cutmotion,2,,,"""G1 Z-1""",']


@pytest.mark.parametrize("make, extra, words", [
    (lambda d: d / "missing.nc", (), "cannot read"),
    (lambda d: write(d, "\x00\x00", "bin.nc"), (), "binary"),
    (lambda d: write(d, "G1 X1\n", "ok.nc"), ("--params", "{d}/p.json"), "not JSON"),
    (lambda d: write(d, "G1 X1\n", "ok.nc"), ("--params", "{d}/bad_name.csv"), "parameter name '1x'"),
    (lambda d: write(d, "G1 X1\n", "ok.nc"), ("--modules", "{d}/m.csv"), "module type 'cutting'"),
    (lambda d: write(d, "G1 X1\n", "ok.nc"), ("--modules", "{d}/far.csv"), "line 9 is not a line"),
    (lambda d: write(d, "G1 X1\n", "ok.nc"), ("--parent", "nope"), "parent class 'nope' does not exist"),
])
def test_bad_input_gets_one_line_exit_1_and_changes_nothing(read_only_run, tmp_path, make, extra, words):
    (tmp_path / "p.json").write_text("{nope")
    (tmp_path / "bad_name.csv").write_text("name,value\n1x,3\n")
    (tmp_path / "m.csv").write_text("line_no,t\n1,cutting\n")
    (tmp_path / "far.csv").write_text("line_no,t\n9,prep\n")
    before = stored_at(read_only_run.url)
    result = read_only_run("import-nc", make(tmp_path), "--class", "nc_bad",
                           *[arg.format(d=tmp_path) for arg in extra])
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1 and words in message
    assert stored_at(read_only_run.url) == before
