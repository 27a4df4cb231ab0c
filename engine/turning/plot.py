"""`engine plot --job ID -o part.png|.svg`: a turning job as the program states it, Z to the right
and X as a diameter up (design notes §8: programs use diameter X), so every X word of the program
and the tool-change point read off the vertical axis as they are written. The upper half of the
section is drawn at its true shape: a mm of diameter is drawn half as tall as a mm of Z.

Each operation has its own colour (two operations with one tool are still told apart), its
feed moves solid and its rapids dashed. job_figure builds the matplotlib Figure without writing
it, so what was drawn can be read back (labels, colours, Line2D data); plot_picture writes it
whole or not at all (engine.pictures)."""
from __future__ import annotations

import math
from collections.abc import Sequence

import msgspec

from ..drawings.geometry import Arc, Segment
from ..pictures import literal, new_figure, picture_target, save_atomically
from .moves import Move, Pass
from .plot_frame import Frame, job_frame
from .region import arc_points

Point = tuple[float, float]            # (z, diameter), both mm
Stock = tuple[float, float, float]     # z_front, z_back, radius
DrawnOperation = tuple[str, int, list[Pass]]   # label ("OP 2 FINISH"), tool, passes

RAPID_STYLE = (0, (4, 2))   # dashes: 4 points on, 2 off
FEED_WIDTH, RAPID_WIDTH = 1.3, 0.7   # points
ARC_STEP_DEG = 2.0          # an arc move is drawn as a polyline with this angle step
PART_FILL, PART_EDGE = "0.72", "0.35"     # the finished part: mid grey
BLANK_FILL, BLANK_EDGE = "0.93", "0.6"    # the blank around it: material to remove, lighter
# Nine colours for the nine operation slots (engine.turning.names.MAX_OPERATIONS), none grey
# like the part: every operation of a job has its own.
OPERATION_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple",
                     "tab:brown", "tab:pink", "tab:olive", "tab:cyan")
TOOL_CHANGE_MARKER = dict(marker="P", markersize=10, color="black", markerfacecolor="gold", linestyle="none")
NOTE_BOX = dict(boxstyle="round,pad=0.2", facecolor="white", edgecolor="0.6", alpha=0.9)
NO_BREAK = float("nan")   # between two pieces of one Line2D that do not join
Y_LABEL = "X diameter (mm)"
STRETCHED_LABEL = "Z (mm) · not to scale: the shape is stretched to be seen"


class JobPicture(msgspec.Struct, frozen=True):
    """What a picture of a turning job shows; tool_change is (Z, X diameter) as in the program."""
    outline: Sequence[Segment]
    stock: Stock | None
    operations: Sequence[DrawnOperation]
    title: str = ""
    tool_change: Point | None = None


def plot_job(path, outline: Sequence[Segment], stock: Stock | None, operations: Sequence[DrawnOperation],
             title: str = "", tool_change: Point | None = None):
    """Draw the job to path (.png or .svg); EngineError for any other suffix. → the Figure."""
    return plot_picture(path, JobPicture(outline, stock, operations, title, tool_change))


def plot_picture(path, picture: JobPicture):
    target, file_format = picture_target(path)
    figure = job_figure(picture)
    save_atomically(figure, target, file_format)
    return figure


def job_figure(picture: JobPicture):
    """The picture as a Figure, not written: one Axes, Z across and X diameter up."""
    traced = [(f"{label} T{tool}", operation_lines(passes, picture.tool_change))
              for label, tool, passes in picture.operations]
    part = diameter_points(outline_points(picture.outline))
    frame = job_frame(part, picture.stock, [lines for _, lines in traced], picture.tool_change)
    figure = new_figure(frame.figure_size)
    figure.set_layout_engine("constrained")
    axes = figure.add_subplot()
    draw_material(axes, part, picture.stock)
    for n, (label, lines) in enumerate(traced):
        draw_operation(axes, lines, OPERATION_COLOURS[n % len(OPERATION_COLOURS)], label)
    draw_line_styles(axes)
    if picture.tool_change is not None:
        draw_tool_change(axes, picture.tool_change, frame)
    finish_axes(figure, axes, frame, picture.title)
    return figure


# --- the part and the blank ------------------------------------------------------------------

def outline_points(outline: Sequence[Segment]) -> list[Point]:
    """The closed outline in (z, radius), arcs as chords."""
    points: list[Point] = []
    for segment in outline:
        piece = arc_points(segment) if isinstance(segment, Arc) else [segment.start, segment.end]
        points.extend(piece if not points else piece[1:])
    return points


def diameter_points(points: Sequence[Point]) -> list[Point]:
    return [(z, 2.0 * r) for z, r in points]


def draw_material(axes, part: list[Point], stock: Stock | None) -> None:
    """The blank behind (lighter), the part on it (darker), both filled: the dashes are the rapids'."""
    if stock is not None:
        z_front, z_back, radius = stock
        diameter = 2.0 * radius
        axes.fill([z_back, z_front, z_front, z_back], [0.0, 0.0, diameter, diameter], facecolor=BLANK_FILL,
                  edgecolor=BLANK_EDGE, linewidth=0.8, zorder=0, label=f"blank Ø{diameter:g}")
    if part:
        zs, ds = zip(*part)
        axes.fill(zs, ds, facecolor=PART_FILL, edgecolor=PART_EDGE, linewidth=0.8, zorder=1, label="part")


# --- the tool paths ------------------------------------------------------------------------------

def operation_lines(passes: Sequence[Pass], tool_change: Point | None) -> dict[str, list[Point]]:
    """The operation's feed and rapid moves as two polylines in (z, diameter), pieces that do not
    join separated by NaN. The operation starts at the tool-change point, where its tool is
    changed (the template's tool-change block); without one, at its first move."""
    lines: dict[str, list[Point]] = {"feed": [], "rapid": []}
    here = tool_change
    for move in (move for one in passes for move in one):
        if here is not None:
            add_piece(lines["rapid" if move.kind == "rapid" else "feed"], move_points(here, move))
        here = (move.z, move.x)
    return lines


def add_piece(line: list[Point], piece: list[Point]) -> None:
    if line and line[-1] == piece[0]:
        line.extend(piece[1:])
        return
    if line:
        line.append((NO_BREAK, NO_BREAK))
    line.extend(piece)


def move_points(start: Point, move: Move) -> list[Point]:
    """The move from start as a polyline in (z, diameter); arcs sampled about their centre
    (i is a radius, so the arc is traced in radius and doubled)."""
    end = (move.z, move.x)
    if move.kind not in ("cw", "ccw") or move.i is None or move.k is None:
        return [start, end]
    (z0, r0), (z1, r1) = (start[0], start[1] / 2.0), (move.z, move.x / 2.0)
    centre = (z0 + move.k, r0 + move.i)
    a0 = math.atan2(r0 - centre[1], z0 - centre[0])
    a1 = math.atan2(r1 - centre[1], z1 - centre[0])
    turn = (a1 - a0) % (2 * math.pi) if move.kind == "ccw" else -((a0 - a1) % (2 * math.pi))
    radius = math.dist((z0, r0), centre)
    steps = max(2, math.ceil(abs(math.degrees(turn)) / ARC_STEP_DEG))
    inner = [(centre[0] + radius * math.cos(a0 + turn * n / steps),
              2.0 * (centre[1] + radius * math.sin(a0 + turn * n / steps))) for n in range(1, steps)]
    return [start, *inner, end]


def draw_operation(axes, lines: dict[str, list[Point]], colour: str, label: str) -> None:
    """Feed moves solid (the legend entry of the operation), rapids dashed in the same colour."""
    feed, rapid = (list(zip(*lines[kind])) or [(), ()] for kind in ("feed", "rapid"))
    axes.plot(*feed, color=colour, linewidth=FEED_WIDTH, label=literal(label), zorder=3)
    axes.plot(*rapid, color=colour, linewidth=RAPID_WIDTH, linestyle=RAPID_STYLE, label=literal(f"_{label} rapid"),
              zorder=2)


def draw_line_styles(axes) -> None:
    """Legend entries that say what solid and dashed mean, for every colour."""
    axes.plot([], [], color="0.2", linewidth=FEED_WIDTH, label="feed (G1/G2/G3, thread): solid")
    axes.plot([], [], color="0.2", linewidth=RAPID_WIDTH, linestyle=RAPID_STYLE, label="rapid (G0): dashed")


def draw_tool_change(axes, point: Point, frame: Frame) -> None:
    """The marker at the point; when the point lies outside the frame, an arrow at the frame's
    edge points towards it, with its coordinates."""
    z, x = point
    label = f"tool change Z{z:g} X{x:g}"
    axes.plot([z], [x], label=label, zorder=4, **TOOL_CHANGE_MARKER)
    if frame.contains(point):
        return
    edge = frame.clamped(point)
    away = frame.inward_offset(point)
    axes.annotate(f"tool change\nZ{z:g} X{x:g}", xy=edge, xytext=away, textcoords="offset points",
                  ha="center", va="center", fontsize="small", zorder=5, bbox=NOTE_BOX,
                  arrowprops=dict(arrowstyle="->", color="black", linewidth=1.0))


def finish_axes(figure, axes, frame: Frame, title: str) -> None:
    axes.set_xlim(frame.z_limits)
    axes.set_ylim(frame.x_limits)
    axes.set_aspect(frame.aspect, adjustable="box")
    axes.set_xlabel("Z (mm)" if frame.aspect != "auto" else STRETCHED_LABEL)
    axes.set_ylabel(Y_LABEL)
    axes.axhline(0.0, color="0.4", linewidth=0.6, linestyle="-.", zorder=1)   # the spindle axis
    axes.grid(True, linewidth=0.3)
    if title:
        axes.set_title(literal(title), fontsize="medium")
    figure.legend(loc="outside right upper", fontsize="small")
