"""`engine simulate --program ID`: follow a stored hobbing program against its gear, hob and
machine, or a stored lathe program against its job's drawing and blank, and say what it proves
(engine.simulation)."""
from __future__ import annotations

import click

from ..errors import EngineError
from .context import connection, emit_json
from .ids import PROGRAM_ID


@click.command()
@click.option("--program", "program_id", type=PROGRAM_ID, required=True, help="Stored program id.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object on one line.")
@click.pass_context
def simulate(ctx, program_id, as_json):
    """Simulate a stored hobbing or turning program: collisions of the hob (tip cylinder, length, swivel)
    with the blank, its units, the fixture and the tailstock; the teeth, hand and lead the
    coupling generates and the swivel, against the gear; depth, stock and run-out per cut; the
    table speed; the feed per workpiece revolution; the cycle time against the header. A lathe
    program (a job from a drawing): rapids through the blank or the part, cuts into the part,
    thread passes outside the drawn thread, tool changes away from the job's position, cuts with
    the spindle stopped, and feed per revolution and cutting speed against the cutting-data table.
    A lathe class job's program (engine instantiate --class: no drawing) against its blank, stated
    or assumed from its feeds: rapids through it, cuts with the spindle stopped, tool changes in a
    moving block or inside the blank; the lines "not checked: ..." say what needs a drawing.

    One line per finding (every one), then the summary. Exit 1 when the simulation refuses the
    program, or when its lines are not the rendering of the template version and job it names
    (MISMATCH), or cannot be rendered again because its job was edited since (UNCHECKED), or the
    proof a new program gets refuses it now (REFUSED: its findings are listed first).

    Example: engine simulate --program 7 --json
    """
    from ..programs.rendering import REFUSED, stored_rendering
    from ..simulation import simulate_stored_program

    with connection(ctx) as conn:
        rendering = stored_rendering(conn, program_id)
        if rendering.status != REFUSED:   # a forged program proves nothing; a refused rendering is shown
            rendering.refuse_unless_matching("the simulation")
        report = simulate_stored_program(conn, program_id)
    if as_json:
        emit_json({"program_id": program_id, **report.as_dict()})
    else:
        for line in report.lines():
            click.echo(line)
    listed = " in the JSON's findings" if as_json else ", listed above"
    if rendering.status == REFUSED:   # the proof's refusal, and where the simulation's findings are
        said = f"; the simulation's findings are{listed.replace(', ', ' ')}" if report.refused else ""
        raise EngineError(f"program {program_id}: {REFUSED}: {rendering.reason}{said}")
    if report.refused:
        raise report.error(listed)
