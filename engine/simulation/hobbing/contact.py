"""Where a move's hob poses meet the solids (engine.simulation.hobbing.solids), and whether that is
the intended cut. Intended: a G1 with the table coupled and the hob spindle turning, in a
unit whose teeth the coupling generates, never below its intended root (less TOLERANCE). The
gaps such cuts leave are free to the hob while the same coupling lasts (a coupled retract out
of its own gaps), except on a rapid along Z (engine.simulation.hobbing.walk). Anything else
that enters material is a collision, held to COLLISION_TOLERANCE between the sampled heights
and poses too (engine.simulation.hobbing.contact_bounds: convexity on a straight piece), except
in those own gaps and on a move that swivels the hob, where the samples are all that is
checked. Plain floats, pose by pose and height by height, for a process's first MATH_SECTIONS
sections (one gear's proof imports no numpy); engine.simulation.hobbing.contact_arrays follows
the rest by the same rules (issue 28)."""
from __future__ import annotations

import math
from bisect import bisect_left, bisect_right

import msgspec

from .contact_bounds import exact_collision
from .contact_records import COLLISION_TOLERANCE, TOLERANCE, Contact, Motion, contact_at, exact
from .envelope import HobBody, centres, nearest_radii
from .paths import corners, pieces_poses
from .solids import Solid

__all__ = ["TOLERANCE", "Contact", "Motion", "follow"]

MARGIN = 1e-6         # mm a move's bounding box is widened by against rounding (its poses are interpolated)
# Sections (one pose at one height) a process follows in plain floats before it imports numpy for
# the rest (engine.simulation.hobbing.contact_arrays, envelope_arrays): one gear takes a few
# thousand (gear 42 of the samples 4,051; bench/simulation.py's programs 7,800 on average), a
# batch hundreds of thousands. Break-even on the 2-core machine (bench/README.md, 2026-11-30): a
# program takes 3.5 µs per section in plain floats, 0.5 µs with numpy (3.0 µs saved); importing
# numpy and the array modules costs a simulating process about 85 ms of wall time and 190 ms of
# CPU (OpenBLAS starts a thread per core): 85 ms / 3.0 µs ≈ 28,000 sections by the clock,
# 190 ms / 3.0 µs ≈ 63,000 in CPU, where whole processes of N sections (plain throughout against
# numpy from the first) crossed. Set between the two: a process of 28,000 to 40,000 sections
# takes up to 36 ms (12,000 × 3.0 µs) longer than with numpy from the start, and less CPU.
MATH_SECTIONS = 40_000
_followed = [0]       # sections followed by this process so far


def follow(solids: list[Solid], hob: HobBody, swivel: float, pieces: list, motion: Motion) -> list[Contact]:
    """Every solid the hob meets on the move's straight pieces (engine.simulation.hobbing.paths:
    machine positions, DIN) against the rules above; the intended cuts recorded in the units'
    reach. A solid the move's bounding box keeps clear of the hob is passed over before any pose
    is worked out (most are: the fixture and the tailstock on nearly every move, the blank on
    the approach)."""
    x, y, z = corners(pieces)
    box = Box.of(x, y, z, hob, swivel)
    near = [solid for solid in solids if (motion.tailstock or not solid.clamped_only) and box.reaches(solid)]
    if not near:
        return []
    if _followed[0] > MATH_SECTIONS:
        from .contact_arrays import meet_all
        return meet_all(near, hob, swivel, pieces, motion)
    sampled = [solid for solid in near if not exact(solid, motion)]
    poses = [centres(px, py, pz, swivel) for px, py, pz in zip(*pieces_poses(pieces))] if sampled else []
    found = (_meet(solid, hob, swivel, poses, motion) if solid in sampled
             else exact_collision(solid, hob, swivel, pieces, _followed) for solid in near)
    return [contact for contact in found if contact is not None]


class Box(msgspec.Struct, frozen=True):
    """The least hob centre X of a move's poses and the heights its hob spans (mm, DIN): the poses
    lie on straight pieces between the given positions, so their least and greatest values bound
    them; the centre's Z is Z + Y·sin A, bounded by the extremes of each term."""
    x_low: float
    z_low: float
    z_high: float
    radius: float

    @classmethod
    def of(cls, x, y, z, hob: HobBody, swivel: float) -> Box:
        sine = math.sin(math.radians(swivel))
        shifts = (min(y) * sine, max(y) * sine)
        extent = hob.extent(swivel)
        return cls(min(x), min(z) + min(shifts) - extent, max(z) + max(shifts) + extent, hob.radius)

    def reaches(self, solid: Solid) -> bool:
        """The tests of _spans, for the whole move at once (with a micrometre's margin for rounding)."""
        return (self.x_low - self.radius < solid.largest_radius + TOLERANCE and self.z_high + MARGIN >= solid.z_low
                and self.z_low - MARGIN <= solid.z_high)


def _meet(solid: Solid, hob: HobBody, swivel: float, poses: list, motion: Motion) -> Contact | None:
    """The poses near the solid, each with the heights of the solid its extent spans, measured."""
    spans = list(_spans(solid, hob.extent(swivel), hob.radius, poses))
    if not spans:
        return None
    _followed[0] += sum(last - first for *_, first, last in spans)
    radii = [(first, nearest_radii(hob, swivel, cx, cy, cz, solid.heights[first:last]))
             for cx, cy, cz, first, last in spans]
    if motion.cutting_teeth is not None and solid.teeth == motion.cutting_teeth:
        return _cut(solid, motion, radii)
    return _collision(solid, motion, radii)


def _spans(solid: Solid, extent: float, radius: float, poses: list):
    """(cx, cy, cz, first, last) of each pose within reach of the solid: the indices of its
    heights from first to before last lie within the hob's extent along Z."""
    largest = solid.largest_radius
    for cx, cy, cz in poses:
        if cx - radius < largest + TOLERANCE and cz + extent >= solid.z_low and cz - extent <= solid.z_high:
            first, last = bisect_left(solid.heights, cz - extent), bisect_right(solid.heights, cz + extent)
            if last > first:
                yield cx, cy, cz, first, last


def _cut(solid: Solid, motion: Motion, radii: list) -> Contact | None:
    """Records the cut in the unit's reach (radii: per pose, the first height index and the
    distances from there); the deepest point below the intended root, if any."""
    solid.start_session(motion.session)
    root, blank, reach, session_reach = solid.intended_root, solid.radius, solid.reach, solid.session_reach
    assert root is not None   # a unit the hob cuts has its intended root
    deepest, at, entered = TOLERANCE, -1, False
    for index, found in radii:
        for radius in found:
            if radius < reach[index]:
                reach[index] = radius
            if radius < session_reach[index]:
                session_reach[index] = radius
            entered = entered or radius < blank[index] - TOLERANCE
            if root[index] - radius > deepest:
                deepest, at = root[index] - radius, index
            index += 1
    if entered:
        solid.cut_sessions.add(motion.session)
    return contact_at(solid, deepest, at, True)


def _collision(solid: Solid, motion: Motion, radii: list) -> Contact | None:
    """The deepest point inside the solid deeper than COLLISION_TOLERANCE (mm), where it is not a
    gap this coupling cut."""
    own_gaps = motion.coupled_running and solid.session == motion.session
    blank, session_reach = solid.radius, solid.session_reach
    deepest, at = COLLISION_TOLERANCE, -1
    for index, found in radii:
        for radius in found:
            if blank[index] - radius > deepest and not (own_gaps and radius >= session_reach[index] - TOLERANCE):
                deepest, at = blank[index] - radius, index
            index += 1
    return contact_at(solid, deepest, at, False)
