"""What a turning tool from outside can make: a solid of revolution whose every cross-section
at one Z is a single span from the axis up to the surface.

The tools of these jobs come from outside and move in the (Z, X) plane; the holder stands
above the cutting edge. So at every Z the part must be material from the axis up to one
radius, and that radius is the surface the tool turns. Two shapes break this, and a job
that ignored them would be a different part:

* a bore: at some Z the material starts above the axis (a closed section drawn off the axis
  is a ring; a bore needs internal turning, which these templates do not do);
* an undercut: at some Z there is a gap in the material under material at a larger radius
  (a pocket under a collar); the tool cannot be in the gap without its holder cutting
  through the collar.

The check slices the closed outline (its flattened edges) at the middle of every span between
consecutive corner Zs: between corners every edge is straight and none is vertical, so the
section there is the same all along the span.
"""
from __future__ import annotations

from collections.abc import Sequence

import msgspec

from ..drawings.profile import END_MATCH_TOLERANCE_MM
from ..errors import EngineError
from .region import CHORD_TOLERANCE_MM, Edge

# Drawing noise, not geometry: a bore or gap thinner than this, or an undercut shorter in Z.
DRAWING_TOLERANCE_MM = END_MATCH_TOLERANCE_MM + CHORD_TOLERANCE_MM


class Slice(msgspec.Struct, frozen=True):
    """The material between two Zs: spans (bottom, top) in radius, in increasing radius."""
    z_low: float
    z_high: float
    spans: tuple[tuple[float, float], ...]


def crossings(edges: Sequence[Edge], z: float) -> list[float]:
    """Radii where the vertical line at z crosses the edges (z at no corner), in increasing radius."""
    found = []
    for (z0, r0), (z1, r1) in edges:
        if (z0 < z) != (z1 < z):
            found.append(r0 + (z - z0) * (r1 - r0) / (z1 - z0))
    return sorted(found)


def material_spans(radii: list[float]) -> tuple[tuple[float, float], ...]:
    """Even-odd pairs of crossings; spans whose gap is drawing noise are joined."""
    spans: list[tuple[float, float]] = []
    for bottom, top in zip(radii[::2], radii[1::2]):
        if spans and bottom - spans[-1][1] <= DRAWING_TOLERANCE_MM:
            spans[-1] = (spans[-1][0], top)
        else:
            spans.append((bottom, top))
    return tuple(spans)


def slices(edges: Sequence[Edge]) -> list[Slice]:
    """The outline's material between consecutive corner Zs, in increasing Z."""
    corners = sorted({z for edge in edges for z, _ in edge})
    ordered = sorted(edges, key=lambda edge: min(edge[0][0], edge[1][0]))
    found, active, next_edge = [], [], 0
    for z_low, z_high in zip(corners, corners[1:]):
        middle = (z_low + z_high) / 2.0
        while next_edge < len(ordered) and min(ordered[next_edge][0][0], ordered[next_edge][1][0]) < middle:
            active.append(ordered[next_edge])
            next_edge += 1
        active = [edge for edge in active if max(edge[0][0], edge[1][0]) > middle]
        found.append(Slice(z_low, z_high, material_spans(crossings(active, middle))))
    return found


def z_ranges(flagged: list[Slice]) -> list[tuple[float, float]]:
    """Adjacent slices joined into Z ranges."""
    ranges: list[tuple[float, float]] = []
    for piece in flagged:
        if ranges and abs(ranges[-1][1] - piece.z_low) <= DRAWING_TOLERANCE_MM:
            ranges[-1] = (ranges[-1][0], piece.z_high)
        else:
            ranges.append((piece.z_low, piece.z_high))
    return ranges


def is_bored(piece: Slice) -> bool:
    return bool(piece.spans) and piece.spans[0][0] > DRAWING_TOLERANCE_MM


def is_undercut(piece: Slice) -> bool:
    return len(piece.spans) > 1


def check_turnable_from_outside(edges: Sequence[Edge], part: str) -> None:
    """EngineError naming the Z range of a bore or an undercut of the part's outline (module doc);
    `part` names the profile in the message (the drawing)."""
    pieces = slices(edges)
    bored = [piece for piece in pieces if is_bored(piece)]
    if bored:
        raise EngineError(bore_message(bored, part))
    undercut = [r for r in z_ranges([piece for piece in pieces if is_undercut(piece)])
                if r[1] - r[0] > DRAWING_TOLERANCE_MM]
    if undercut:
        raise EngineError(undercut_message(undercut, pieces, part))


def bore_message(bored: list[Slice], part: str) -> str:
    smallest, largest = (2.0 * f(piece.spans[0][0] for piece in bored) for f in (min, max))
    one = largest - smallest <= 2 * DRAWING_TOLERANCE_MM
    diameters = f"Ø{smallest:.6g}" if one else f"Ø{smallest:.6g} … Ø{largest:.6g}"
    where = ", ".join(f"Z{low:g} … Z{high:g}" for low, high in z_ranges(bored))
    return (f"{part} is a part with a bore {diameters} at {where} (its section does not reach the axis "
            "there): internal turning is not supported; to turn the outside only, draw its half-profile "
            "closed by the axis (drawing Y = 0)")


def undercut_message(undercut: list[tuple[float, float]], pieces: list[Slice], part: str) -> str:
    low, high = undercut[0]
    over = [piece.spans for piece in pieces if low <= piece.z_low and piece.z_high <= high]
    gap = (min(spans[-2][1] for spans in over), max(spans[-1][0] for spans in over))
    collar_top = max(spans[-1][1] for spans in over)
    more = f" (and {len(undercut) - 1} more)" if len(undercut) > 1 else ""
    return (f"{part} has an undercut at Z{low:g} … Z{high:g}{more}: a gap at radius {gap[0]:.6g} … {gap[1]:.6g} "
            f"under the collar up to radius {collar_top:.6g}, where an external tool cannot reach; "
            "draw the part as turned from outside (the undercut made by another operation or machine)")
