"""Which reading of the profile layer makes the part: a half-profile in the seed-000
convention (profile), or a side view drawn whole (side_view), or a half-profile with a
vertical axis (vertical, issue 27), or neither, said by name (issue 17).

A view a centre line runs through is a side view. Otherwise the layer is read as a
half-profile as before; only when that fails is it tried as a side view symmetric about
the middle of its extents, and a layer that is neither, made of closed outlines some of
which lie inside others, is refused as the flat part (a plate) it is.
"""
from __future__ import annotations

from .geometry import Segment
from .profile import END_MATCH_TOLERANCE_MM, Chain, Profile, chain_segments, find_profile, merged_bounds
from .read import DxfError
from .side_view import Marks, side_view, side_view_of, symmetry_axis
from .vertical import vertical_profile

HATCH_FLATTENING = 0.01   # drawing units: hatching only tells where material is, not its edge


def hatch_polygons(hatch) -> list[list[tuple[float, float]]]:
    """The boundary loops of a HATCH as point lists (drawing units, WCS)."""
    from ezdxf import path

    return [[(v.x, v.y) for v in loop.flattening(HATCH_FLATTENING)] for loop in path.from_hatch(hatch)]


def profile_of(segments: list[Segment], marks: Marks, layer: str) -> tuple[Profile, list[str], list[Chain]]:
    """(profile, notes, chains of the layer): notes are non-empty exactly for a side view or a
    vertical axis (a reading other than seed-000's half-profile on drawing Y 0)."""
    found = side_view_of(segments, marks, layer)
    if found is not None:
        return found.profile, found.notes, []
    chains = chain_segments(segments)
    try:
        profile = find_profile(chains, layer=layer)
    except DxfError as refusal:
        axis = symmetry_axis(segments)
        if axis is None:
            vertical = None if plate_refusal(chains, layer) else vertical_profile(segments, layer)
            if vertical is not None:
                return vertical.profile, vertical.notes, []
            raise plate_refusal(chains, layer) or refusal from None
        found = side_view(axis, segments, marks, f"layer {layer}")
        return found.profile, found.notes, []
    check_not_a_view_off_the_axis(profile, segments, layer)
    return profile, [], chains


def check_not_a_view_off_the_axis(profile: Profile, segments: list[Segment], layer: str) -> None:
    """A closed outline away from drawing Y 0 and symmetric (about a line of either direction)
    reads two ways: a ring's section in the seed-000 convention (radius = drawing Y) or the whole
    side view of a part drawn off Y 0 without its centre line. Which part it is, the drawing does
    not say, so neither is made."""
    if profile.closed_by_axis or profile.bounds[2] <= END_MATCH_TOLERANCE_MM:
        return
    axis = symmetry_axis(segments)
    if axis is None:
        return
    z_min, z_max, low, high = profile.bounds
    side = "below" if profile.mirrored else "above"
    raise DxfError(f"layer {layer}: its closed outline lies {side} drawing Y 0 "
                   f"(radius {low:g} … {high:g}, Z{z_min:g} … "
                   f"Z{z_max:g}) and is symmetric about {axis.source}: as drawn (radius = drawing Y) it is a ring's "
                   f"section with a bore Ø{2 * low:g}, and internal turning is not supported; as a whole side view "
                   "drawn off Y 0 it lacks its centre line; draw the part's half-profile on Y 0, or a centre line "
                   "on its axis")


def plate_refusal(chains: list[Chain], layer: str) -> DxfError | None:
    """A layer of closed outlines, some inside others, and no axis: a plate with holes or pockets."""
    closed = [chain for chain in chains if chain.closed]
    inside = sum(1 for chain in closed if any(other is not chain and encloses(other, chain) for other in closed))
    if len(closed) < 2 or not inside or len(closed) < 0.5 * len(chains):
        return None
    return DxfError(f"layer {layer} is not a turned part: {len(closed)} closed outlines, {inside} of them inside "
                    "another (holes or pockets of a flat part, a plate), no half-profile on the axis and no side "
                    "view symmetric about a centre line; a lathe job needs the turned part's profile")


def encloses(outer: Chain, inner: Chain) -> bool:
    a, b = merged_bounds(outer.segments), merged_bounds(inner.segments)
    return a[0] < b[0] and b[1] < a[1] and a[2] < b[2] and b[3] < a[3]
