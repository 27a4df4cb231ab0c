"""What a program's page shows beyond its record, each also a page of its own: its plot as SVG
(`engine plot --program`), its simulation report (`engine simulate --program`), its trace (`engine
explain --program`) and one template row's part of it (`--row N`: where a line of the program
leads). Each is shown only of a program that is the rendering of what it names (MATCH), as the
commands refuse anything else; the simulation also of a REFUSED one, to show what is refused."""
from __future__ import annotations

import tempfile
import threading
from pathlib import Path

from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import Route

from ...errors import EngineError
from ...nc.lineage import LINEAGE_ROW_ID
from ...programs.explain import explain_program, traced_lines
from ...programs.plots import plot_program
from ...programs.rendering import REFUSED, Rendering, stored_rendering
from ...simulation import simulate_stored_program
from .answers import answered, shown, whole

SVG_START = "<svg"
DRAWING = threading.Lock()   # matplotlib's font and text caches are not made for threads drawing at once


def traced(conn, record) -> list[dict]:
    """The program's lines, each with the template row that made it and the row's sentence (the
    lineage line: the engine's, no row's)."""
    rows, row_ids = traced_lines(conn, record.id)
    said = {row.row_id: row.sentence() for row in rows}
    return [{"text": line, "row": None if row_id == LINEAGE_ROW_ID else row_id, "why": said.get(row_id)}
            for line, row_id in zip(record.lines, row_ids)]


def plot_svg(conn, program_id: int) -> tuple[str | None, str | None]:
    """(the SVG element of the program's plot, None), or (None, why it is not drawn): drawn as
    `engine plot --program` draws it, into a file of a temporary folder read back."""
    try:
        with tempfile.TemporaryDirectory(prefix="engine-plot-") as folder, DRAWING:
            target = Path(folder) / "plot.svg"
            plot_program(conn, program_id, target)
            text = target.read_text(encoding="utf-8")
    except EngineError as error:
        return None, str(error)
    return text[text.index(SVG_START):], None   # the element alone: no XML declaration or DOCTYPE in a page


def simulation_report(conn, program_id: int, rendering: Rendering | None = None) -> dict:
    """`engine simulate --program`'s report: {"json": its JSON, "lines": its lines, "refusal": the
    one line it ends with when it refuses, or None}; the refusal alone when nothing was simulated.
    `rendering`: the program's, when the page has checked it already (not rendered and proved twice)."""
    rendering = rendering or stored_rendering(conn, program_id)
    try:
        if rendering.status != REFUSED:   # a forged program proves nothing; a refused rendering is shown
            rendering.refuse_unless_matching("the simulation")
        report = simulate_stored_program(conn, program_id)
    except EngineError as error:
        return {"json": None, "lines": [], "refusal": str(error)}
    refusal = None
    if rendering.status == REFUSED:
        refusal = f"program {program_id}: {REFUSED}: {rendering.reason}"
    elif report.refused:
        refusal = str(report.error(", listed above"))
    return {"json": {"program_id": program_id, **report.as_dict()}, "lines": report.lines(), "refusal": refusal}


def _program_id(request: Request) -> int:
    return whole("program", request.path_params["program_id"])


def plot(request: Request):
    """The plot alone, as an SVG file."""
    def work(conn):
        program_id = _program_id(request)
        svg, refusal = plot_svg(conn, program_id)
        if svg is None:
            raise EngineError(refusal or f"program {program_id} is not drawn")
        return Response(svg, media_type="image/svg+xml")
    return answered(request, work)


def simulation(request: Request):
    """`engine simulate --program ID --json`; a refused program answers 400 with its report."""
    def work(conn):
        report = simulation_report(conn, _program_id(request))
        if report["json"] is None:
            raise EngineError(report["refusal"])
        return shown(request, "simulation.html", report["json"], lambda: report,
                     status=400 if report["refusal"] else 200)
    return answered(request, work)


def trace(request: Request):
    """`engine explain --program ID --json`: every template row, emitted or not, and why."""
    return answered(request, lambda conn: _explained(request, explain_program(conn, _program_id(request)), False))


def row(request: Request):
    """`engine explain --program ID --row N --json`: where a line of the program leads."""
    return answered(request, lambda conn: _explained(request, explain_program(
        conn, _program_id(request), whole("row", request.path_params["row_id"])), True))


def _explained(request: Request, rows: list, single: bool):
    data = {"program_id": _program_id(request), "rows": [row.as_dict() for row in rows]}
    return shown(request, "trace.html", data,
                 lambda: {"single": single, "sentences": [row.sentence() for row in rows]})


ROUTES = [Route("/programs/{program_id}/plot.svg", plot, name="program_plot"),
          Route("/programs/{program_id}/simulation", simulation, name="program_simulation"),
          Route("/programs/{program_id}/trace", trace, name="program_trace"),
          Route("/programs/{program_id}/rows/{row_id}", row, name="program_row")]
