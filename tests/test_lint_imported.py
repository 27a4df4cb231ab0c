"""Lint of classes imported from proven NC programs (engine import-nc): they have no hobbing
model, so their parameter names are checked against the parameters they were imported with
(gear_class.import_params)."""
from __future__ import annotations

import json

import pytest
from helpers.nc_files import DATA, PARAMS, class_name, real_files, write
from msgspec.structs import replace

from engine.errors import EngineError
from engine.library.nc_import import import_nc
from engine.templates.checks import LintProblem
from engine.templates.lint import lint_class
from engine.templates.rows import TemplateRow
from engine.templates.store import ensure_class, load_template, replace_template

CAM = "sinumerik/cam_840dsl/CAM_TEST.MPF"


def import_params(conn, gear_class: str):
    return conn.execute("SELECT import_params FROM gear_class WHERE name = %s", (gear_class,)).fetchone()[0]


def own_rows(conn, gear_class: str) -> list[TemplateRow]:
    return list(load_template(conn, gear_class).rows)


@pytest.mark.parametrize("relative", [relative for relative, params in PARAMS.items() if params])
def test_an_imported_real_program_lints_clean(real_library, real_conn, relative):
    real_files()
    real_library.imported(relative)   # import_nc, once per worker (ImportedLibrary)
    assert lint_class(real_conn, class_name(relative)) == []


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_lint_command_passes_after_import_nc(run, tmp_path):
    real_files()
    params = tmp_path / "params.json"
    params.write_text(json.dumps(PARAMS[CAM]))
    imported = run("import-nc", DATA / CAM, "--class", "nc_cam", "--params", params)
    assert imported.exit_code == 0, imported.output
    result = run("lint", "--json")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout) == {"errors": []}


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_changed_row_naming_an_unknown_parameter_is_the_one_problem(conn):
    real_files()
    import_nc(conn, DATA / CAM, "nc_cam", PARAMS[CAM])
    rows = own_rows(conn, "nc_cam")
    changed = rows[5]
    rows[5] = replace(changed, o='f"G1 X{nonexistent}"')
    replace_template(conn, "nc_cam", rows)
    problems = lint_class(conn, "nc_cam")
    assert problems == [LintProblem("nc_cam", changed.id, "o", "unknown parameter 'nonexistent'")]
    assert str(problems[0]) == f"class nc_cam row {changed.id} column o: unknown parameter 'nonexistent'"


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_names_computed_by_earlier_rows_are_known(conn):
    real_files()
    import_nc(conn, DATA / CAM, "nc_cam", PARAMS[CAM])
    rows = own_rows(conn, "nc_cam")
    compute, use = "slow_feed = feed / 2", 'f"G1 F{slow_feed:.1f}"'
    computed_first = [replace(rows[5], s=compute, o=None), replace(rows[6], o=use)]
    replace_template(conn, "nc_cam", rows[:5] + computed_first + rows[7:])
    assert lint_class(conn, "nc_cam") == []
    used_first = [replace(rows[5], o=use), replace(rows[6], s=compute, o=None)]
    replace_template(conn, "nc_cam", rows[:5] + used_first + rows[7:])
    assert lint_class(conn, "nc_cam") == [
        LintProblem("nc_cam", rows[5].id, "o", "unknown parameter 'slow_feed'")]


def test_a_class_with_neither_model_nor_import_params_says_what_to_do(conn):
    ensure_class(conn, "hand_made")
    replace_template(conn, "hand_made", [TemplateRow(10, "main", 1, None, None, 'f"G1 X{x}"', None)])
    problems = lint_class(conn, "hand_made")
    assert len(problems) == 1
    problem = problems[0]
    assert (problem.gear_class, problem.row_id, problem.column) == ("hand_made", None, "model")
    assert "no hobbing model" in problem.message
    assert "import-nc" in problem.message and "--params" in problem.message


def test_import_params_hold_the_given_params_and_are_replaced_on_reimport(conn, tmp_path):
    path = write(tmp_path, "G1 X5 F250.\n")
    import_nc(conn, path, "nc_params", {"x": 5, "feed": 250, "label": "first"})
    assert import_params(conn, "nc_params") == {"x": 5, "feed": 250, "label": "first"}
    import_nc(conn, path, "nc_params", {"x_start": 5.0})
    assert import_params(conn, "nc_params") == {"x_start": 5.0}
    import_nc(conn, path, "nc_params")
    assert import_params(conn, "nc_params") == {}


def test_lint_follows_the_params_of_the_last_import(conn, tmp_path):
    path = write(tmp_path, "G1 X5\n")
    import_nc(conn, path, "nc_params", {"x": 5})
    rows = own_rows(conn, "nc_params")
    import_nc(conn, path, "nc_params", {})
    replace_template(conn, "nc_params", rows)   # the rows of the first import, naming x
    assert lint_class(conn, "nc_params") == [LintProblem("nc_params", 10, "o", "unknown parameter 'x'")]


def test_a_failed_reimport_keeps_rows_and_import_params(conn, tmp_path):
    import_nc(conn, write(tmp_path, "G1 X5\n"), "nc_params", {"x": 5})
    before = own_rows(conn, "nc_params")
    with pytest.raises(EngineError, match="NaN"):
        import_nc(conn, write(tmp_path, "G1 X7\n", "other.nc"), "nc_params", {"x": 7, "bad": float("nan")})
    assert own_rows(conn, "nc_params") == before
    assert import_params(conn, "nc_params") == {"x": 5}


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_an_import_under_a_parent_with_a_model_is_checked_against_its_own_parameters(conn):
    real_files()
    import_nc(conn, DATA / CAM, "nc_cam_cylindrical", PARAMS[CAM], parent="cylindrical")
    assert lint_class(conn, "nc_cam_cylindrical") == []
