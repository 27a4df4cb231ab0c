"""Imported NC files come back byte for byte whatever their line ending (issue 17): the class
keeps LF or CRLF and whether the file ended with a newline; the rows hold the lines without
them, so a CRLF program shares its components with the LF one; a file mixing both is refused."""
from __future__ import annotations

import psycopg
import pytest
from helpers.nc_files import DATA, PARAMS, class_name, real_files, written_back
from helpers.outcomes import one_line_error

from engine.errors import EngineError
from engine.library.nc_import import import_nc
from engine.templates.store import load_template

TWO_FILES = ["sinumerik/cam_840dsl/CAM_TEST.MPF", "emco_from_dxf/testNegDXF.cnc"]


def variant(tmp_path, relative: str, crlf: bool, final_newline: bool):
    """A real file rewritten by hand: its lines with CRLF or LF, with or without a final newline."""
    lines = (DATA / relative).read_bytes().split(b"\n")[:-1]   # every real file ends with LF
    ending = b"\r\n" if crlf else b"\n"
    data = ending.join(lines) + (ending if final_newline else b"")
    path = tmp_path / (flat_name(relative) + ("_crlf" if crlf else "_lf") + ("_nl" if final_newline else ""))
    path.write_bytes(data)
    return path, data


def flat_name(relative: str) -> str:
    return relative.replace("/", "_").replace(".", "_")


@pytest.mark.parametrize("relative", list(PARAMS))
def test_every_real_file_is_written_back_byte_for_byte(real_library, real_conn, relative):
    real_files()
    real_library.imported(relative)   # import_nc, once per worker (ImportedLibrary)
    assert written_back(real_conn, class_name(relative), PARAMS[relative]) == (DATA / relative).read_bytes()


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
@pytest.mark.parametrize("relative", TWO_FILES)
@pytest.mark.parametrize("crlf, final_newline", [(False, False), (True, True), (True, False)])
def test_crlf_and_no_final_newline_are_written_back_byte_for_byte(conn, tmp_path, relative, crlf, final_newline):
    path, data = variant(tmp_path, relative, crlf, final_newline)
    assert data != (DATA / relative).read_bytes()
    import_nc(conn, path, "nc_variant", PARAMS[relative])
    assert written_back(conn, "nc_variant", PARAMS[relative]) == data


def components(conn, gear_class: str) -> set[int]:
    return {row[0] for row in conn.execute("SELECT component_id FROM class_template(%s)", (gear_class,))}


@pytest.mark.parametrize("relative", TWO_FILES)
def test_crlf_lines_share_components_with_the_lf_program(conn, tmp_path, relative):
    import_nc(conn, DATA / relative, "nc_lf", PARAMS[relative])
    path, _ = variant(tmp_path, relative, crlf=True, final_newline=True)
    import_nc(conn, path, "nc_crlf", PARAMS[relative])
    assert components(conn, "nc_crlf") == components(conn, "nc_lf")
    stored = [row.o for row in load_template(conn, "nc_crlf").rows]
    assert not any("\\r" in o or "\r" in o for o in stored)


def test_m17_of_a_crlf_file_is_the_m17_of_an_lf_file(conn, tmp_path):
    (tmp_path / "lf.SPF").write_bytes(b"G1 X10\nM17\n")
    (tmp_path / "crlf.SPF").write_bytes(b"G0 Z5\r\nM17\r\n")
    import_nc(conn, tmp_path / "lf.SPF", "nc_lf")
    import_nc(conn, tmp_path / "crlf.SPF", "nc_crlf")
    assert len(components(conn, "nc_lf") & components(conn, "nc_crlf")) == 1
    assert written_back(conn, "nc_crlf", {}) == b"G0 Z5\r\nM17\r\n"


@pytest.mark.parametrize("data, line", [(b"G0 Z5\r\nG1 X10\nM17\r\n", 2), (b"G0 Z5\r\nG1 X10\r\nM17\n", 3)])
def test_a_file_mixing_line_endings_is_refused_naming_the_first_other_line(conn, tmp_path, data, line):
    path = tmp_path / "mixed.SPF"
    path.write_bytes(data)
    with pytest.raises(EngineError, match=rf"mixes line endings: line 1 ends with CRLF, line {line} ") as refused:
        import_nc(conn, path, "nc_mixed")
    assert "\n" not in str(refused.value)
    assert conn.execute("SELECT 1 FROM gear_class WHERE name = 'nc_mixed'").fetchone() is None


def test_an_lf_file_whose_first_line_has_no_cr_but_a_later_one_has_is_refused(conn, tmp_path):
    path = tmp_path / "mixed.SPF"
    path.write_bytes(b"G0 Z5\nG1 X10\r\nM17\n")
    with pytest.raises(EngineError, match=r"mixes line endings: line 1 ends with LF, line 2 .* with CRLF"):
        import_nc(conn, path, "nc_mixed")


@pytest.mark.parametrize("breaking", ["\r", "\f", "\u0085", "\u2028"], ids=["CR", "FF", "NEL", "LS"])
def test_an_nc_file_with_a_line_break_inside_a_line_is_refused_at_import(read_only_run, tmp_path, breaking):
    """`G1 X10<CR>G0 X0` in an LF file is one line to the import (one row, its module decided by
    G0, one text to the refactor) and two blocks to a control or editor that breaks lines at a
    bare CR; the database refuses such a line in every program (migration 0009), so the class
    the import stores and calls a draft can never give a program. It should be refused naming
    the line, as a control character is, with nothing stored."""
    nc = tmp_path / "broken.nc"
    nc.write_bytes(f"G1 X10{breaking}G0 X0\nM30\n".encode())
    result = read_only_run("import-nc", nc, "--class", "nc_broken")
    assert one_line_error(result) and "line 1" in result.stderr, result.output
    with psycopg.connect(read_only_run.url) as conn:
        assert conn.execute("SELECT count(*) FROM gear_class WHERE name = 'nc_broken'").fetchone()[0] == 0
