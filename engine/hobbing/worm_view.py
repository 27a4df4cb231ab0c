"""The worm wheel seen from above (issue 27): the plane of its cuts, X (centre distance) to the
right and Y (along the hob, Y = Z × X, reference §A7) up, so both of its motions show in one view
(§B10): the radial infeed along X (the whole cut of the radial method, the move to the centre
distance before a tangential pass) and the tangential pass along Y. The wheel's tip circle and
intended root, the hob's outline (its tip diameter across, its length along Y foreshortened by
the swivel) where each cut begins and at its end, and an arrow per motion with the program's
numbers. Drawn from the simulation's recording, as the other views."""
from __future__ import annotations

import math

from matplotlib.patches import Circle, Rectangle

from ..pictures import literal
from ..simulation.hobbing.frame import Senses
from .setup_numbers import moved_axes, span
from .side_view import BLANK_FILL, cut_colour

MOTIONS = (("X", "radial infeed"), ("Y", "tangential pass"))
LABEL_STEP = 10          # points between labels of motions that start at one place (rough, finish, infeed)


def draw_worm_view(axes, scene) -> list[str]:
    """→ one report line per motion drawn."""
    unit = scene.recording.units[0]
    axes.add_patch(Circle((0.0, 0.0), unit.radius_at_top, facecolor=BLANK_FILL, edgecolor="0.3", linewidth=0.8,
                          gid="top wheel tip", label="wheel tip circle"))
    if unit.intended_root is not None:
        axes.add_patch(Circle((0.0, 0.0), min(unit.intended_root), fill=False, edgecolor="0.3",
                              linestyle=":", linewidth=0.7, gid="top wheel root", label="intended root"))
    senses, drawn = Senses.of(scene.machine), []
    for index, cut in enumerate(scene.recording.cuts):
        draw_hob(axes, scene, cut.moves[0].start, f"top hob {cut.label} start", "0.45", (0, (3, 2)))
        draw_hob(axes, scene, cut.moves[-1].end, f"top hob {cut.label} end", "black", "-")
        for row, (axis, name) in enumerate(MOTIONS, start=len(MOTIONS) * index):
            moves = [move for move in cut.moves if moved_axes(move) == {axis}]
            if moves:
                drawn.append(draw_motion(axes, cut, moves, (axis, name), (index, row), senses))
    finish(axes)
    return drawn or ["top view: no infeed or tangential pass"]


def draw_hob(axes, scene, pose: dict, gid: str, colour: str, style) -> None:
    """The hob seen from above: its tip diameter along X, its length along Y times cos A."""
    if not {"X", "Y"} <= pose.keys():
        return
    radius = scene.hob.tip_diameter / 2
    half = scene.hob.length / 2 * abs(math.cos(math.radians(scene.recording.final_swivel)))
    axes.add_patch(Rectangle((pose["X"] - radius, pose["Y"] - half), 2 * radius, 2 * half, fill=False,
                             edgecolor=colour, linestyle=style, linewidth=1.0, gid=gid))


def draw_motion(axes, cut, moves, motion: tuple, place: tuple, senses: Senses) -> str:
    """The arrow of one motion (axis, name), from where its first move starts to where its last
    ends, in the cut's colour; its label on its own row (place: the cut's index, the label's row)."""
    (axis, name), start, end, colour = motion, moves[0].start, moves[-1].end, cut_colour(place[0])
    if not ({"X", "Y"} <= start.keys() and {"X", "Y"} <= end.keys()):
        return f"{cut.label}: {name} where Y is not known"
    words = f"{cut.label}: {name} {span(moves, axis, senses)}"
    axes.annotate("", xy=(end["X"], end["Y"]), xytext=(start["X"], start["Y"]), gid=f"top {name} {cut.label}",
                  arrowprops=dict(arrowstyle="-|>", color=colour, linewidth=1.8, mutation_scale=16))
    # A radial infeed before a tangential pass is a millimetre or so: named where it is, to be seen.
    short = " ".join(cut.label.split()[:2])
    axes.annotate(literal(f"{short}: {name}"), xy=(start["X"], start["Y"]), xytext=(8, 4 + LABEL_STEP * place[1]),
                  textcoords="offset points", color=colour,
                  fontsize="x-small", gid=f"top label {name} {cut.label}")
    axes.plot([], [], color=colour, linewidth=1.8, label=literal(words))
    return words


def finish(axes) -> None:
    axes.autoscale_view()
    axes.set_aspect("equal", adjustable="datalim")
    axes.set_xlabel("X (mm)")
    axes.set_ylabel("Y (mm)")
    axes.set_title("worm wheel from above: radial infeed (X) and tangential pass (Y)", fontsize="medium")
    axes.grid(True, linewidth=0.3)
    axes.legend(loc="best", fontsize="x-small")
