"""`engine plot --program ID`: a stored hobbing program drawn as the simulation reads it
(engine.simulation.hobbing.recorded): the side view (blank, units, fixture, tailstock, hob at approach and
at full depth, each pass with its direction, working area), the whole working area with every
move, the hob seen from its side with the shift range, the numbers an operator checks the set-up
against (engine.hobbing.setup_numbers), the hand check of teeth and hob thread
(engine.hobbing.hand_view) and, for a worm wheel, the view from above with its radial infeed and
tangential pass (engine.hobbing.worm_view). The program's job supplies the gear,
hob and machine, as `engine simulate --program ID` takes them. The lines are read in the
machine's dialect by the simulation's reading (an 840D program, or a Fanuc one with G81/G80,
issue 30), never by a parser of the picture's own: a line it cannot read, or a coupling it cannot
prove before the walk, is refused in one line naming the line and the dialect. PNG or SVG,
written whole or not at all (engine.pictures)."""
from __future__ import annotations

import textwrap
from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from ..gears.records import Gear, Hob, load_gear
from ..machines.records import Machine, load_machine
from ..machines.work_holding import job_work_holding
from ..pictures import literal, new_figure, picture_target, save_atomically
from ..simulation.hobbing.recorded import Recording, record_program
from ..simulation.hobbing.report import SimulationError
from ..simulation.hobbing.stored import load_hob
from .hand_view import draw_hand_check
from .hob_view import draw_hob_view
from .setup_numbers import setup_numbers
from .side_view import draw_overview, draw_side_view
from .worm_view import draw_worm_view

if TYPE_CHECKING:
    from ..db.connection import Connection

FIGURE_SIZE_IN = (21.0, 10.5)
TITLE_WIDTH = 200          # characters of a title line at the figure's width
TITLE_COLOURS = {False: "black", True: "red"}   # by whether the simulation refuses the program
COLUMN_WIDTHS = (3, 2, 2)   # side view; overview over hob view; numbers over hand check (over worm view)
RIGHT_ROWS = {False: (1.0, 1.1), True: (1.0, 0.9, 1.1)}   # by whether the gear is a worm wheel
NUMBERS_WIDTH = 62         # characters of a line of the numbers' panel
NUMBERS_ROWS = 22          # lines the panel has room for at least (more: closer together)
NUMBERS_TITLE = "numbers read from the program (the simulation's reading)"
DRAFT_WORDS = " · DRAFT: made from a template version not released, it never reaches the machine"
PROGRAM_QUERY = """
SELECT p.name, p.lines, p.draft, p.job_id, j.gear_id, j.gear_class, j.hob_id, j.machine
FROM program p JOIN job j ON j.id = p.job_id
WHERE p.id = %s"""


class Scene(msgspec.Struct, frozen=True):
    program_id: int
    job_id: int
    name: str
    draft: bool             # made from a template version not released: never reaches the machine
    gear_class: str
    gear: Gear
    hob: Hob
    machine: Machine
    recording: Recording

    @property
    def title(self) -> str:
        return (f"job {self.job_id} · gear {self.gear.id} ({self.gear_class}, m{self.gear.module:g} "
                f"z{self.gear.teeth}) · hob {self.hob.id} · {self.machine.name} · program {self.name} "
                f"(id {self.program_id}){DRAFT_WORDS if self.draft else ''}")


def plot_stored_program(conn: Connection, program_id: int, out) -> list[str]:
    """Draw the stored program to `out` (.png or .svg); → one line per thing drawn."""
    target, file_format = picture_target(out)
    figure, drawn = program_figure(load_scene(conn, program_id))
    save_atomically(figure, target, file_format)
    return drawn


def load_scene(conn: Connection, program_id: int) -> Scene:
    row = conn.execute(PROGRAM_QUERY, (program_id,)).fetchone()
    if row is None:
        raise EngineError(f"program {program_id} does not exist; see `SELECT id, name FROM program`")
    name, lines, draft, job_id, gear_id, gear_class, hob_id, machine_name = row
    machine = load_machine(conn, machine_name)
    if machine.kind != "hobber" or gear_id is None or hob_id is None:
        raise EngineError(f"program {program_id} runs on {machine_name}, a {machine.kind}, not a hobbing program; "
                          f"draw its job with `engine plot --job {job_id} -o FILE.png`")
    gear, hob = load_gear(conn, gear_id), load_hob(conn, hob_id)
    try:
        recording = record_program(list(lines), gear, hob, machine, name, job_work_holding(conn, job_id))
    except SimulationError as error:
        raise EngineError(f"program {program_id} is not drawn (read in {machine_name}'s dialect "
                          f"{machine.dialect}): {error}") from None
    return Scene(program_id, job_id, name, draft, gear_class, gear, hob, machine, recording)


def program_figure(scene: Scene):
    """The figure, built whole before anything is written (the tests read its artists)."""
    figure = new_figure(FIGURE_SIZE_IN)
    figure.set_layout_engine("constrained")
    grid = figure.add_gridspec(2, 3, width_ratios=COLUMN_WIDTHS)
    drawn = draw_side_view(figure.add_subplot(grid[:, 0]), scene)
    drawn.append(draw_overview(figure.add_subplot(grid[0, 1]), scene))
    drawn += draw_hob_view(figure.add_subplot(grid[1, 1]), scene)
    drawn += draw_right_column(figure, grid[:, 2], scene)
    colour = TITLE_COLOURS[scene.recording.report.refused]
    figure.suptitle(literal(figure_title(scene)), fontsize="medium", color=colour)
    figure.legend(*figure.axes[0].get_legend_handles_labels(), loc="outside lower left", ncols=5, fontsize="small")
    drawn.append(simulation_words(scene.recording))
    return figure, drawn


def draw_right_column(figure, place, scene: Scene) -> list[str]:
    """The numbers, the hand check and, for a worm wheel, the view from above."""
    worm_wheel = scene.hob.purpose == "worm_wheel"
    rows = place.subgridspec(len(RIGHT_ROWS[worm_wheel]), 1, height_ratios=RIGHT_ROWS[worm_wheel])
    drawn = draw_numbers(figure.add_subplot(rows[0]), scene)
    drawn.append(draw_hand_check(figure.add_subplot(rows[1]), scene))
    if worm_wheel:
        drawn += draw_worm_view(figure.add_subplot(rows[2]), scene)
    return drawn


def draw_numbers(axes, scene: Scene) -> list[str]:
    """One text per number, top down, in a panel of its own; → the same lines for the report."""
    numbers = setup_numbers(scene)
    texts = [textwrap.wrap(number.text, NUMBERS_WIDTH, subsequent_indent="      ", drop_whitespace=False)
             for number in numbers]
    step, row = 1.0 / max(NUMBERS_ROWS, sum(map(len, texts)) + len(texts)), 0.5
    for number, text in zip(numbers, texts):
        axes.text(0.0, 1.0 - row * step, literal("\n".join(text)), transform=axes.transAxes, va="top",
                  fontsize="small", family="monospace", gid=number.gid)
        row += len(text) + 1
    axes.set_title(NUMBERS_TITLE, fontsize="medium")
    axes.set_axis_off()
    return [number.text for number in numbers]


def figure_title(scene: Scene) -> str:
    """The title; for a program the simulation refuses now, the refusal first (a picture is passed
    around without the command's output, and must not look like that of a proved program)."""
    report = scene.recording.report
    if not report.refused:
        return scene.title
    more = len(report.refusals) - 1
    refusal = report.refusals[0].sentence(report.name) + (f" (and {more} more finding(s))" if more else "")
    return "\n".join([*textwrap.wrap(f"REFUSED BY THE SIMULATION: {refusal}", TITLE_WIDTH), scene.title])


def simulation_words(recording: Recording) -> str:
    refusals = recording.report.refusals
    if not refusals:
        return "drawn from the simulation's reading: it proves the program"
    return (f"drawn from the simulation's reading: it refuses the program now ({len(refusals)} finding(s); "
            f"see `engine simulate`)")
