"""`engine import-dxf`: turning jobs from lathe drawings (design notes §8)."""
from __future__ import annotations

import math

import click

from ..errors import EngineError
from ..machines.turning_cutting import (
    DEFAULT_TOOL_MATERIAL,
    DEFAULT_WORKPIECE_MATERIAL,
    TOOL_MATERIALS,
    WORKPIECE_MATERIALS,
)
from ..turning.defaults import DEFAULT_LATHE, PROFILE_DEFAULTS, STOCK_MARGIN
from .context import connection, emit_json, keyed, record_dict


class FiniteFloatRange(click.FloatRange):
    """click.FloatRange lets nan and inf through (no comparison fails for nan)."""

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return number


POSITIVE = FiniteFloatRange(min=0, min_open=True)


@click.command("import-dxf")
@click.argument("dxf_file", type=click.Path(dir_okay=False))
@click.option("--machine", default=DEFAULT_LATHE, show_default=True,
              help="Lathe record (lathe-iso or lathe-840d); its dialect picks the template class.")
@click.option("--rough-depth", type=POSITIVE,
              help=f"Profile-only drawings: radial depth per rough pass, mm "
                   f"[default: {PROFILE_DEFAULTS['rough_depth']:g}].")
@click.option("--allowance", type=FiniteFloatRange(min=0),
              help=f"Profile-only drawings: material left on the profile by roughing, mm "
                   f"[default: {PROFILE_DEFAULTS['allowance']:g}].")
@click.option("--tool", type=click.IntRange(min=1),
              help=f"Profile-only drawings: tool (and offset) number [default: {PROFILE_DEFAULTS['tool']}].")
@click.option("--speed", type=POSITIVE,
              help=f"Profile-only drawings: spindle speed, r/min [default: {PROFILE_DEFAULTS['speed']:g}].")
@click.option("--feed", type=POSITIVE,
              help=f"Profile-only drawings: feed, mm/min [default: {PROFILE_DEFAULTS['feed']:g}].")
@click.option("--stock-diameter", type=POSITIVE,
              help=f"Diameter of the blank, mm [default for profile-only drawings: the profile's largest "
                   f"diameter + {STOCK_MARGIN:g}, rounded up to whole mm].")
@click.option("--alternate", metavar="A,B",
              help="Machine ROUGH operations A and B (one tool) pass by pass alternately, e.g. 1,2.")
@click.option("--program-name", metavar="NAME",
              help="The program's name (letters, digits, _; two letters first; at most 24) "
                   "[default: the file name in upper case, - . and spaces as _; on an ISO lathe, "
                   "when that is no such name, DXF_O and the program number].")
@click.option("--profile-layer", metavar="NAME",
              help="Layer holding the part's profile (CAD drawings often use 'outline' or 'Sketch') "
                   "[default: 0; when layer 0 is empty, the one layer with one contour on the axis].")
@click.option("--material", type=click.Choice(WORKPIECE_MATERIALS),
              help=f"Workpiece material (ISO 513 group), for the cutting-data check "
                   f"[default: {DEFAULT_WORKPIECE_MATERIAL}]; stored as params.workpiece_material.")
@click.option("--tool-material", type=click.Choice(TOOL_MATERIALS),
              help=f"Tool material of every operation, for the cutting-data check "
                   f"[default: {DEFAULT_TOOL_MATERIAL}]; stored as module_params prep:n.tool_material.")
@click.option("--draft", is_flag=True,
              help="Check the job's program with the turning class's draft, not its released template.")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object: job_id, operations, repairs, notes, ...")
@click.pass_context
def import_dxf_command(ctx, dxf_file, machine, rough_depth, allowance, tool, speed, feed, stock_diameter,
                       alternate, program_name, profile_layer, material, tool_material, draft, as_json):
    """Make DXF_FILE a turning job: profile on layer 0 (or --profile-layer), operation n on layer n with its @-codes.

    A part drawn whole about a centre line (a side view) is turned as its upper half-profile;
    a half-profile about a vertical axis at drawing X 0 (OpenSCAD, FreeCAD revolve) is turned
    into the lathe's Z-X plane, its upper end the front (the report says so).

    A drawing with a profile only becomes a job when any of --rough-depth, --allowance,
    --tool, --speed, --feed, --stock-diameter is given: rough passes between blank and
    profile plus allowance, then a finish pass along the profile. Every number is stored
    as a job parameter (edit it in SQL, then `engine instantiate --job ID`). Nothing is
    stored if the drawing cannot become a job or its program would exceed the lathe.
    """
    from importers.dxf import import_dxf

    from ..turning.job_params import ProfileOptions

    options = ProfileOptions(rough_depth, allowance, tool, speed, feed, stock_diameter)
    with connection(ctx) as conn:
        report = import_dxf(conn, dxf_file, machine, options, parse_pair(alternate), program_name, draft,
                            profile_layer, (tool_material, material))
    if as_json:
        emit_json(keyed(record_dict(report)))
        return
    click.echo(f"job {report.job_id}")
    click.echo(f"  {report.drawing} → {report.gear_class} on {report.machine}, {report.program_lines} program lines",
               err=True)
    for op in report.operations:
        feed_text = f" F{op['feed']:g}" if op["feed"] is not None else ""
        click.echo(f"  operation {op['operation']} {op['kind']} from {op['source']}: T{op['tool']} "
                   f"S{op['spindle_rpm']:g}{feed_text}{' coolant' if op['coolant'] else ''}", err=True)
    for line in report.repairs:
        click.echo(f"  repaired: {line}", err=True)
    for line in report.notes:
        click.echo(f"  note: {line}", err=True)
    click.echo(f"  program: engine instantiate --job {report.job_id}", err=True)


def parse_pair(text: str | None) -> list[int] | None:
    if text is None:
        return None
    parts = [part.strip() for part in text.split(",")]
    if len(parts) != 2 or not all(part.isdecimal() for part in parts) or parts[0] == parts[1]:
        raise EngineError(f"--alternate {text!r}: give two different operation numbers A,B, e.g. 1,2")
    return [int(part) for part in parts]
