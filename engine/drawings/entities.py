"""DXF entities → path segments (Line, Arc) in world coordinates, drawing units.

Each supported entity type has a handler in HANDLERS (keyed by dxftype). Handlers work in
the XY plane of the WCS: ARC, CIRCLE and LWPOLYLINE live in their object coordinate
system (OCS); with extrusion (0,0,-1) the OCS X axis points along −X, so points mirror and
the turning sense flips. Entities in any other plane are projected onto XY by flattening
them. SPLINE and ELLIPSE become lines within FLATTEN_TOLERANCE_MM. INSERTs are exploded
recursively; block content on layer 0 takes the layer of the INSERT (the DXF rule).
"""
from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator

import msgspec

from .geometry import Arc, Line, Point, Segment
from .read import DxfError, one_line

# Largest distance between a flattened SPLINE/ELLIPSE (or an arc outside the XY plane) and
# its line approximation: 2 µm, a tenth of the IT6 band of a 30 mm diameter (1 µm doubled
# the segment count of large ellipses in real drawings for no gain on a lathe).
FLATTEN_TOLERANCE_MM = 0.002
# Extrusions closer than this to ±Z count as "in the XY plane".
PLANAR_EPSILON = 1e-9
# Shorter lines and smaller radii (drawing units) are drawing noise, not geometry.
DEGENERATE_LENGTH = 1e-9
# No turned part reaches a kilometre from its origin (mm): a coordinate beyond, or one that is no
# number at all (NaN, inf, or 1e308 that overflows once scaled), is a broken entity. It is
# refused where it is read, before chains, passes or a program are computed from it.
MAX_COORDINATE_MM = 1_000_000.0


class Context(msgspec.Struct, frozen=True):
    sagitta: float  # FLATTEN_TOLERANCE_MM in drawing units
    handle: str = ""  # handle of the top-level entity (virtual block content has none)
    reach: float = MAX_COORDINATE_MM  # MAX_COORDINATE_MM in drawing units


def unit_scale(insunits: int | None) -> tuple[str, float, bool]:
    """(unit name, factor to mm, assumed?) for a $INSUNITS value; unitless counts as mm."""
    if not insunits:
        return "mm", 1.0, True
    try:
        from ezdxf import units

        name = units.decode(insunits)
        assert name is not None   # only 0, unitless, has no name
        # ezdxf annotates InsertUnits, an IntEnum, and indexes its table with any $INSUNITS int
        return name, units.conversion_factor(insunits, units.MM), False   # type: ignore[arg-type]
    except (KeyError, IndexError, ValueError):
        raise DxfError(f"$INSUNITS = {insunits} is not a known unit code; set the drawing units "
                       "(e.g. 4 = millimetres) in the CAD program") from None


def segments_of(entity, context: Context) -> list[Segment]:
    """The segments of one entity; unsupported types yield nothing."""
    handler = HANDLERS.get(entity.dxftype())
    if handler is None:
        return []
    with named_on_failure(entity, context.handle):
        segments = list(handler(entity, context))
    for segment in segments:
        check_reach(entity, context, segment.start, segment.end,
                    *([segment.centre] if isinstance(segment, Arc) else []))
    return segments


def check_reach(entity, context: Context, *points: Point) -> None:
    """Every point a number within MAX_COORDINATE_MM of the origin (NaN fails the comparison)."""
    for x, y in points:
        if not (abs(x) <= context.reach and abs(y) <= context.reach):
            raise DxfError(f"{entity.dxftype()} {context.handle or entity.dxf.handle} on layer "
                           f"{entity.dxf.get('layer', '?')!r} has the point ({x:g}, {y:g}), not a number within "
                           f"{MAX_COORDINATE_MM:g} mm of the origin; redraw or delete it")


def check_finite(entity, context: Context) -> None:
    """No attribute of a read entity (a point, radius, angle, extrusion, scale) is NaN or infinite."""
    for name, value in entity.dxf.all_existing_dxf_attribs().items():
        numbers = value if isinstance(value, (tuple, list)) or hasattr(value, "isclose") else (value,)
        if any(isinstance(number, float) and not math.isfinite(number) for number in numbers):
            raise DxfError(f"{entity.dxftype()} {context.handle or entity.dxf.handle} on layer "
                           f"{entity.dxf.get('layer', '?')!r}: its {name} holds {value}, not a number; "
                           "redraw or delete it")


@contextlib.contextmanager
def named_on_failure(entity, handle: str = ""):
    """Turn any failure while reading an entity into a DxfError naming it, not a crash."""
    try:
        yield
    except DxfError:
        raise
    except Exception as failure:  # a broken entity of any kind: name it instead of crashing
        raise DxfError(f"{entity.dxftype()} {handle or entity.dxf.handle} on layer "
                       f"{entity.dxf.get('layer', '?')!r} cannot be read ({one_line(failure)}); "
                       "redraw or delete it") from None


def extrusion_sign(entity) -> int:
    """+1 / −1 for an entity in the XY plane (extrusion ±Z), 0 for any other plane."""
    ex, ey, ez = entity.dxf.get("extrusion", (0.0, 0.0, 1.0))
    if abs(ex) < PLANAR_EPSILON and abs(ey) < PLANAR_EPSILON:
        return 1 if ez > 0 else -1
    return 0


def ocs_point(x: float, y: float, sign: int) -> Point:
    """OCS → WCS (x, y) for extrusion (0,0,sign): the arbitrary-axis rule mirrors X for −Z."""
    return (x, y) if sign > 0 else (-x, y)


def polyline_of(points: list[Point], handle: str) -> Iterator[Line]:
    for start, end in zip(points, points[1:]):
        if math.dist(start, end) > DEGENERATE_LENGTH:
            yield Line(start, end, handle)


def flattened(entity, context: Context) -> Iterator[Line]:
    points = [(v.x, v.y) for v in entity.flattening(context.sagitta)]
    return polyline_of(points, context.handle or entity.dxf.handle)


def line_segments(entity, context: Context) -> Iterator[Segment]:
    start, end = entity.dxf.start, entity.dxf.end
    yield from polyline_of([(start.x, start.y), (end.x, end.y)], context.handle or entity.dxf.handle)


def arc_from_ocs(centre: Point, radius: float, start_deg: float, end_deg: float,
                 sign: int, handle: str) -> Arc:
    """An OCS arc (always counter-clockwise from start to end angle in its OCS) in WCS."""
    cx, cy = centre
    start = (cx + radius * math.cos(math.radians(start_deg)), cy + radius * math.sin(math.radians(start_deg)))
    end = (cx + radius * math.cos(math.radians(end_deg)), cy + radius * math.sin(math.radians(end_deg)))
    return Arc(ocs_point(*start, sign), ocs_point(*end, sign), ocs_point(cx, cy, sign), sign > 0, handle)


def arc_segments(entity, context: Context) -> Iterator[Segment]:
    sign, radius = extrusion_sign(entity), entity.dxf.radius
    if radius <= DEGENERATE_LENGTH:
        return
    if sign == 0:
        yield from flattened(entity, context)
        return
    centre, handle = (entity.dxf.center.x, entity.dxf.center.y), context.handle or entity.dxf.handle
    start_deg, end_deg = entity.dxf.start_angle % 360.0, entity.dxf.end_angle % 360.0
    if math.isclose(start_deg, end_deg, abs_tol=1e-9):
        yield from full_circle(centre, radius, sign, handle)
    else:
        yield arc_from_ocs(centre, radius, start_deg, end_deg, sign, handle)


def full_circle(centre: Point, radius: float, sign: int, handle: str) -> Iterator[Arc]:
    """Two half arcs, so the circle has end points that chaining can use."""
    yield arc_from_ocs(centre, radius, 0.0, 180.0, sign, handle)
    yield arc_from_ocs(centre, radius, 180.0, 360.0, sign, handle)


def circle_segments(entity, context: Context) -> Iterator[Segment]:
    sign, radius = extrusion_sign(entity), entity.dxf.radius
    if radius <= DEGENERATE_LENGTH:
        return
    if sign == 0:
        yield from flattened(entity, context)
        return
    centre = (entity.dxf.center.x, entity.dxf.center.y)
    yield from full_circle(centre, radius, sign, context.handle or entity.dxf.handle)


def bulge_segment(start: Point, end: Point, bulge: float, handle: str) -> Segment | None:
    """The segment from start to end with a polyline bulge (tan of a quarter of the included
    angle, positive = counter-clockwise); all points in the same 2D system."""
    chord = math.dist(start, end)
    if chord <= DEGENERATE_LENGTH:
        return None
    if abs(bulge) < 1e-12:
        return Line(start, end, handle)
    ux, uy = (end[0] - start[0]) / chord, (end[1] - start[1]) / chord
    offset = chord / 2.0 * (1.0 - bulge * bulge) / (2.0 * bulge)
    centre = ((start[0] + end[0]) / 2.0 - uy * offset, (start[1] + end[1]) / 2.0 + ux * offset)
    return Arc(start, end, centre, bulge > 0, handle)


def mirrored_x(segment: Segment) -> Segment:
    """A segment drawn in an OCS with extrusion −Z, brought to WCS (X mirrored, sense flipped)."""
    if isinstance(segment, Line):
        return Line(ocs_point(*segment.start, -1), ocs_point(*segment.end, -1), segment.handle)
    return Arc(ocs_point(*segment.start, -1), ocs_point(*segment.end, -1),
               ocs_point(*segment.centre, -1), not segment.ccw, segment.handle)


def bulged_path(vertices: list[tuple[float, float, float]], closed: bool, sign: int,
                handle: str) -> Iterator[Segment]:
    """Segments of a bulged vertex list (x, y, bulge) given in an OCS with extrusion ±Z."""
    pairs = list(zip(vertices, vertices[1:]))
    if closed and len(vertices) > 1:
        pairs.append((vertices[-1], vertices[0]))
    for (x0, y0, bulge), (x1, y1, _) in pairs:
        segment = bulge_segment((x0, y0), (x1, y1), bulge, handle)
        if segment is not None:
            yield segment if sign > 0 else mirrored_x(segment)


def lwpolyline_segments(entity, context: Context) -> Iterator[Segment]:
    sign = extrusion_sign(entity)
    if sign == 0:
        for part in entity.virtual_entities():
            yield from segments_of(part, context_for(context, entity))
        return
    # lwpoints rows: x, y, start width, end width, bulge (numpy floats: made Python floats once)
    vertices = [(float(row[0]), float(row[1]), float(row[4])) for row in entity.lwpoints]
    yield from bulged_path(vertices, entity.closed, sign, context.handle or entity.dxf.handle)


# POLYLINE vertex flag 16: a spline frame control point, not a point on the curve.
SPLINE_FRAME_CONTROL_POINT = 16


def polyline_segments(entity, context: Context) -> Iterator[Segment]:
    handle = context.handle or entity.dxf.handle
    if entity.is_polygon_mesh or entity.is_poly_face_mesh:
        return
    on_curve = [v for v in entity.vertices if not v.dxf.flags & SPLINE_FRAME_CONTROL_POINT]
    sign = extrusion_sign(entity)
    if entity.is_2d_polyline and sign != 0:
        vertices = [(v.dxf.location.x, v.dxf.location.y, v.dxf.bulge) for v in on_curve]
        yield from bulged_path(vertices, entity.is_closed, sign, handle)
        return
    if entity.is_2d_polyline:  # in a tilted plane: its WCS projection
        for part in entity.virtual_entities():
            yield from segments_of(part, context_for(context, entity))
        return
    points = [(v.dxf.location.x, v.dxf.location.y) for v in on_curve]
    if entity.is_closed and points:
        points.append(points[0])
    yield from polyline_of(points, handle)


def curve_segments(entity, context: Context) -> Iterator[Segment]:
    yield from flattened(entity, context)


def context_for(context: Context, source) -> Context:
    return Context(context.sagitta, context.handle or source.dxf.handle, context.reach)


HANDLERS: dict[str, Callable[..., Iterator[Segment]]] = {
    "LINE": line_segments,
    "ARC": arc_segments,
    "CIRCLE": circle_segments,
    "LWPOLYLINE": lwpolyline_segments,
    "POLYLINE": polyline_segments,
    "SPLINE": curve_segments,
    "ELLIPSE": curve_segments,
}


def inserted_entities(insert, layer: str, depth: int = 0) -> Iterator[tuple[str, object]]:
    """(effective layer, virtual entity) of a block reference, nested INSERTs exploded too."""
    if depth > MAX_BLOCK_NESTING:
        raise DxfError(f"INSERT {insert.dxf.handle}: blocks nested deeper than {MAX_BLOCK_NESTING} "
                       "levels (a block that contains itself?); explode it in the CAD program")
    references = insert.multi_insert() if insert.mcount > 1 else [insert]
    for reference in references:
        for entity in reference.virtual_entities():
            own = entity.dxf.layer
            effective = layer if own == "0" else own
            if entity.dxftype() == "INSERT":
                yield from inserted_entities(entity, effective, depth + 1)
            else:
                yield effective, entity


MAX_BLOCK_NESTING = 32
