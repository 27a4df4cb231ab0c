"""The decision table of design notes §4, step by step, on templates stored in PostgreSQL."""
import pytest
from helpers.releases import release_draft
from msgspec.structs import astuple

from engine.errors import EngineError
from engine.hobbing.choices import Choices
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode
from engine.templates.decision_table import CompiledTemplate, TemplateError
from engine.templates.rows import TemplateRow
from engine.templates.store import ensure_class, load_template, replace_template


def make_template(conn, name, rows):
    """Store rows (id, t, n, p_calc, s, o, p_emit) as class `name` and load them back."""
    ensure_class(conn, name, "gear")
    replace_template(conn, name, [TemplateRow(*row) for row in rows])
    return CompiledTemplate(load_template(conn, name))


def test_rows_emit_in_id_order_not_insertion_order(conn):
    template = make_template(conn, "t_order", [
        (30, "main", 1, None, None, '"third"', None),
        (10, "main", 1, None, None, '"first"', None),
        (20, "main", 1, None, None, '"second"', None),
    ])
    assert template.run({}).lines == ["first", "second", "third"]


def test_compute_condition_false_skips_the_whole_row(conn):
    template = make_template(conn, "t_pcalc", [
        (1, "main", 1, None, "x = 1", None, None),
        (2, "main", 1, "flag", "x = 2", 'f"X{x}"', None),
    ])
    assert template.run({"flag": True}).lines == ["X2"]
    assert template.run({"flag": False}).lines == []      # not computed, and not emitted either


def test_output_condition_false_emits_nothing_but_keeps_the_computation(conn):
    template = make_template(conn, "t_pemit", [
        (1, "main", 1, None, "x = 5", '"hidden"', "show"),
        (2, "main", 1, None, None, 'f"X{x}"', None),
    ])
    assert template.run({"show": False}).lines == ["X5"]
    result = template.run({"show": True})
    assert result.lines == ["hidden", "X5"] and result.row_ids == [1, 2]


def test_intermediate_variables_carry_across_rows_and_modules(conn):
    template = make_template(conn, "t_carry", [
        (1, "main", 1, None, "a = 2; b = a * 10", None, None),
        (2, "sync", 1, None, "c = b + 1", None, None),
        (3, "cutmotion", 2, None, None, 'f"{a} {b} {c}"', None),
    ])
    assert template.run({}).lines == ["2 20 21"]


def test_module_parameters_are_scoped_to_their_module(conn):
    template = make_template(conn, "t_scope", [
        (1, "cutmotion", 1, None, None, 'f"X{cut_x}"', None),
        (2, "cutmotion", 2, None, None, 'f"X{cut_x}"', None),
        (3, "main", 2, None, None, 'f"X{cut_x}"', None),
    ])
    lines = template.run({"cut_x": 0}, {"cutmotion:1": {"cut_x": 52}, "cutmotion:2": {"cut_x": 51}}).lines
    assert lines == ["X52", "X51", "X0"]   # the job-wide value where no module value applies


def test_sql_style_conditions_work_in_p_emit(conn):
    template = make_template(conn, "t_sql", [
        (1, "shift", 1, None, None, '"G0 Y5"', "shift_on = TRUE AND shift_y <> 0"),
    ])
    assert template.run({"shift_on": True, "shift_y": 5}).lines == ["G0 Y5"]
    assert template.run({"shift_on": True, "shift_y": 0}).lines == []


def test_an_error_names_class_row_column_and_expression(conn):
    template = make_template(conn, "t_error", [
        (1, "main", 1, None, None, '"ok"', None),
        (7, "main", 1, None, None, 'f"X{missing_param:.3f}"', None),
    ])
    with pytest.raises(TemplateError) as caught:
        template.run({})
    message = str(caught.value)
    assert "t_error" in message and "row 7" in message and "column o" in message
    assert "missing_param" in message and 'f"X{missing_param:.3f}"' in message


def test_output_must_be_text_not_a_bare_number(conn):
    template = make_template(conn, "t_number", [(1, "main", 1, None, None, "x * 2", None)])
    with pytest.raises(TemplateError, match="not text"):
        template.run({"x": 25.7})


@pytest.mark.parametrize("row, problem", [
    ((1, "mian", 1, None, None, '"x"', None), "unknown module type"),
    ((1, "main", 1, None, None, None, None), "neither o nor s"),
    ((1, "main", 1, None, None, "open('/etc/passwd')", None), "open"),
    ((1, "main", 1, None, "while True: pass", None, None), "only assignments"),
    ((1, "main", 1, None, None, 'f"X{x:.3f"', None), "does not parse|not a Python"),
])
def test_bad_rows_are_refused_when_stored(conn, row, problem):
    ensure_class(conn, "t_bad", "gear")
    with pytest.raises(EngineError, match=problem):
        replace_template(conn, "t_bad", [TemplateRow(*row)])
    assert conn.execute("SELECT count(*) FROM assembly WHERE gear_class = 't_bad'").fetchone()[0] == 0


def count_rows(conn):
    return conn.execute("SELECT (SELECT count(*) FROM job), (SELECT count(*) FROM program)").fetchone()


def test_a_failing_row_stores_nothing_of_the_instantiation(conn):
    rows = [astuple(r) for r in load_template(conn, "spur").rows]
    broken = rows[:-1] + [(rows[-1][0], "main", 2, None, None, "f'M30 {1 / (z2 - z2)}'", None)]
    replace_template(conn, "spur", [TemplateRow(*row) for row in broken])
    before = count_rows(conn)
    with pytest.raises(TemplateError, match="ZeroDivisionError"):
        instantiate_gear(conn, 42, mode=RunMode(draft=True))   # the editor tries the draft
    assert count_rows(conn) == before


def test_a_template_version_is_recorded_with_each_program(conn):
    first = instantiate_gear(conn, 42)
    rows = list(load_template(conn, "spur").rows)
    rows.insert(2, TemplateRow(250, "main", 1, None, None, '"; EDITED"', None))   # after the header lines
    replace_template(conn, "spur", rows)
    release_draft(conn, "spur")
    second = instantiate_gear(conn, 42)
    assert second.template_version == first.template_version + 1
    assert second.template_hash != first.template_hash
    assert "; EDITED" in second.lines and "; EDITED" not in first.lines
    stored = conn.execute("SELECT template_version, template_hash FROM program WHERE id = %s",
                          (second.program_id,)).fetchone()
    assert stored == (second.template_version, second.template_hash)


def test_stored_job_reinstantiates_with_parameters_edited_in_sql(conn):
    from engine.programs.remake import instantiate_job

    program = instantiate_gear(conn, 42, choices=Choices(coolant=True))
    conn.execute("UPDATE job SET params = params || '{\"coolant\": false}' WHERE id = %s", (program.job_id,))
    again = instantiate_job(conn, program.job_id)
    assert "M8" in program.lines and "M8" not in again.lines and "M9" not in again.lines
    assert again.job_id == program.job_id


def test_result_table_view_lists_lines_with_their_template_rows(conn):
    program = instantiate_gear(conn, 42)
    rows = conn.execute("SELECT line_no, template_row_id, text FROM result_line WHERE program_id = %s "
                        "ORDER BY line_no", (program.program_id,)).fetchall()
    assert [text for _, _, text in rows] == program.lines
    assert rows[0][:2] == (1, 100)


def test_the_cpu_budget_stops_a_runaway_instantiation(conn):
    rows = [(i, "main", 1, None, "x = sqrt(2) * i", 'f"{x:.3f}"', None) for i in range(1, 200)]
    template = make_template(conn, "t_budget", rows)
    assert len(template.run({"i": 1}).lines) == 199
    with pytest.raises(TemplateError, match="exceeded"):
        template.run({"i": 1}, deadline_seconds=0.0)
