"""nc_path: a template row prints a whole tool path, one NC block per move, in the formats
the row gives (the dialect lives in the row); each block is a line of the result table with
the row's id; formats cannot reach into objects."""
from __future__ import annotations

import pytest

from engine.templates.decision_table import CompiledTemplate, TemplateError
from engine.templates.rows import Template, TemplateRow
from engine.turning.moves import Move

ISO = ('nc_path(moves, "G00 X{x:.3f} Z{z:.3f}", "G01 X{x:.3f} Z{z:.3f}", "G02 X{x:.3f} Z{z:.3f} R{r:.3f}", '
       '"G03 X{x:.3f} Z{z:.3f} R{r:.3f}", "G32 X{x:.3f} Z{z:.3f} F{pitch:.3f}")')
SINUMERIK = ('nc_path(moves, "G0 X{x:.3f} Z{z:.3f}", "G1 X{x:.3f} Z{z:.3f}", '
             '"G2 X{x:.3f} Z{z:.3f} I={i:.3f} K={k:.3f}", '
             '"G3 X{x:.3f} Z{z:.3f} CR={r:.3f}", "G33 Z{z:.3f} K{pitch:.3f}")')
MOVES = [Move("rapid", 2.0, 40.0), Move("feed", 0.0, 30.0), Move("ccw", -5.0, 40.0, radius=5.0, i=0.0, k=-5.0),
         Move("cw", -10.0, 30.0, radius=5.0, i=-5.0, k=0.0), Move("thread", -30.0, 29.0, pitch=1.5)]


def run(o: str, params: dict):
    rows = (TemplateRow(10, "main", 1, None, None, '"%"', None),
            TemplateRow(20, "cutmotion", 1, None, None, o, None),
            TemplateRow(30, "main", 1, None, None, '"M30"', None))
    return CompiledTemplate(Template("paths", 1, rows)).run(params)


def test_each_move_is_a_line_of_the_row_in_the_row_s_format():
    result = run(ISO, {"moves": MOVES})
    assert result.lines == ["%", "G00 X40.000 Z2.000", "G01 X30.000 Z0.000", "G03 X40.000 Z-5.000 R5.000",
                            "G02 X30.000 Z-10.000 R5.000", "G32 X29.000 Z-30.000 F1.500", "M30"]
    assert result.row_ids == [10, 20, 20, 20, 20, 20, 30]


def test_another_dialect_is_another_row_not_other_code():
    result = run(SINUMERIK, {"moves": MOVES})
    assert result.lines[3:6] == ["G3 X40.000 Z-5.000 CR=5.000", "G2 X30.000 Z-10.000 I=-5.000 K=0.000",
                                 "G33 Z-30.000 K1.500"]


def test_an_empty_path_prints_nothing_and_negative_zero_prints_as_zero():
    assert run(ISO, {"moves": []}).lines == ["%", "M30"]
    assert run(ISO, {"moves": [Move("feed", -1e-12, -0.0)]}).lines[1] == "G01 X0.000 Z0.000"


@pytest.mark.parametrize("rapid, words", [
    ('"{x.__class__}"', "may use only"),
    ('"{x[0]}"', "may use only"),
    ('"{x!r}"', "may use only"),
    ('"{feed}"', "may use only"),
    ('"{x:{z}}"', "may use only"),
    ('"{x:999.3f}"', "above"),
    ("5", "must be text"),
])
def test_formats_that_reach_further_than_the_fields_are_refused(rapid, words):
    o = f'nc_path(moves, {rapid}, "G1", "G2", "G3", "G32")'
    with pytest.raises(TemplateError, match=words) as refused:
        run(o, {"moves": MOVES})
    assert "row 20 column o" in str(refused.value)


def test_a_field_the_move_does_not_have_is_named():
    o = 'nc_path(moves, "G0 X{x:.3f} R{r:.3f}", "G1", "G2", "G3", "G32")'
    with pytest.raises(TemplateError, match="a rapid move has no r"):
        run(o, {"moves": MOVES})
