"""Issue 27: a bound word of an imported program is written with the value given, never rounded
to the decimals the file had (feed 0.025 in the style of `F0.1` is `F0.025`, not `F0.0`); a value
no NC word holds exactly is refused when the class is instantiated. Numbers inside `[…]`, the
spindle clamp of `G50 S…`/`LIMS=` and the lengths of the lathe cycles G71–G76 are not bound with
the speed or the feed. The report lists per parameter the words bound and left alone, with their
lines. A tab is refused at import, naming its line. Expected values are computed here from the
value's own digits (Decimal of its repr), never read off the engine's output."""
from __future__ import annotations

import json
import re
from decimal import Decimal

import psycopg
import pytest
from helpers.nc_files import DATA, MACROS, PARAMS, REAL, TABBED, class_name, instantiated, stored, write

from engine.errors import EngineError
from engine.library.nc_import import import_nc

THREADING = MACROS + "threading.ngc"          # LinuxCNC lathe macro: `g95 F0.1 ; Feed-Per-Rev Mode`
CAM = "sinumerik/cam_840dsl/CAM_TEST.MPF"     # 840D sl CAM output: `F250.`, trailing points


def own_digits(value, decimals: int, point: bool) -> str:
    """The value's shortest exact decimal, with at least `decimals` after the point; a whole value
    keeps the trailing point of a `250.` style."""
    exact = Decimal(repr(value)) if isinstance(value, float) else Decimal(value)
    places = max(decimals, -exact.normalize().as_tuple().exponent, 0)
    text = f"{exact:.{places}f}"
    return text + "." if point and "." not in text else text


def lines_with(relative: str, word: str) -> list[int]:
    """Lines whose code (comments removed) holds `word` as a whole word."""
    pattern = re.compile(rf"(?<![A-Za-z0-9.]){re.escape(word)}(?![0-9.])", re.IGNORECASE)
    return [number for number, line in enumerate((DATA / relative).read_text().splitlines(), start=1)
            if pattern.search(re.sub(r"\([^()]*\)|;.*", "", line))]


@pytest.mark.parametrize("feed", [0.025, 0.0125, 0.25, 0.1, 2, 0.12345678])
def test_a_new_feed_is_written_with_its_own_digits_in_a_real_lathe_macro(conn, feed):
    at = lines_with(THREADING, "F0.1")
    assert at, "the macro no longer writes its feed as F0.1"
    import_nc(conn, DATA / THREADING, "nc_threading", PARAMS[THREADING])
    produced = instantiated(conn, "nc_threading", {**PARAMS[THREADING], "feed_per_rev": feed})
    original = (DATA / THREADING).read_text().splitlines()
    expected = [re.sub(r"(?<=F)0\.1(?![0-9])", own_digits(feed, 1, False), line) if number in at else line
                for number, line in enumerate(original, start=1)]
    assert produced == expected
    assert Decimal(re.search(r"F([0-9.]+)", produced[at[0] - 1])[1]) == Decimal(repr(float(feed)))   # exact


@pytest.mark.parametrize("feed", [31.25, 20, 0.5, 1234.5678])
def test_a_trailing_point_style_keeps_its_point_and_takes_the_digits_the_value_needs(conn, feed):
    at = lines_with(CAM, "F250.")
    import_nc(conn, DATA / CAM, "nc_cam", PARAMS[CAM])
    produced = instantiated(conn, "nc_cam", {**PARAMS[CAM], "feed": feed})
    original = (DATA / CAM).read_text().splitlines()
    for number in at:
        assert produced[number - 1] == original[number - 1].replace("F250.", "F" + own_digits(feed, 0, True))
    assert [line for number, line in enumerate(produced, 1) if number not in at] == [
        line for number, line in enumerate(original, 1) if number not in at]


@pytest.mark.parametrize("feed, digits", [(0.1 + 0.2, 17), (1 / 3, 16), (123456.789, 9)])
def test_a_value_no_word_holds_exactly_is_refused_at_instantiate_never_rounded(run, tmp_path, feed, digits):
    assert len(Decimal(repr(feed)).normalize().as_tuple().digits) == digits
    imported = tmp_path / "imported.json"
    imported.write_text(json.dumps(PARAMS[THREADING]))
    result = run("import-nc", DATA / THREADING, "--class", "nc_threading", "--params", imported)
    assert result.exit_code == 0, result.output
    params = tmp_path / "new.json"
    params.write_text(json.dumps({"feed_per_rev": feed}))
    with psycopg.connect(run.url) as connection:
        before = connection.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone()
    refused = run("instantiate", "--class", "nc_threading", "--machine", "lathe-iso", "--draft", "--unverified",
                  "--params", params)
    assert refused.exit_code == 1, refused.output
    message = refused.stderr.strip()
    assert len(message.splitlines()) == 1 and "Traceback" not in refused.output
    assert f"{digits} significant digits" in message and "cannot be written exactly" in message, message
    with psycopg.connect(run.url) as connection:
        assert connection.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone() \
            == before


# A lathe program shaped as Haas and Fanuc programs are (an ISO lathe): the clamp G50 S is the
# same number as the G96 speed, the G71 allowances U W are the same number as the feed.
ISO = """%
O1234 (SHAFT)
G50 S1000 (MAX RPM)
G96 S1000 M03
G00 X52. Z2.
G71 U1. R0.5
G71 P10 Q20 U0.01 W0.01 F0.01
N10 G00 X20.
N20 G01 Z-30. F0.01
G70 P10 Q20
M30
%
"""
SIEMENS = """DEF REAL TECH_TIME[10]
TECH_TIME[4]=4
LIMS=1000
G96 S1000 M3
G1 X4 F0.01
"""
LINUXCNC = "#<depth> = 2\nG1 X[#<depth>+2] Z2 F0.01\n"


@pytest.mark.parametrize("form", ["plain", "bound"])
def test_the_spindle_clamp_and_the_cycle_allowances_stay_when_speed_and_feed_change(conn, tmp_path, form):
    params = ({"speed": 1000, "feed": 0.01} if form == "plain" else
              {"speed": {"value": 1000, "addresses": ["S"]}, "feed": {"value": 0.01, "addresses": ["F"]}})
    report = import_nc(conn, write(tmp_path, ISO), "nc_iso", params)
    produced = instantiated(conn, "nc_iso", {"speed": 180, "feed": 0.025})
    expected = [line.replace("G96 S1000", "G96 S180").replace("F0.01", "F" + own_digits(0.025, 2, False))
                for line in ISO.splitlines()]
    assert produced == expected
    lines = ISO.splitlines()
    clamp = next(number for number, line in enumerate(lines, 1) if line.startswith("G50"))
    cycle = next(number for number, line in enumerate(lines, 1) if "U0.01" in line)
    left = {(entry["line"], entry["word"], entry["parameter"]) for entry in report.left_alone}
    assert {(clamp, "S1000", "speed"), (cycle, "U0.01", "feed"), (cycle, "W0.01", "feed")} <= left
    why = {entry["word"]: entry["why"] for entry in report.left_alone}
    assert "speed limit" in why["S1000"] and "not a feed" in why["U0.01"]


def test_subscripts_expressions_and_lims_are_never_bound(conn, tmp_path):
    import_nc(conn, write(tmp_path, SIEMENS, "TECH.MPF"), "nc_tech", {"x": 4, "speed": 1000})
    produced = instantiated(conn, "nc_tech", {"x": 8, "speed": 150})
    assert produced == ["DEF REAL TECH_TIME[10]", "TECH_TIME[4]=8", "LIMS=1000", "G96 S150 M3", "G1 X8 F0.01"]
    import_nc(conn, write(tmp_path, LINUXCNC, "depth.ngc"), "nc_depth", {"depth": 2})
    assert instantiated(conn, "nc_depth", {"depth": 3}) == ["#<depth> = 3", "G1 X[#<depth>+2] Z3 F0.01"]


def test_the_report_lists_the_words_bound_and_left_alone_with_their_lines(run, tmp_path):
    params = tmp_path / "params.json"
    params.write_text(json.dumps({"feed": {"value": 0.01, "addresses": ["F"]}, "speed": 1000}))
    result = run("import-nc", write(tmp_path, ISO), "--class", "nc_iso", "--params", params, "--json")
    assert result.exit_code == 0, result.output
    report = {entry["parameter"]: entry for entry in json.loads(result.stdout)["bindings"]}
    lines = ISO.splitlines()
    at = {address: [number for number, line in enumerate(lines, 1) if re.search(rf"\b{address}0\.01\b", line)]
          for address in "FUW"}
    assert report["feed"]["lines"] == {"F": at["F"]} and report["feed"]["at"] == {"F": len(at["F"])}
    assert report["feed"]["left_alone"] == {address: {"words": len(at[address]), "lines": at[address]}
                                            for address in "UW"}
    speeds = [number for number, line in enumerate(lines, 1) if "S1000" in line]
    assert report["speed"]["lines"] == {"S": speeds[1:]} and report["speed"]["left_alone"] == {
        "S": {"words": 1, "lines": speeds[:1]}}
    text = run("import-nc", write(tmp_path, ISO), "--class", "nc_iso2", "--params", params)
    feed_line = next(line for line in text.stdout.splitlines() if line.strip().startswith("feed"))
    assert f"F {len(at['F'])}: lines {at['F'][0]}, {at['F'][1]}" in feed_line
    assert f"left alone: U 1 (line {at['U'][0]}); W 1 (line {at['W'][0]})" in feed_line


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_each_real_program_with_a_tab_is_refused_at_import_naming_the_line(conn):
    assert TABBED, "no real program with a tab left: the refusal is no longer exercised"
    for relative in TABBED:
        text = (REAL / relative).read_text()
        tab = text.index("\t")
        line, column = text.count("\n", 0, tab) + 1, tab - text.rfind("\n", 0, tab)
        before = stored(conn)
        with pytest.raises(EngineError, match=rf"line {line} column {column} holds a tab.*nothing stored"):
            import_nc(conn, REAL / relative, class_name(relative), PARAMS[relative])
        assert stored(conn) == before
        import_nc(conn, DATA / relative, class_name(relative), PARAMS[relative])   # its tabs made spaces: in


def test_the_import_nc_command_refuses_a_tab_with_exit_1(read_only_run, tmp_path):
    path = write(tmp_path, "G0 X1\nG1\tX2 F0.1\n")
    result = read_only_run("import-nc", path, "--class", "nc_tab")
    assert result.exit_code == 1 and "line 2 column 3 holds a tab" in result.stderr, result.output
    listed = read_only_run("template", "export", "--class", "nc_tab")
    assert listed.exit_code != 0   # no class was made


def test_a_format_spec_of_python_with_a_tilde_fill_is_still_python_s():
    from engine.templates.evaluator import evaluate
    from engine.templates.expressions import compile_expression

    assert evaluate(compile_expression('f"{x:~>6}|{x:~#.00}|{x:~^7.2f}"'), {"x": 1.5}) == \
        f"{1.5:~>6}|{own_digits(1.5, 2, False)}|{1.5:~^7.2f}"
