"""`engine import-dxf --profile-layer NAME` (issue 17): real CAD drawings keep the part outline
on a named layer (`outline`, `Sketch`, …), not on layer 0 as the seed-000 convention does.
The half-profile here is drawn with ezdxf; its expected bounds are the drawn coordinates."""
from __future__ import annotations

import json

import ezdxf
import pytest
from helpers.drawings import DXF
from helpers.drawn_parts import outline_drawing
from helpers.outcomes import job_count, one_line_refusal

from engine.drawings.drawing import read_drawing
from engine.drawings.read import DxfError


def test_the_profile_is_read_from_the_named_layer(tmp_path):
    path = outline_drawing(tmp_path / "shaft.dxf")
    chosen = read_drawing(path)   # layer 0 is empty: the one layer with a contour on the axis
    assert chosen.profile.bounds == pytest.approx((-40, 0, 0, 14))
    assert any("layer 0 is empty" in note and "'outline'" in note for note in chosen.notes)
    two = outline_drawing(tmp_path / "two.dxf", copy_on="Sketch")
    with pytest.raises(DxfError, match=r"layer 0 is empty and layers 'Sketch' and 'outline' .*--profile-layer"):
        read_drawing(two)
    profile = read_drawing(two, "outline").profile
    assert profile.closed_by_axis
    assert profile.bounds == pytest.approx((-40, 0, 0, 14))


def test_layer_names_ignore_case_as_in_cad(tmp_path):
    path = outline_drawing(tmp_path / "shaft.dxf", layer="Sketch")
    assert read_drawing(path, "SKETCH").profile.bounds == pytest.approx((-40, 0, 0, 14))


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_an_unknown_layer_is_refused_with_the_drawing_s_layers():
    with pytest.raises(DxfError) as caught:
        read_drawing(DXF / "qcad_screw_R2007.dxf", "outline")
    layers = [layer.dxf.name for layer in ezdxf.readfile(DXF / "qcad_screw_R2007.dxf").layers]
    message = str(caught.value)
    assert "'outline'" in message and "\n" not in message
    assert all(repr(name) in message for name in layers)


def test_import_dxf_makes_a_job_from_the_named_layer_and_its_program(run, tmp_path):
    path = outline_drawing(tmp_path / "shaft.dxf", copy_on="Sketch2")
    before = job_count(run.url)
    refused = one_line_refusal(run("import-dxf", path, "--rough-depth", "1", "--program-name", "SHAFT"))
    assert "'Sketch2' and 'outline'" in refused and "--profile-layer" in refused and job_count(run.url) == before
    unknown = one_line_refusal(run("import-dxf", path, "--profile-layer", "Sketch", "--rough-depth", "1"))
    assert "'Sketch'" in unknown and "'outline'" in unknown and "'Sketch2'" in unknown and job_count(run.url) == before
    made = run("import-dxf", path, "--profile-layer", "outline", "--rough-depth", "1",
               "--program-name", "SHAFT", "--json")
    assert made.exit_code == 0, made.output
    job_id = json.loads(made.stdout)["job_id"]
    assert job_count(run.url) == before + 1
    program = run("instantiate", "--job", job_id, "--json")   # gouge and finish checks run here too
    assert program.exit_code == 0, program.output
    assert json.loads(program.stdout)["lines"] > 10


def test_help_names_the_option_and_keeps_its_example(read_only_run):
    text = read_only_run("import-dxf", "--help").output
    assert "--profile-layer" in text
    assert any(line.strip().startswith("Example: engine import-dxf") for line in text.splitlines())


def test_refusals_about_the_profile_name_the_layer_it_was_looked_for_on(tmp_path):
    doc = ezdxf.new("R2010")
    doc.layers.add("outline")
    doc.modelspace().add_line((0, 5), (-10, -5), dxfattribs={"layer": "outline"})   # crosses the axis
    doc.saveas(tmp_path / "cross.dxf")
    with pytest.raises(DxfError, match=r"^layer outline has no closed profile") as caught:
        read_drawing(tmp_path / "cross.dxf", "outline")
    assert "layer 0" not in str(caught.value)
