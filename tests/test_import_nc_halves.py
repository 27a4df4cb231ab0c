"""import-nc of a long program reads half of its lines in a forked process and proves its rows in
a thread while they are written (issue 13, item 9). Neither may change what is stored or what is
refused: the class is the one a single process makes, byte for byte, and a bad line in either
half, or a row that would not give its line back, stores nothing."""
import re
import sys
from pathlib import Path

import pytest

from engine.errors import EngineError
from engine.library import nc_halves, nc_verify
from engine.library.nc_import import import_nc
from engine.templates.store import load_template
from engine.templates.template_csv import export_csv

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
from import_nc import HOB_PARAMS as PARAMS  # noqa: E402   the benchmark's generated 840D program
from import_nc import hob_program as program  # noqa: E402
from import_nc import lathe_program  # noqa: E402   the benchmark's generated lathe program (issue 27)


def stored(conn):
    return conn.execute("SELECT (SELECT count(*) FROM assembly), (SELECT count(*) FROM component), "
                        "(SELECT count(*) FROM gear_class)").fetchone()


@pytest.fixture
def long_program(tmp_path) -> Path:
    path = tmp_path / "HOB.MPF"
    path.write_text("\n".join(program(3_000)) + "\n")
    return path


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_program_read_in_two_processes_is_stored_as_one_process_stores_it(conn, long_program, monkeypatch):
    monkeypatch.setattr(nc_halves, "TWO_PROCESSES_FROM", 10**9)
    alone = import_nc(conn, long_program, "nc_alone", PARAMS)
    monkeypatch.setattr(nc_halves, "TWO_PROCESSES_FROM", 100)
    forked = import_nc(conn, long_program, "nc_forked", PARAMS)
    assert export_csv(load_template(conn, "nc_forked")) == export_csv(load_template(conn, "nc_alone"))
    assert (forked.rows, forked.parameterised, forked.modules, forked.ambiguous) == \
        (alone.rows, alone.parameterised, alone.modules, alone.ambiguous)
    assert forked.parameterised > 0 and forked.rows == 3_000


@pytest.mark.parametrize("line", [2, 2_900])   # a bad line in the first half, and in the forked half
def test_a_bad_line_in_either_half_is_named_and_nothing_is_stored(conn, long_program, monkeypatch, line):
    monkeypatch.setattr(nc_halves, "TWO_PROCESSES_FROM", 100)
    lines = long_program.read_text().splitlines()
    lines[line - 1] = "X" * 5_000
    long_program.write_text("\n".join(lines) + "\n")
    before = stored(conn)
    with pytest.raises(EngineError, match=f"line {line}: 5000 characters"):
        import_nc(conn, long_program, "nc_bad", PARAMS)
    assert stored(conn) == before


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_rows_that_do_not_give_the_file_back_are_not_stored(conn, long_program, monkeypatch):
    """The proof compares what the rows give with the file: a wrong line makes it refuse."""
    original = nc_verify.CompiledTemplate.run

    def one_line_wrong(self, *args, **kwargs):
        result = original(self, *args, **kwargs)
        result.lines[1500] += " "
        return result

    monkeypatch.setattr(nc_verify.CompiledTemplate, "run", one_line_wrong)
    before = stored(conn)
    with pytest.raises(EngineError, match="line 1501: the imported template gives"):
        import_nc(conn, long_program, "nc_wrong", PARAMS)
    assert stored(conn) == before


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_line_repeated_through_the_program_is_reported_at_every_line_holding_it(conn, tmp_path, monkeypatch):
    """Each distinct text is read once (issue 27); the report still names every line: the roughing
    cycle `G71 U1.5 R0.5` of each operation binds its depth of cut at U and leaves R0.5 (the
    retract, equal to the finishing allowance parameter that binds only W) alone, line by line."""
    path = tmp_path / "SHAFTS.NC"
    lines = lathe_program(3_000)
    path.write_text("\n".join(lines) + "\n")
    cycle = [number for number, line in enumerate(lines, start=1) if line == "G71 U1.5 R0.5"]
    speed = [number for number, line in enumerate(lines, start=1) if re.search(r"\bS200\b", line)]
    assert len(cycle) > 50 and len(speed) > 100   # operations of about 30 lines, each twice G96
    params = {"depth": {"value": 1.5, "addresses": ["U"]}, "allowance": {"value": 0.5, "addresses": ["W"]},
              "surface_speed": 200}
    for reads_in_two in (False, True):
        monkeypatch.setattr(nc_halves, "TWO_PROCESSES_FROM", 100 if reads_in_two else 10**9)
        report = import_nc(conn, path, f"nc_repeated_{int(reads_in_two)}", params)
        by_name = {binding["parameter"]: binding for binding in report.bindings}
        assert by_name["depth"]["lines"] == {"U": cycle}
        assert by_name["surface_speed"]["lines"] == {"S": speed}
        assert [(left["line"], left["word"]) for left in report.left_alone if left["parameter"] == "allowance"] == [
            (number, "R0.5") for number in cycle]
        assert report.parameterised == len(cycle) + len(speed)
