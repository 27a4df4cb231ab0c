"""A parameter binds the addresses it names (issue 17): `--params` with
`{"diameter": {"value": 0.3, "addresses": ["D"]}}` turns only the D words of value 0.3 into
references; an equal number at another address (the retract `R0.3` of LinuxCNC's G71 demo) stays as
written and is reported with its line. The plain form binds every address but G M N O T $. What the
tests expect is read off the real files' words here, by a regular expression of their own."""
from __future__ import annotations

import json
import re
from decimal import Decimal

import psycopg
import pytest
from helpers.class_jobs import import_emco
from helpers.nc_files import DATA, binds, bound_count, instantiated, real_files, stored_at, stored_rows, written_back
from helpers.outcomes import one_line_error

from engine.library import nc_halves
from engine.library.nc_import import import_nc

DEMO = "linuxcnc/lathe_g70_71_demo.ngc"      # D0.3 (cutter compensation) and R0.3 (G71's retract)
CAM = "sinumerik/cam_840dsl/CAM_TEST.MPF"    # I4.25 and J4.25 (arc centres)
# (file, parameter, its value, the address it binds, the other value that keeps its spelling)
CASES = [(DEMO, "diameter", "0.3", "D", "0.4"), (CAM, "radius", "4.25", "I", "4.75")]
OTHER = {DEMO: {"feed": 400}, CAM: {"feed": 250}}

WORD = re.compile(r"(?<![A-Za-z_$#])([A-Za-z])(\s*=?\s*)([+-]?(?:\d+\.?\d*|\.\d+))")
COMMENT = re.compile(r";.*|\([^()]*\)")


def words(relative: str) -> list[tuple[int, str, str, str]]:
    """(line, address upper case, the word as written, its number) of every word outside comments."""
    found = []
    for number, line in enumerate((DATA / relative).read_text().splitlines(), start=1):
        code = COMMENT.sub(lambda match: " " * len(match.group()), line)
        found += [(number, match.group(1).upper(), match.group(), match.group(3)) for match in WORD.finditer(code)]
    return found


def equal_words(relative: str, value: str) -> list[tuple[int, str, str, str]]:
    return [word for word in words(relative) if Decimal(word[3]) == Decimal(value)]


CYCLE = re.compile(r"\bG7[0-6](\.[12])?\b", re.IGNORECASE)   # the lathe cycles G70–G76 (LinuxCNC's G71.1 …)


def in_cycle(relative: str, line: int, address: str) -> bool:
    """Whether the word is a cycle's length (U W R of a G71–G76 block, issue 27): no feed binds it."""
    return address in "UWR" and bool(CYCLE.search((DATA / relative).read_text().splitlines()[line - 1]))


def left_per_address(left: list) -> dict:
    """address → {"words", "lines"} of the equal words left alone, as the report counts them."""
    per: dict = {}
    for line, address, _, _ in left:
        per.setdefault(address, []).append(line)
    return {address: {"words": len(lines), "lines": lines} for address, lines in sorted(per.items())}


def bound_form(parameter: str, value: str, address: str, relative: str) -> dict:
    return {parameter: {"value": float(value), "addresses": [address]}, **OTHER[relative]}


@pytest.mark.parametrize("relative, parameter, value, address, other", CASES)
def test_a_bound_parameter_becomes_a_reference_only_at_its_address(conn, relative, parameter, value, address, other):
    real_files()
    equal = equal_words(relative, value)
    at_address = [word for word in equal if word[1] == address]
    elsewhere = [word for word in equal if word[1] not in (address, "G", "M")]
    assert at_address and elsewhere, "the file no longer holds the value at two addresses"
    report = import_nc(conn, DATA / relative, "nc_bound", bound_form(parameter, value, address, relative))

    rows = stored_rows(conn, "nc_bound")
    assert {line for line, o in rows.items() if binds(o, parameter)} == {line for line, *_ in at_address}
    for line, _, word, _ in elsewhere:
        assert word in rows[line] and bound_count(rows[line], parameter) == sum(
            1 for found in at_address if found[0] == line)
    assert [(left["line"], left["word"], left["parameter"]) for left in report.left_alone] == [
        (line, word, parameter) for line, _, word, _ in elsewhere]
    for left, (line, found_address, word, _) in zip(report.left_alone, elsewhere):   # a cycle's length names itself
        assert left["why"].startswith(f"{word} names the cycle's" if in_cycle(relative, line, found_address)
                                      else f"{parameter} binds only {address}")
    assert report.bindings[0] == {"parameter": parameter, "addresses": [address], "binds": address,
                                  "words": len(at_address), "at": {address: len(at_address)},
                                  "lines": {address: [line for line, *_ in at_address]},
                                  "left_alone": left_per_address(elsewhere)}


@pytest.mark.parametrize("relative, parameter, value, address, other", CASES)
def test_a_new_value_changes_only_the_bound_words(conn, relative, parameter, value, address, other):
    params = bound_form(parameter, value, address, relative)
    import_nc(conn, DATA / relative, "nc_bound", params)
    original = (DATA / relative).read_text().splitlines()
    expected = list(original)
    for line, found_address, word, number in equal_words(relative, value):
        if found_address == address:
            expected[line - 1] = expected[line - 1].replace(word, word[:-len(number)] + other, 1)
    assert expected != original
    assert instantiated(conn, "nc_bound", {**OTHER[relative], parameter: float(other)}) == expected
    assert written_back(conn, "nc_bound",
                        {**OTHER[relative], parameter: float(value)}) == (DATA / relative).read_bytes()


@pytest.mark.parametrize("relative, parameter, value, address, other", CASES)
def test_the_plain_form_binds_every_address_but_the_codes(conn, relative, parameter, value, address, other):
    report = import_nc(conn, DATA / relative, "nc_plain", {parameter: float(value), **OTHER[relative]})
    equal = equal_words(relative, value)
    quantities = [word for word in equal if word[1] not in "GMNOT" and not in_cycle(relative, word[0], word[1])]
    rows = stored_rows(conn, "nc_plain")
    assert {line for line, o in rows.items() if binds(o, parameter)} == {line for line, *_ in quantities}
    assert {found for found in (word[1] for word in quantities)} >= {address}   # the demo's R0.3 is G71's retract
    assert [(left["line"], left["word"], left["parameter"]) for left in report.left_alone] == [
        (line, word, parameter) for line, found, word, _ in equal if found in "NOT" or in_cycle(relative, line, found)]
    counts = {found: sum(1 for word in quantities if word[1] == found) for found in sorted({w[1] for w in quantities})}
    assert {key: report.bindings[0][key] for key in ("parameter", "addresses", "binds", "words", "at")} == {
        "parameter": parameter, "addresses": None, "binds": "every address but G M N O T $",
        "words": len(quantities), "at": counts}
    assert conn.execute("SELECT import_params FROM gear_class WHERE name = 'nc_plain'").fetchone()[0] == \
        {parameter: float(value), **OTHER[relative]}


def test_the_class_keeps_the_plain_values_of_a_bound_form(conn):
    import_nc(conn, DATA / DEMO, "nc_bound", bound_form("diameter", "0.3", "D", DEMO))
    assert conn.execute("SELECT import_params FROM gear_class WHERE name = 'nc_bound'").fetchone()[0] == \
        {"diameter": 0.3, "feed": 400}


def test_a_tool_number_equal_to_a_plain_value_is_left_alone_and_reported(conn):
    tools = [word for word in words(DEMO) if word[1] == "T"]
    number = tools[0][3]
    report = import_nc(conn, DATA / DEMO, "nc_tool", {"tool": int(number)})
    equal = equal_words(DEMO, number)
    # T names the tool; the demo's other 2 that names something is G42.1's L2, the cutter's
    # orientation (a code: nc_references); its P2 is G70's count of passes, a quantity.
    assert [(left["line"], left["word"]) for left in report.left_alone] == [
        (line, word) for line, found, word, _ in equal if found in "NOTL"]
    assert report.left_alone[0] == {"line": tools[0][0], "word": tools[0][2], "parameter": "tool",
                                    "why": f"{tools[0][2]} names a tool"}
    assert report.bindings[0]["words"] == sum(1 for word in equal if word[1] not in "GMNOTL")


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_lines_read_in_two_processes_report_what_one_process_reports(conn, monkeypatch):
    params = bound_form("radius", "4.25", "I", CAM)
    monkeypatch.setattr(nc_halves, "TWO_PROCESSES_FROM", 10**9)
    alone = import_nc(conn, DATA / CAM, "nc_alone", params)
    monkeypatch.setattr(nc_halves, "TWO_PROCESSES_FROM", 100)
    forked = import_nc(conn, DATA / CAM, "nc_forked", params)
    assert (forked.bindings, forked.left_alone) == (alone.bindings, alone.left_alone)
    assert forked.left_alone[0]["line"] < len((DATA / CAM).read_text().splitlines()) / 2 < forked.left_alone[-1]["line"]


def test_two_parameters_binding_the_same_address_use_the_first_given(conn):
    params = {"first": {"value": 0.3, "addresses": ["R"]}, "second": {"value": 0.3, "addresses": ["R", "D"]}}
    report = import_nc(conn, DATA / DEMO, "nc_shared", params)
    equal = equal_words(DEMO, "0.3")
    assert report.ambiguous == {"0.3": ["first", "second"]}
    assert [(binding["parameter"], binding["at"]) for binding in report.bindings] == [
        ("first", {"R": sum(1 for word in equal if word[1] == "R")}),
        ("second", {"D": sum(1 for word in equal if word[1] == "D")})]


# --- the command ---------------------------------------------------------------------------


def rows_at(url, gear_class: str) -> dict[int, str]:
    with psycopg.connect(url) as connection:
        return stored_rows(connection, gear_class)


def test_the_command_lists_bindings_and_warns_once_per_word_left_alone(run, tmp_path):
    params = tmp_path / "p.json"
    params.write_text(json.dumps(bound_form("diameter", "0.3", "D", DEMO)))
    result = run("import-nc", DATA / DEMO, "--class", "nc_cli", "--params", params)
    assert result.exit_code == 0, result.output
    elsewhere = [word for word in equal_words(DEMO, "0.3") if word[1] != "D"]
    warnings = [line for line in result.stderr.splitlines() if "left as written" in line]
    assert len(warnings) == len(elsewhere)
    for (line, _, word, _), warning in zip(elsewhere, warnings):
        assert f"line {line}:" in warning and word in warning and "diameter" in warning
    assert any(line.strip().startswith("diameter → D: 1 word(s)") for line in result.stdout.splitlines())
    assert any(line.strip().startswith("feed → every address but G M N O T $") for line in result.stdout.splitlines())


def test_the_csv_addresses_column_binds_as_the_json_form(run, tmp_path):
    (tmp_path / "p.json").write_text(json.dumps({"diameter": {"value": 0.3, "addresses": ["D"]}, "feed": 400}))
    (tmp_path / "p.csv").write_text("name,value,addresses\ndiameter,0.3,D\nfeed,400,\n")
    (tmp_path / "semicolon.csv").write_text("name;value;addresses\ndiameter;0,3;D\nfeed;400;\n")
    reports = {}
    for name in ("p.json", "p.csv", "semicolon.csv"):
        result = run("import-nc", DATA / DEMO, "--class", "nc_" + name.replace(".", "_"), "--params",
                     tmp_path / name, "--json")
        assert result.exit_code == 0, result.output
        reports[name] = json.loads(result.stdout)
    assert reports["p.csv"]["left_alone"] == reports["p.json"]["left_alone"] == reports["semicolon.csv"]["left_alone"]
    assert reports["p.csv"]["left_alone"] and reports["p.csv"]["bindings"] == reports["p.json"]["bindings"]
    assert rows_at(run.url, "nc_p_csv") == rows_at(run.url, "nc_p_json") == rows_at(run.url, "nc_semicolon_csv")


@pytest.mark.parametrize("given, words_said", [
    ('{"feed": {"value": 400}}', "parameter 'feed'"),
    ('{"feed": {"value": 400, "addresses": "F"}}', "parameter 'feed'"),
    ('{"feed": {"value": 400, "addresses": []}}', "parameter 'feed'"),
    ('{"feed": {"value": 400, "addresses": ["F1"]}}', "parameter 'feed'"),
    ('{"feed": {"value": 400, "adresses": ["F"]}}', "parameter 'feed'"),
    ("name,value,addresses\nfeed,400,F1\n", "line 2, column addresses"),
])
def test_a_bad_bound_form_is_refused_in_one_line_and_nothing_is_stored(read_only_run, tmp_path, given, words_said):
    params = tmp_path / ("p.json" if given.startswith("{") else "p.csv")
    params.write_text(given)
    before = stored_at(read_only_run.url)
    result = read_only_run("import-nc", DATA / DEMO, "--class", "nc_refused", "--params", params)
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1 and words_said in message and str(params) in message
    assert stored_at(read_only_run.url) == before


@pytest.mark.parametrize("value", ['{"a": 1}', "[400]", "true", "null", '"F400"'])
def test_a_bound_parameter_whose_value_is_no_number_is_refused(read_only_run, tmp_path, value):
    """Only a number binds a word: `{"feed": {"value": true, "addresses": ["F"]}}` asks for F to
    be bound and binds nothing, F400 stays literal, no warning, exit 0; the user believes the
    feed is a parameter of the class."""
    params = tmp_path / "p.json"
    params.write_text(f'{{"feed": {{"value": {value}, "addresses": ["F"]}}}}')
    result = read_only_run("import-nc", DATA / DEMO, "--class", "nc_nonumber", "--params", params)
    assert one_line_error(result) and "feed" in result.stderr, result.output


def test_a_json_parameter_given_twice_is_refused_as_the_csv_one_is(read_only_run, tmp_path):
    """A CSV naming a parameter twice is refused; the JSON form silently keeps the last value
    ({"feed": 400, "feed": 3.0} binds 3.0 at I3.0 and leaves the feed F400 literal)."""
    params = tmp_path / "p.json"
    params.write_text('{"feed": 400, "feed": 3.0}')
    result = read_only_run("import-nc", DATA / DEMO, "--class", "nc_twice", "--params", params)
    assert one_line_error(result) and "feed" in result.stderr, result.output


def test_a_params_file_nested_too_deep_is_bad_input_not_a_bug(read_only_run, tmp_path):
    """A parameters file of 100,000 nested brackets (a generator gone wrong) is bad input:
    json.loads raises RecursionError, exit 2."""
    params = tmp_path / "deep.json"
    params.write_text('{"feed": ' + "[" * 100_000 + "]" * 100_000 + "}")
    result = read_only_run("import-nc", DEMO, "--class", "nc_deep", "--params", params)
    assert one_line_error(result) and str(params) in result.stderr, result.output


def class_job_dry_run(run, tmp_path, text: str):
    params = tmp_path / "params.json"
    params.write_text(text)
    return run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--draft", "--params", params,
               "--dry-run")


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_deeply_nested_parameters_file_is_bad_input_not_a_bug(run, tmp_path):
    """A parameters file that is not an object of values (here an array nested 100 000 deep) is
    refused in one line, exit 1, like any other file that is not {"name": value}."""
    import_emco(run, tmp_path)
    made = class_job_dry_run(run, tmp_path, "[" * 100_000 + "]" * 100_000)
    assert made.exit_code == 1, made.output
    assert made.stderr.startswith("error: ") and made.stderr.count("\n") == 1


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_addresses_the_class_does_not_bind_are_not_silently_ignored(run, tmp_path):
    """The class binds feed to F (import-nc --params). A file saying feed binds S asks for a
    different program than the one made: the engine makes F100 and keeps S600 without a word.
    It must refuse, naming the address the class binds."""
    import_emco(run, tmp_path)
    made = class_job_dry_run(run, tmp_path, json.dumps({"feed": {"value": 100, "addresses": ["S"]}}))
    assert made.exit_code == 1, made.output
    assert made.stderr.count("\n") == 1 and "F" in made.stderr
