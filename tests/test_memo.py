"""The memo (issue 12): a row whose inputs have the same values and origins as for an earlier job
takes its outcome from the template's memo. It must never change a line or a trace: every job is
compared with the same job evaluated by a template that remembers nothing."""
import json

import pytest

from engine.templates import decision_table
from engine.templates.decision_table import CompiledTemplate
from engine.templates.rows import Template, TemplateRow


def template_of(*rows):
    return CompiledTemplate(Template("memo", 1, tuple(TemplateRow(*row) for row in rows)))


def fresh_run(rows, params, module_params=None):
    """The same job on a template that remembers nothing."""
    return template_of(*rows).run(params, module_params)


ROWS = [(1, "main", 1, None, "y = x * 2", "f'{y}'", None),
        (2, "main", 1, None, None, "f'{x:>4}'", "flag"),
        (3, "cutmotion", 1, None, None, "f'{m}/{x}'", None)]

# Values that compare equal in Python but print differently, one after the other.
JOBS = [{"x": 1.0}, {"x": 1}, {"x": True}, {"x": 0.0}, {"x": -0.0}, {"x": float("inf")}, {"x": "inf"},
        {"x": "0x1.0000000000000p+0"}, {"x": 1.0}, {"x": 2}, {"x": 2.0}]


@pytest.mark.parametrize("flag", [True, False, 1, 0])
def test_a_remembered_outcome_is_the_outcome_a_fresh_evaluation_gives(flag):
    remembering = template_of(*ROWS)
    for index, params in enumerate(JOBS):
        params = {**params, "flag": flag}
        modules = {"cutmotion:1": {"m": index % 2 or 0.0}}
        remembered, fresh = remembering.run(params, modules), fresh_run(ROWS, params, modules)
        assert (remembered.lines, remembered.row_ids) == (fresh.lines, fresh.row_ids), params
        assert json.dumps(remembered.trace) == json.dumps(fresh.trace), params
    assert remembering.memo     # it did remember


@pytest.mark.parametrize("flag", [True, False])
def test_a_run_without_its_trace_gives_the_lines_a_traced_run_gives(flag):
    """The release impact runs its templates without the trace (issue 28): the same lines and row
    ids, from remembered outcomes and fresh ones alike, and an empty trace."""
    remembering = template_of(*ROWS)
    for index, params in enumerate(JOBS):
        params, modules = {**params, "flag": flag}, {"cutmotion:1": {"m": index % 2 or 0.0}}
        bare, fresh = remembering.run(params, modules, traced=False), fresh_run(ROWS, params, modules)
        assert (bare.lines, bare.row_ids) == (fresh.lines, fresh.row_ids), params
        assert bare.trace == {"inputs": {}, "rows": []}


def test_rows_whose_inputs_repeat_are_not_evaluated_again(monkeypatch):
    remembering, modules = template_of(*ROWS), {"cutmotion:1": {"m": 5}}
    first = remembering.run({"x": 3, "flag": True}, modules)
    evaluated = []
    original = remembering.evaluator.evaluate
    monkeypatch.setattr(remembering.evaluator, "evaluate", lambda *args: evaluated.append(1) or original(*args))
    again = remembering.run({"x": 3, "flag": True}, modules)
    assert again.lines == first.lines == ["6", "   3", "5/3"] and again.trace == first.trace
    assert evaluated == []


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_the_seeded_classes_give_the_same_programs_with_and_without_the_memo(conn, monkeypatch):
    from engine.hobbing.choices import Choices
    from engine.programs.instantiate import instantiate_gear

    choice_sets = [Choices(), Choices(cuts=2), Choices(coolant=False), Choices(shift_per_part=0.5)]
    from engine.nc.lineage import without_lineage

    def made(gear, choices):   # the template's lines: the lineage line names each program's own id
        program = instantiate_gear(conn, gear, choices=choices)
        return without_lineage(program.lines, program.row_ids)

    remembered = [made(gear, choices) for choices in choice_sets for gear in (42, 43, 44, 45, 46, 47, 50, 51, 53, 54)]
    monkeypatch.setattr(decision_table.CompiledTemplate, "remembered", lambda self, key: None)
    fresh = [made(gear, choices) for choices in choice_sets for gear in (42, 43, 44, 45, 46, 47, 50, 51, 53, 54)]
    assert remembered == fresh
