"""import-nc of a long program reads half of its lines in a forked process and proves its rows in
a thread while they are written (issue 13, item 9). Neither may change what is stored or what is
refused: the class is the one a single process makes, byte for byte, and a bad line in either
half, or a row that would not give its line back, stores nothing."""
import sys
from pathlib import Path

import pytest

from engine.errors import EngineError
from engine.library import nc_halves, nc_verify
from engine.library.nc_import import import_nc
from engine.templates.rows import export_csv
from engine.templates.store import load_template

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
from import_nc import HOB_PARAMS as PARAMS  # noqa: E402   the benchmark's generated 840D program
from import_nc import hob_program as program  # noqa: E402


def stored(conn):
    return conn.execute("SELECT (SELECT count(*) FROM assembly), (SELECT count(*) FROM component), "
                        "(SELECT count(*) FROM gear_class)").fetchone()


@pytest.fixture
def long_program(tmp_path) -> Path:
    path = tmp_path / "HOB.MPF"
    path.write_text("\n".join(program(3_000)) + "\n")
    return path


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
