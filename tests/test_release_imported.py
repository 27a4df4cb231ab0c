"""Imported programs become templates runners use (issue 17): `engine template release` lets the
class of a real NC program through its gate. Real programs repeat plain lines: the engine's own
lathe program rapids back to the same point after every cut, the LinuxCNC programs of tests/data/nc
repeat lines far apart and have blank lines in pairs. The gate's duplicate-row rule takes those as
the program's content; it still refuses a row an editor pasted right after its twin, and a repeated
row that computes.

The verified chain is the one of test_instantiate_class: a real lathe drawing becomes a turning
job (import-dxf), its program is written to a file on the ISO lathe and imported (import-nc) as a
class, which is released and then instantiated without --draft, read by the lathe's verifier."""
from __future__ import annotations

import json

import psycopg
import pytest
from helpers.class_jobs import PAWN, import_emco, ok, refused, stored_program
from helpers.nc_files import DATA as NC
from helpers.roles import as_role

from engine.errors import EngineError
from engine.library.nc_import import import_nc
from engine.programs.class_jobs import instantiate_class
from engine.release.gate import release

# LinuxCNC's expected interpreter output (interp_tests/*.expected) is a record of moves, not a program
REAL_PROGRAMS = sorted(path for path in NC.rglob("*") if path.is_file() and path.name != "PROVENANCE.tsv"
                       and path.suffix != ".expected")
TWINNED = NC / "liblathe" / "profile.gcode"   # LibLathe's path repeats each approach rapid
PAWN_PARAMS = {"spindle": 1000, "feed": 50.0}
PASTE = ("INSERT INTO template_view (gear_class, id, t, n, o) "
         "SELECT gear_class, id + 1, t, n, o FROM template_view WHERE gear_class = %s AND id = %s")
REPEATED_PLAIN_ROWS = """
SELECT min(id), max(id) FROM template_view WHERE gear_class = %s AND o <> '""' AND p_emit IS NULL
GROUP BY t, n, o HAVING count(*) > 1 AND max(id) - min(id) > 10 ORDER BY min(id) LIMIT 1"""
EDIT_CONDITION = "UPDATE template_view SET p_emit = %s WHERE gear_class = %s AND id = ANY(%s)"


def program_lines(path) -> list[str]:
    return path.read_text().splitlines()


def repeats(lines: list[str]) -> tuple[list[str], list[str], list[int]]:
    """(non-blank lines repeated further on, non-blank lines right after their twin, blank lines right
    after a blank line), each by its line number."""
    after_twin = [index for index in range(1, len(lines)) if lines[index] == lines[index - 1]]
    twins, seen, further_on = set(after_twin), set(), []
    for index, line in enumerate(lines):   # one pass: `line in lines[:index]` took 8 s on TOKARKA.NC's 28,904 lines
        if line.strip() and index not in twins and line in seen:
            further_on.append(index)
        seen.add(line)
    return (further_on, [index for index in after_twin if lines[index].strip()],
            [index for index in after_twin if not lines[index].strip()])


def refusal(conn, gear_class: str) -> EngineError:
    with pytest.raises(EngineError) as refused_release:
        release(conn, gear_class, dry_run=True, without_golden_tests=True)
    return refused_release.value


# --- the engine's own program, end to end, verified -------------------------------------------------------

@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_engines_lathe_program_imported_is_released_and_runners_make_verified_jobs_of_it(run, tmp_path):
    source, lines = import_emco(run, tmp_path)
    further_on, after_twin, _ = repeats(lines)
    assert len(further_on) >= 2 and after_twin == []   # the retract comes back after each cut, never doubled
    unreleased = refused(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso"))
    assert "no released template version" in unreleased and "template release" in unreleased
    released = ok(run("template", "release", "--class", "emco_neg", "--yes", "--without-golden-tests"))
    assert "released class emco_neg v1" in released.stdout
    made = json.loads(ok(run("instantiate", "--class", "emco_neg", "--machine", "lathe-iso", "--json")).stdout)
    template_lines, lineage, unverified = stored_program(run.url, made["program_id"])
    assert template_lines == lines and unverified is False and made["template_version"] == 1
    assert lineage[0].startswith(f"(PROGRAM {made['program_id']} TEMPLATE emco_neg v1 ") and "DRAFT" not in lineage[0]
    with psycopg.connect(run.url) as conn, as_role(conn, "engine_runner"):
        job = instantiate_class(conn, "emco_neg", {"speed": 800}, machine="lathe-iso")
    assert job.program.unverified is False and job.program.template_version == 1
    assert [line for line in job.program.lines if "S800" in line] == [
        line.replace("S600", "S800") for line in lines if "S600" in line] != []


# --- every real program of tests/data/nc ----------------------------------------------------------------

@pytest.mark.slow   # imports and releases every real program (about 25 s)
def test_every_real_nc_program_imports_and_is_released(run):
    found = {path: repeats(program_lines(path)) for path in REAL_PROGRAMS}
    assert any(found[path][0] for path in REAL_PROGRAMS)        # lines repeated further on
    # one says a line twice in a row: its release is refused (tests/test_real_lathe_corpus.py)
    assert [path for path in REAL_PROGRAMS if found[path][1]] == [TWINNED]
    assert any(found[path][2] for path in REAL_PROGRAMS)        # blank lines in pairs
    for number, path in enumerate(path for path in REAL_PROGRAMS if path != TWINNED):
        gear_class = f"real_{number}"
        ok(run("import-nc", path, "--class", gear_class))
        released = run("template", "release", "--class", gear_class, "--yes", "--without-golden-tests")
        assert released.exit_code == 0 and f"released class {gear_class} v1" in released.stdout, (path, released.output)


# --- what the rule still refuses ------------------------------------------------------------------------

def test_a_row_an_editor_pastes_right_after_its_twin_is_refused(conn):
    import_nc(conn, PAWN, "pawn", PAWN_PARAMS)
    assert release(conn, "pawn", dry_run=True, without_golden_tests=True).checks["analysis"] == "no finding"
    twin = conn.execute("SELECT min(id) FROM template_view WHERE gear_class = 'pawn' AND o <> '\"\"'").fetchone()[0]
    with as_role(conn, "engine_editor"):
        assert conn.execute(PASTE, ("pawn", twin)).rowcount == 1
    error = refusal(conn, "pawn")
    assert error.problems == [f"class pawn row {twin + 1} column o: repeats row {twin} exactly (t, n, p_calc, s, o, "
                              "p_emit) right after it: a row pasted twice (duplicate-row)"]


def test_a_repeated_row_that_computes_is_refused_where_the_plain_line_was_content(conn):
    import_nc(conn, PAWN, "pawn", PAWN_PARAMS)
    first, again = conn.execute(REPEATED_PLAIN_ROWS, ("pawn",)).fetchone()
    assert release(conn, "pawn", dry_run=True, without_golden_tests=True).checks["analysis"] == "no finding"
    with as_role(conn, "engine_editor"):
        assert conn.execute(EDIT_CONDITION, ("feed > 0", "pawn", [first, again])).rowcount == 2
    error = refusal(conn, "pawn")
    assert len(error.problems) == 1 and f"class pawn row {again} column o: repeats row {first}" in error.problems[0]
    assert "dead" in error.problems[0] and "(duplicate-row)" in error.problems[0]
