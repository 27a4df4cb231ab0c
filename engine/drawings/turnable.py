"""What a lathe cannot make from outside, seen in a side view (issue 17): each check refuses
with the reason by name. The view is in machine coordinates (z, radius about its centre line),
its outline (the upper envelope) already taken.

* a circle centred on the centre line: the view looks along the axis, it is no side view;
* nothing drawn crosses or meets the centre line: separate outlines, a plate's holes;
* a section's hatching that stops short of the axis, or hidden lines along the axis from an
  end face: a bore, which needs internal turning;
* edges along the whole length of a cylinder-like span at a radius a prism shows (PRISM_EDGES):
  a hexagon head, not a turned surface.
"""
from __future__ import annotations

import math

from .geometry import Arc, Line, Segment
from .profile import END_MATCH_TOLERANCE_MM, bounds, sweep
from .read import DxfError

HATCH_SAMPLES = 200
# Interior edges along the whole length of a cylinder-like span, as a share of its outline
# radius, and what a side view with them shows: the faces of a prism, not a turned surface.
PRISM_EDGES = ((0.5, "a hexagon seen across its corners (edges at ±e/4 inside its outline ±e/2)"),
               (0.0, "a hexagon seen across its flats, or a square across its corners (an edge on the centre line)"))
PRISM_SHARE_TOLERANCE = 0.03
# An edge along at least this share of a constant-radius span runs along it (chamfered ends aside).
PRISM_SPAN_SHARE = 0.9


def check_not_an_end_view(framed: list[Segment], where: str) -> None:
    """A circle (or an arc of more than half a turn) centred on the axis: the view looks along the axis."""
    turned: dict[tuple, float] = {}
    for s in framed:
        if isinstance(s, Arc) and abs(s.centre[1]) <= END_MATCH_TOLERANCE_MM:
            turn_key = (s.handle, round(s.centre[0], 3), round(s.radius, 3))
            turned[turn_key] = turned.get(turn_key, 0.0) + sweep(s)
    circles = sorted({2 * radius for (_, _, radius), turn in turned.items() if turn > math.pi + 1e-6})
    if circles:
        shown = ", ".join(f"Ø{d:g}" for d in circles[:4])
        raise DxfError(f"{where} shows circles centred on its centre line ({shown}): a view along the axis, "
                       "not a side view; draw the side view of the part (or its half-profile)")


def check_reaches_the_axis(framed: list[Segment], where: str, axis: str) -> None:
    """A turned part's side view has lines across the axis (its end faces); a plate's holes do not.
    axis: how the axis was found (a centre line's handle, or the drawing's symmetry)."""
    if any(bounds(s)[2] < -END_MATCH_TOLERANCE_MM and bounds(s)[3] > END_MATCH_TOLERANCE_MM
           or max(abs(s.start[1]), abs(s.end[1])) <= END_MATCH_TOLERANCE_MM for s in framed):
        return
    handles = len({s.handle for s in framed})
    raise DxfError(f"{where}: nothing drawn crosses or meets the axis ({axis}); it is {handles} separate "
                   "outline(s) on either side (holes of a plate, a flat part), not a turned part")


def lowest_hatched(polygons: list[list[tuple[float, float]]], z: float) -> tuple[float | None, float | None]:
    """The smallest radius of hatched material at z above and below the axis (None: no hatch)."""
    crossings = sorted(r0 + (z - z0) * (r1 - r0) / (z1 - z0) for polygon in polygons
                       for (z0, r0), (z1, r1) in zip(polygon, polygon[1:] + polygon[:1])
                       if (z0 <= z < z1) or (z1 <= z < z0))
    inside = list(zip(crossings[0::2], crossings[1::2]))
    above = [max(low, 0.0) for low, high in inside if high > 0.0]
    below = [max(-high, 0.0) for low, high in inside if low < 0.0]
    return (min(above) if above else None), (min(below) if below else None)


def check_no_bore(polygons: list[list[tuple[float, float]]], z_min: float, z_max: float, where: str) -> None:
    """In a section the hatching is the material: where it stops short of the axis, a bore is."""
    if not polygons:
        return
    bored = []
    for k in range(1, HATCH_SAMPLES):
        z = z_min + (z_max - z_min) * k / HATCH_SAMPLES
        lows = [low for low in lowest_hatched(polygons, z) if low is not None]
        if lows and min(lows) > END_MATCH_TOLERANCE_MM:
            bored.append((z, min(lows)))
    if bored:
        diameter = 2 * min(radius for _, radius in bored)
        through = len(bored) == HATCH_SAMPLES - 1
        span = (f"through the whole part (Z{z_min:.3f} to Z{z_max:.3f})" if through
                else f"from Z{bored[0][0]:.3f} to Z{bored[-1][0]:.3f}")
        raise DxfError(f"{where}: the section shows a bore Ø{diameter:.3f} {span}: its hatching stops short of "
                       "the axis; cutting it needs internal turning, which is not supported")


def check_no_prism(framed: list[Segment], outline: list[Segment], where: str) -> None:
    """Edges along the whole length of a constant-radius span, at a radius a prism shows."""
    spans = [(min(s.start[0], s.end[0]), max(s.start[0], s.end[0]), s.start[1]) for s in outline
             if isinstance(s, Line) and abs(s.start[1] - s.end[1]) <= END_MATCH_TOLERANCE_MM
             and abs(s.start[0] - s.end[0]) > END_MATCH_TOLERANCE_MM]
    for s in framed:
        if (not isinstance(s, Line) or abs(s.start[1] - s.end[1]) > END_MATCH_TOLERANCE_MM
                or s.start[1] < -END_MATCH_TOLERANCE_MM):
            continue
        z0, z1, radius = min(s.start[0], s.end[0]), max(s.start[0], s.end[0]), s.start[1]
        for a, b, outer in spans:
            if along_the_span(z0, z1, a, b) and radius < outer - END_MATCH_TOLERANCE_MM:
                check_prism_share(radius, outer, a, b, where)


def along_the_span(z0: float, z1: float, a: float, b: float) -> bool:
    """An edge from z0 to z1 runs along the span a … b: within it and over PRISM_SPAN_SHARE of it
    (a hexagon's edges stop short of its ends where its corners are chamfered, 30° on a bolt's
    head: issue 27, an inch hex bolt's edges start 0.2 mm in)."""
    slack = 5 * END_MATCH_TOLERANCE_MM
    return a - slack <= z0 and z1 <= b + slack and z1 - z0 >= PRISM_SPAN_SHARE * (b - a)


def check_prism_share(radius: float, outer: float, a: float, b: float, where: str) -> None:
    for share, shows in PRISM_EDGES:
        if abs(radius / outer - share) <= PRISM_SHARE_TOLERANCE:
            raise DxfError(f"{where}: the part from Z{a:.3f} to Z{b:.3f} is not a turned surface: its side view has "
                           f"edges at ±{radius:.3f} along its whole length inside its outline ±{outer:.3f}, as "
                           f"{shows}; a lathe cannot make it as drawn")


def check_no_hidden_bore(hidden: list[Segment], outline: list[Segment], where: str) -> None:
    """Hidden lines along the axis from an end face, inside the outline: a bore seen from outside."""
    z_min, z_max = outline[-1].end[0], outline[0].start[0]
    for line in hidden:
        if not isinstance(line, Line) or abs(line.start[1] - line.end[1]) > END_MATCH_TOLERANCE_MM:
            continue
        z0, z1 = sorted((line.start[0], line.end[0]))
        from_face = abs(z0 - z_min) <= END_MATCH_TOLERANCE_MM or abs(z1 - z_max) <= END_MATCH_TOLERANCE_MM
        if from_face and z1 - z0 > END_MATCH_TOLERANCE_MM and abs(line.start[1]) > END_MATCH_TOLERANCE_MM:
            raise DxfError(f"{where}: hidden lines show a bore Ø{2 * abs(line.start[1]):.3f} from Z{z0:.3f} to "
                           f"Z{z1:.3f}, from the end face; cutting it needs internal turning, which is not supported")
