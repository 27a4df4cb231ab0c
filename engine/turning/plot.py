"""`engine plot --job ID -o part.png|.svg`: the profile, the blank and every tool path of a
turning job in the (Z, radius) plane: rapids dashed, cutting moves solid, one colour per
tool. Written whole or not at all (engine.pictures)."""
from __future__ import annotations

import math
from typing import Sequence

from importers.dxf_geometry import Arc, Segment

from ..pictures import new_figure, picture_target, save_atomically
from .moves import Move, Pass
from .region import arc_points

RAPID_STYLE = (0, (3, 2))   # dashes: 3 points on, 2 off
# Angle step (degrees) for drawing an arc move as a polyline.
ARC_STEP_DEG = 2.0
FIGURE_SIZE_IN = (10.0, 5.0)
OUTLINE_FILL = "0.85"   # light grey
TOOL_COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:orange", "tab:purple",
                "tab:brown", "tab:pink", "tab:olive", "tab:cyan", "tab:gray")

Stock = tuple[float, float, float]   # z_front, z_back, radius


def plot_job(path, outline: Sequence[Segment], stock: Stock | None,
             operations: Sequence[tuple[str, int, list[Pass]]]) -> None:
    """Draw the job to path (.png or .svg); EngineError for any other suffix."""
    target, file_format = picture_target(path)
    figure = new_figure(FIGURE_SIZE_IN)
    axes = figure.add_subplot()
    draw_outline(axes, outline)
    if stock is not None:
        draw_stock(axes, stock)
    colours: dict[int, str] = {}
    for label, tool, passes in operations:
        colour = colours.setdefault(tool, TOOL_COLOURS[len(colours) % len(TOOL_COLOURS)])
        draw_passes(axes, passes, colour, f"{label} (T{tool})")
    finish_axes(axes)
    save_atomically(figure, target, file_format)


def draw_outline(axes, outline: Sequence[Segment]) -> None:
    points = outline_points(outline)
    if points:
        zs, rs = zip(*points)
        axes.fill(zs, rs, color=OUTLINE_FILL, zorder=0)
        axes.plot(zs + zs[:1], rs + rs[:1], color="0.4", linewidth=0.8, zorder=1, label="profile")


def outline_points(outline: Sequence[Segment]) -> list[tuple[float, float]]:
    points: list[tuple[float, float]] = []
    for segment in outline:
        piece = arc_points(segment) if isinstance(segment, Arc) else [segment.start, segment.end]
        points.extend(piece if not points else piece[1:])
    return points


def draw_stock(axes, stock: Stock) -> None:
    z_front, z_back, radius = stock
    axes.plot([z_back, z_front, z_front, z_back, z_back], [0.0, 0.0, radius, radius, 0.0],
              color="0.3", linestyle=(0, (6, 3)), linewidth=0.9, label="blank")


def draw_passes(axes, passes: Sequence[Pass], colour: str, label: str) -> None:
    """Each move from the end of the one before; the first move of all has no start."""
    here: tuple[float, float] | None = None
    for move in (move for one in passes for move in one):
        if here is not None:
            zs, rs = zip(*move_points(here, move))
            rapid = move.kind == "rapid"
            axes.plot(zs, rs, color=colour, linewidth=0.6 if rapid else 1.1,
                      linestyle=RAPID_STYLE if rapid else "-")
        here = (move.z, move.x / 2.0)
    axes.plot([], [], color=colour, linewidth=1.1, label=label)   # the legend entry: solid


def move_points(start: tuple[float, float], move: Move) -> list[tuple[float, float]]:
    """The move as a polyline in (z, radius); arcs sampled about their centre."""
    end = (move.z, move.x / 2.0)
    if move.kind not in ("cw", "ccw") or move.i is None or move.k is None:
        return [start, end]
    centre = (start[0] + move.k, start[1] + move.i)
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    turn = (a1 - a0) % (2 * math.pi) if move.kind == "ccw" else -((a0 - a1) % (2 * math.pi))
    radius = math.dist(start, centre)
    steps = max(2, math.ceil(abs(math.degrees(turn)) / ARC_STEP_DEG))
    return [(centre[0] + radius * math.cos(a0 + turn * n / steps),
             centre[1] + radius * math.sin(a0 + turn * n / steps)) for n in range(steps + 1)]


def finish_axes(axes) -> None:
    axes.set_aspect("equal", adjustable="datalim")
    axes.set_xlabel("Z (mm)")
    axes.set_ylabel("radius (mm)")
    axes.axhline(0.0, color="0.5", linewidth=0.5, linestyle="-.")
    axes.grid(True, linewidth=0.3)
    axes.legend(loc="best", fontsize="small")
