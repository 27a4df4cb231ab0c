"""A LinuxCNC G70/G71/G72 profile and the passes made over it, ported from the class g7x of
LinuxCNC's src/emc/rs274ngc/interp_g7x.cc (LinuxCNC/linuxcnc 5c41560e, GPL-2.0; `cc NNN` names
its line; docs/reference/linuxcnc-lathe.md §5).

The profile is turned (G72: rotated 90° first) and mirrored so that X and Z fall along it
(swap), its fillets and chamfers placed, checked monotone, and moved a distance D normal to
itself (add_distance, a connecting arc at each outer corner). G71/G72 then cut levels I apart
from the start X, each a feed along Z to the profile and a retract R at 45°, pockets included
(type 0), left out (type 1, .1) or only them (type 2, .2); G70 follows the profile P times at
distances from D down to E. The moves go out mirrored back. Bounded: more than MAX_PASSES levels
or cuts, or an offset or a pocket walk that does not end, is refused (LinuxCNC's own issues #2844
and #2939 are such loops)."""
from __future__ import annotations

from collections.abc import Callable

import engine.verifier.expanders.cycles as iso_cycles

from .linuxcnc_g7x_segments import TOLERANCE, Cursor, G7xError, Output, Round, Segment, Straight

MAX_PASSES = iso_cycles.MAX_PASSES
MAX_OFFSET_STEPS = 10_000     # add_distance steps by at most half the shortest segment: a loop beyond is stuck
MAX_WALK = 200_000            # pocket() iterations: the walk along the profile of a loop that does not end
# the mirrored coordinates back to the program's, by flip state (cc 517-561): bit 1 Z mirrored, bit 2
# X mirrored, bit 4 turned 90° (G72); (map, whether an arc changes its sense)
MIRRORS: dict[int, tuple[Callable[[complex], complex], bool]] = {
    0: (lambda p: p, False), 1: (lambda p: -p.conjugate(), True), 2: (lambda p: p.conjugate(), True),
    3: (lambda p: -p, False), 4: (lambda p: 1j * p, False), 5: (lambda p: (1j * p).conjugate(), True),
    6: (lambda p: -(1j * p).conjugate(), True), 7: (lambda p: -1j * p, False)}


class Mirrored:
    """swapped_motion<flip_state>: the moves of the standard quadrant put back where they are cut."""
    def __init__(self, out: Output, state: int) -> None:
        self.out, (self.map, self.turns) = out, MIRRORS[state]

    def straight_move(self, end: complex) -> None:
        self.out.straight_move(self.map(end))

    def straight_rapid(self, end: complex) -> None:
        self.out.straight_rapid(self.map(end))

    def circular_move(self, ccw: bool, center: complex, end: complex) -> None:
        self.out.circular_move(ccw != self.turns, self.map(center), self.map(end))


class Profile(list[Segment]):
    def __init__(self, segments: list[Segment] | None = None, flip_state: int = 0) -> None:
        super().__init__(s.dup() for s in segments or [])
        self.flip_state, self.delta, self.escape = flip_state, 0.5, 0.3 + 0.3j
        self.pocket_starts: list[complex] = []
        self.levels = 0

    def copy(self) -> Profile:
        return Profile(self, self.flip_state)

    def rotate(self) -> None:              # cc 575
        for segment in self:
            segment.rotate()
        self.flip_state ^= 4

    def swap(self) -> None:                # cc 582: X and Z decreasing along the profile
        way = self[0].end - self[-1].end
        if way.imag > 0:
            for segment in self:
                segment.flip_imag()
            self.flip_state ^= 2
        if way.real < 0:
            for segment in self:
                segment.flip_real()
            self.flip_state ^= 1

    def monotonic(self) -> None:           # cc 611
        first = self[0]
        if (first.end - first.start).real > 0:
            first.start = complex(first.end.real, first.start.imag)
        if not all(segment.monotonic() for segment in self):
            raise G7xError("Not monotonic")

    def do_finish(self) -> None:           # cc 621
        for n in range(1, len(self) - 1):
            self[n].do_finish(self[n - 1], self[n + 1])
        self[:] = [segment for segment in self if segment.radius() >= 1e-3]

    def should_rotate_paths(self) -> bool:  # cc 631
        paths = self.copy()
        paths.pop(0)
        paths.swap()
        return any(not path.monotonic() for path in paths)

    def add_distance(self, distance: float) -> None:   # cc 844
        lead_in, across = self[0].end - self[0].start, self[-1].start - self[0].start
        if across != 0 and (lead_in / across).imag < 0:     # C++: a division by 0 gives NaN, never < 0
            distance = -distance
        first = self.pop(0)
        current, steps = 0.0, 0
        while current != distance:
            steps += 1
            if steps > MAX_OFFSET_STEPS or not self:
                raise G7xError(f"the offset D of the profile does not end in {MAX_OFFSET_STEPS:,} steps")
            step = min([segment.radius() / 2 for segment in self] + [1e9, abs(distance - current)])
            step = -step if distance < 0 else step
            self._offset_step(step, distance > 0)
            current += step
        for before, after in zip(self, self[1:]):
            before.end = after.start = (before.end + after.start) / 2.0
        first.end = self[0].start
        self.insert(0, first)

    def _offset_step(self, step: float, outward: bool) -> None:
        for segment in self:
            segment.offset(step)
        self[:] = [segment for segment in self if segment.radius() >= 1e-3]
        n = 0
        while n < len(self) - 1:            # an outer corner opens a gap: a connecting arc (cc 867)
            if (self[n].end - self[n + 1].start).real > 1e-2:
                back, ahead = self[n].dup(), self[n + 1].dup()
                back.offset(-step)
                ahead.offset(-step)
                self.insert(n + 1, Round(outward, self[n].end, (back.end + ahead.start) / 2.0, self[n + 1].start))
                n += 1
            n += 1
        self._trim()

    def _trim(self) -> None:                # cc 882-898
        n = 0
        while n < len(self) - 1:
            if not self[n].monotonic():
                if n == 0:
                    raise G7xError("the offset profile turns back at its first segment")
                del self[n if self[n].radius() < self[n - 1].radius() else n - 1]
                n = 0
            if n >= len(self) - 1:
                raise G7xError("the offset profile has no segment left to follow")
            if self[n].radius() < 1e-3:
                del self[n]
                n = 0
            else:
                self[n + 1].intersect_end(self[n])
            n += 1

    def finishing(self, out: Output, start: complex, distances: tuple[float, float], passes: int) -> None:
        """G70 (cc 660): P passes at (pass − 1)·(D − E)/P + E from the profile, each from the start."""
        self[0].start = start
        if self.should_rotate_paths():
            self.rotate()
        self.swap()
        self.do_finish()
        self.monotonic()
        mirrored = Mirrored(out, self.flip_state)
        d, e = distances
        for number in range(passes, 0, -1):
            paths = self.copy()
            paths.add_distance((number - 1) * (d - e) / passes + e)
            mirrored.straight_rapid(paths[0].start)
            mirrored.straight_rapid(paths[0].end)
            for path in paths[1:]:
                path.draw(mirrored)

    def roughing(self, out: Output, cycle: int, start: complex, words: tuple[float, ...], rotated: bool) -> None:
        """G71/G72 (cc 698): words (U, W, D, I, R); G72 is G71 on the profile turned 90°."""
        u, w, d, i, r = words
        self[0].start = start
        if rotated:
            self.rotate()
        self.swap()
        self.do_finish()
        self.monotonic()
        self.add_distance(d)
        for segment in self:
            segment.move(complex(w, u))
        mirrored = Mirrored(out, self.flip_state)
        self.delta, self.escape = max(i, 2 * TOLERANCE), r * (1 + 1j)
        mirrored.straight_rapid(self[0].start)
        if self[-1].end.imag < self[0].start.imag:
            self.append(Straight(self[-1].end, complex(self[-1].end.real, self[0].start.imag)))
        self.pocket_starts.append(self[0].start)
        self.pocket(cycle, Cursor(self[0].start), mirrored)

    def _lower(self, x: float) -> float:
        self.levels += 1
        if self.levels > MAX_PASSES:
            raise G7xError(f"more than {MAX_PASSES:,} levels of depth I")
        return x - self.delta

    def pocket(self, cycle: int, cursor: Cursor, out: Output) -> None:
        """cc 738: dive along the profile to each level, cut along Z to where the profile comes back
        up, retract; a climb out of a pocket starts the next pocket (the C++ recursion, as a loop)."""
        p, walked = 0, 0
        if cycle == 2:                      # skip the first roughing: cut only the pockets
            while p < len(self) and not self[p].dive(cursor, -1e9, out, p == 0):
                p += 1
            cycle = 3
        at: int | None = p
        while at is not None:
            at, _, walked = self._walk(cycle, cursor, out, (at, self.pocket_starts[-1].imag, walked))

    def _walk(self, cycle: int, cursor: Cursor, out: Output, state: tuple[int, float, int]
              ) -> tuple[int | None, float, int]:
        p, x, walked = state
        while p < len(self):
            walked += 1
            if walked > MAX_WALK:
                raise G7xError(f"the roughing walk does not end in {MAX_WALK:,} steps")
            while x - TOLERANCE > cursor.at.imag:
                x = self._lower(x)
            if self[p].dive(cursor, x, out, p == 0):
                return self._climb(cycle, cursor, out, p), x, walked
            if p == len(self) - 1:
                return None, x, walked
            if abs(cursor.at.imag - x) > TOLERANCE or self[p].end == cursor.at:
                p += 1
                continue
            p, x = self._cut(cursor, out, p, x)
        return None, x, walked

    def _climb(self, cycle: int, cursor: Cursor, out: Output, p: int) -> int | None:
        """cc 756-783: type 1 follows the profile to its end; else up to the next pocket's start."""
        for n in range(p, len(self)):
            if cycle == 1:
                self[n].climb_only(cursor, out)
            elif self[n].climb(cursor, out):
                if cycle == 3:
                    if cursor.at.imag > self.pocket_starts[-1].imag and len(self.pocket_starts) > 1:
                        self.pocket_starts.pop()
                    if len(self.pocket_starts) == 1:
                        self.pocket_starts.append(cursor.at)
                return n
        return None

    def _cut(self, cursor: Cursor, out: Output, p: int, x: float) -> tuple[int, float]:
        """cc 799-840: along Z at this level to the first segment met, retract R at 45°, back at rapid."""
        for ip in range(p, len(self)):
            found = self[ip].intersection_z(cursor.at.imag)
            if not found:
                continue
            z = found[0] if ip != p else found[-1]
            distance = abs(z - cursor.at.real)
            if z - TOLERANCE > cursor.at.real:
                continue
            if distance < TOLERANCE:
                if p == ip:
                    continue
                if abs(cursor.at - self[ip].start) < TOLERANCE:
                    return ip, x
                return p, self._lower(x)
            self._pass(cursor.at, complex(z, cursor.at.imag), distance, out, p == 0)
            return p, self._lower(x)
        return p, x

    def _pass(self, at: complex, end: complex, distance: float, out: Output, first: bool) -> None:
        out.straight_move(end)
        scale = 1.0 if self.escape.real == 0 else min(1.0, distance / 2 / self.escape.real)
        out.straight_rapid(end + scale * self.escape)
        out.straight_rapid(at - (scale * self.escape).conjugate())
        (out.straight_rapid if first else out.straight_move)(at)
