"""Where a move's hob poses meet the solids (engine.simulation.hobbing.solids), and whether that is
the intended cut. Intended: a G1 with the table coupled and the hob spindle turning, in a
unit whose teeth the coupling generates, never below its intended root (less TOLERANCE). The
gaps such cuts leave are free to the hob while the same coupling lasts (a coupled retract out
of its own gaps), except on a rapid along Z (engine.simulation.hobbing.walk). Anything else that enters
material is a collision. Plain floats, pose by pose and height by height (issue 28: no numpy)."""
from __future__ import annotations

from bisect import bisect_left, bisect_right
from dataclasses import dataclass

from .envelope import HobBody, centres, nearest_radii
from .solids import Solid

TOLERANCE = 0.01      # mm: below the root, or into material, before it counts
# Sections (one pose at one height) a process follows in plain floats before it imports numpy for
# the rest (engine.simulation.hobbing.envelope_arrays): one gear takes a few thousand (gear 42 of
# the samples 4,300), a batch hundreds of thousands; in plain floats each costs about 5 µs more, so
# this many cost about what importing numpy does (0.1 s)
MATH_SECTIONS = 20_000
_followed = [0]       # sections followed by this process so far


@dataclass(frozen=True, slots=True)
class Motion:
    """What the hob is doing on a move: which teeth it cuts (None: not an intended cut), whether
    the coupling is on with the spindle turning (its own gaps are free), in which coupling
    session, with the tailstock clamped or not, and why it is not a cut (for the message)."""
    cutting_teeth: int | None
    coupled_running: bool
    session: int
    tailstock: bool
    reason: str


@dataclass(frozen=True, slots=True)
class Contact:
    solid: Solid
    depth: float          # mm
    height: float         # DIN Z where it is deepest
    below_root: bool      # an intended cut below the root (else a collision)


def follow(solids: list[Solid], hob: HobBody, swivel: float, x, y, z, motion: Motion) -> list[Contact]:
    """Every solid the poses (sequences x, y, z: machine positions, DIN) meet against the rules
    above; the intended cuts recorded in the units' reach."""
    poses = [centres(float(px), float(py), float(pz), swivel) for px, py, pz in zip(x, y, z)]
    contacts = []
    for solid in solids:
        if solid.clamped_only and not motion.tailstock:
            continue
        found = _meet(solid, hob, swivel, poses, motion)
        if found is not None:
            contacts.append(found)
    return contacts


def _meet(solid: Solid, hob: HobBody, swivel: float, poses: list, motion: Motion) -> Contact | None:
    """The poses near the solid, each with the heights of the solid its extent spans, measured."""
    spans = list(_spans(solid, hob.extent(swivel), hob.radius, poses))
    if not spans:
        return None
    radii = [(span[3], found) for span, found in zip(spans, _span_radii(solid, hob, swivel, spans))]
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


def _span_radii(solid: Solid, hob: HobBody, swivel: float, spans: list) -> list[list[float]]:
    """The least distance of the hob from the work axis at each height of each span: in plain
    floats for a process's first MATH_SECTIONS sections, then with numpy."""
    _followed[0] += sum(last - first for *_, first, last in spans)
    if _followed[0] > MATH_SECTIONS:
        from .envelope_arrays import span_radii
        return span_radii(hob, swivel, spans, solid.heights)
    return [nearest_radii(hob, swivel, cx, cy, cz, solid.heights[first:last]) for cx, cy, cz, first, last in spans]


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
    return _contact(solid, deepest, at, True)


def _collision(solid: Solid, motion: Motion, radii: list) -> Contact | None:
    """The deepest point inside the solid, where it is not a gap this coupling cut."""
    own_gaps = motion.coupled_running and solid.session == motion.session
    blank, session_reach = solid.radius, solid.session_reach
    deepest, at = TOLERANCE, -1
    for index, found in radii:
        for radius in found:
            if blank[index] - radius > deepest and not (own_gaps and radius >= session_reach[index] - TOLERANCE):
                deepest, at = blank[index] - radius, index
            index += 1
    return _contact(solid, deepest, at, False)


def _contact(solid: Solid, depth: float, at: int, below_root: bool) -> Contact | None:
    """The deepest point (the first pose and lowest height of equal depths), or None (at -1)."""
    if at < 0:
        return None
    return Contact(solid, depth, solid.heights[at], below_root)
