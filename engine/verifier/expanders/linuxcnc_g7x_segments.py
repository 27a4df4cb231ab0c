"""The segments of a LinuxCNC G70/G71/G72 profile, ported from LinuxCNC's own code
(src/emc/rs274ngc/interp_g7x.cc, LinuxCNC/linuxcnc 5c41560e, GPL-2.0; docs/reference/
linuxcnc-lathe.md §5): a point is a complex number Z + iX (X a radius, mm), as there.

A straight or an arc (G3 counterclockwise in that plane) knows where a level X = x meets it
(intersection_z), how the roughing tool dives along it to a level, climbs along it out of a pocket,
is offset by a distance normal to itself and is cut short where it meets its neighbour; a fillet
(A) or a chamfer (C) is an arc or a straight fitted between its neighbours (corner_finish). Every
rule, tolerance and error text is LinuxCNC's; a line number `cc NNN` names the line of that file."""
from __future__ import annotations

import copy
import math
from typing import Protocol

TOLERANCE = 1e-6        # cc 43


class G7xError(ValueError):
    """LinuxCNC's `throw(std::string)` in the G7x code: the control stops with "G7X error: …"."""


class Output(Protocol):
    def straight_move(self, end: complex) -> None: ...
    def straight_rapid(self, end: complex) -> None: ...
    def circular_move(self, ccw: bool, center: complex, end: complex) -> None: ...


class Cursor:
    """Where the tool stands (LinuxCNC passes `location` by reference)."""
    def __init__(self, at: complex) -> None:
        self.at = at


def _norm(value: complex) -> float:
    return value.real ** 2 + value.imag ** 2


class Segment:
    finish = 0.0                       # the fillet/chamfer size A/C until do_finish places it

    def __init__(self, start: complex, end: complex) -> None:
        self.start, self.end = start, end

    def dup(self) -> Segment:
        return copy.copy(self)

    def monotonic(self) -> bool:       # cc 65: Z does not grow along the segment
        return (self.end - self.start).real <= 1e-3

    def do_finish(self, prev: Segment, nxt: Segment) -> None:
        return None

    def flip_imag(self) -> None:
        self.start, self.end = self.start.conjugate(), self.end.conjugate()

    def flip_real(self) -> None:
        self.start, self.end = -self.start.conjugate(), -self.end.conjugate()

    def rotate(self) -> None:
        self.start, self.end = -self.start * 1j, -self.end * 1j

    def move(self, by: complex) -> None:
        self.start, self.end = self.start + by, self.end + by

    def corner_finish(self, prev: Segment, nxt: Segment) -> complex:
        """cc 80-102: the neighbours offset by the finish size meet at the fillet's centre."""
        before, after = self._offset_pair(prev, nxt, self.finish)
        if (before.end - after.start).real > 1e-2:
            self.finish = -self.finish
            before, after = self._offset_pair(prev, nxt, self.finish)
        if (before.end - after.start).real > 1e-2:
            raise G7xError(f"Corner finish failed at {prev.end}")
        after.intersect_end(before)
        center = (before.end + after.start) / 2.0
        before.offset(-self.finish)
        after.offset(-self.finish)
        self.start = prev.end = before.end
        self.end = nxt.start = after.start
        return center

    @staticmethod
    def _offset_pair(prev: Segment, nxt: Segment, distance: float) -> tuple[Segment, Segment]:
        before, after = prev.dup(), nxt.dup()
        before.offset(distance)
        after.offset(distance)
        return before, after

    # each kind's own rules
    def intersection_z(self, x: float) -> list[float]: raise NotImplementedError
    def climb(self, cursor: Cursor, out: Output) -> bool: raise NotImplementedError
    def dive(self, cursor: Cursor, x: float, out: Output, fast: bool) -> bool: raise NotImplementedError
    def climb_only(self, cursor: Cursor, out: Output) -> None: raise NotImplementedError
    def draw(self, out: Output) -> None: raise NotImplementedError
    def offset(self, distance: float) -> None: raise NotImplementedError
    def intersect_end(self, prev: Segment) -> None: raise NotImplementedError
    def radius(self) -> float: raise NotImplementedError


class Straight(Segment):
    def intersection_z(self, x: float) -> list[float]:          # cc 130
        s, e = self.start, self.end
        if min(s.imag, e.imag) > x + TOLERANCE or max(s.imag, e.imag) < x - TOLERANCE:
            return []
        if abs((s - e).imag) < TOLERANCE:
            return [s.real, e.real]
        return [(x - s.imag) / (e.imag - s.imag) * (e.real - s.real) + s.real]

    def climb(self, cursor: Cursor, out: Output) -> bool:        # cc 144
        if self.end.imag + TOLERANCE < self.start.imag:
            return True
        if abs(cursor.at - self.start) > TOLERANCE:
            raise G7xError("How did we get here?")
        out.straight_move(self.end)
        cursor.at = self.end
        return False

    def climb_only(self, cursor: Cursor, out: Output) -> None:   # cc 156
        if self.end.imag < self.start.imag:
            return
        found = self.intersection_z(cursor.at.imag)
        if not found:
            return
        cursor.at = complex(found[0], cursor.at.imag)
        out.straight_move(cursor.at)
        out.straight_move(self.end)
        cursor.at = self.end

    def dive(self, cursor: Cursor, x: float, out: Output, fast: bool) -> bool:   # cc 173
        if self.start.imag <= self.end.imag + TOLERANCE:
            return True
        target = self.end
        if x >= self.end.imag:
            found = self.intersection_z(x)
            if not found:
                raise G7xError("x too large in straight dive")
            target = complex(found[0], x)
        (out.straight_rapid if fast else out.straight_move)(target)
        cursor.at = target
        return False

    def draw(self, out: Output) -> None:
        out.straight_move(self.end)

    def offset(self, distance: float) -> None:                  # cc 116
        shift = 1j * distance * (self.start - self.end) / abs(self.start - self.end)
        self.start, self.end = self.start + shift, self.end + shift

    def radius(self) -> float:
        return abs(self.start - self.end)

    def intersect_end(self, prev: Segment) -> None:
        """Cut `prev`'s end and this start where they meet (cc 406, 420)."""
        if isinstance(prev, Round):
            self._after_arc(prev)
            return
        rot = (self.start - self.end).conjugate() / abs(self.start - self.end)
        ps, pe = (prev.start - self.end) * rot, (prev.end - self.end) * rot
        if (ps - pe).imag == 0:
            raise G7xError("Cannot intersect parallel lines")
        f = ps.imag / (ps - pe).imag
        self.start = prev.end = (ps + f * (pe - ps)) / rot + self.end

    def _after_arc(self, prev: Round) -> None:
        if abs(self.start - prev.end) < TOLERANCE:
            return
        rot = (self.start - self.end).conjugate() / abs(self.start - self.end)
        self.start = prev.end = _nearest(self.start, (prev.end - self.end) * rot, (prev.center - self.end) * rot,
                                         rot, self.end)


def _nearest(near: complex, pe: complex, pc: complex, rot: complex, origin: complex) -> complex:
    """Of the two points where the line meets the circle (cc 431-443), the one nearer `near`."""
    b = _norm(pc - pe) - pc.imag * pc.imag
    b = 0.0 if b < 0 else math.sqrt(b)
    s1, s2 = (pc.real + b) / rot + origin, (pc.real - b) / rot + origin
    return s1 if abs(near - s1) < abs(near - s2) else s2


class Round(Segment):
    def __init__(self, ccw: bool, start: complex, center: complex, end: complex) -> None:
        super().__init__(start, end)
        self.ccw, self.center = ccw, center

    def radius(self) -> float:
        return min(abs(self.start - self.end), abs(self.start - self.center))

    def flip_imag(self) -> None:
        super().flip_imag()
        self.ccw, self.center = not self.ccw, self.center.conjugate()

    def flip_real(self) -> None:
        super().flip_real()
        self.ccw, self.center = not self.ccw, -self.center.conjugate()

    def rotate(self) -> None:
        super().rotate()
        self.center = -self.center * 1j

    def move(self, by: complex) -> None:
        super().move(by)
        self.center += by

    def monotonic(self) -> bool:                                # cc 243
        if self.finish != 0:
            return True
        entry, exit_ = (self.start - self.center).imag, (self.end - self.center).imag
        dz = (self.end - self.start).real
        if self.ccw:
            return entry >= -1e-3 and exit_ >= -1e-3 and dz <= -1e-3
        return entry <= 1e-3 and exit_ <= 1e-3 and dz <= -1e-3

    def on_segment(self, p: complex) -> bool:                    # cc 261
        a = ((self.start - self.center).conjugate() * (p - self.center)).imag
        b = ((self.end - self.center).conjugate() * (p - self.center)).imag
        if self.ccw:
            return a >= -TOLERANCE and b <= TOLERANCE
        return a <= TOLERANCE and b >= -TOLERANCE

    def intersection_z(self, x: float) -> list[float]:          # cc 271
        r = abs(self.start - self.center)
        s = -(x - r - self.center.imag) * (x + r - self.center.imag)
        if s < -TOLERANCE:
            return []
        s = math.sqrt(max(s, 0.0))
        return [p.real for p in (complex(self.center.real + s, x), complex(self.center.real - s, x))
                if self.on_segment(p)]

    def _top(self) -> complex:
        """A G3 climbing past its top stops there (cc 301-305)."""
        if self.end.real < self.center.real:
            return complex(self.center.real, self.center.imag + abs(self.start - self.center))
        return self.end

    def climb(self, cursor: Cursor, out: Output) -> bool:        # cc 288
        if not self.ccw:
            if cursor.at.real > self.center.real:
                return True
            if abs(cursor.at - self.end) > 1e-3:
                out.circular_move(False, self.center, self.end)
            cursor.at = self.end
            return False
        if cursor.at.real < self.center.real:
            return True
        top = self._top()
        if abs(cursor.at - top) > 1e-3:
            out.circular_move(True, self.center, top)
        cursor.at = top
        return True

    def dive(self, cursor: Cursor, x: float, out: Output, fast: bool) -> bool:   # cc 313
        if abs(cursor.at - self.end) < TOLERANCE or (cursor.at - self.end).real <= TOLERANCE:
            cursor.at = self.end
            return False
        found = self.intersection_z(x) or self.intersection_z(x - TOLERANCE)
        if self.ccw:
            if cursor.at.real - TOLERANCE > self.center.real:
                return True
            target = self.end if not found or found[-1] > self.center.real else complex(found[-1], x)
        else:
            if cursor.at.real <= self.center.real:
                return True
            if found and found[0] < self.center.real:
                return False             # the back side only: the pocket loop lowers x
            target = complex(found[0], x) if found else self.end
        out.circular_move(self.ccw, self.center, target)
        cursor.at = target
        return False

    def climb_only(self, cursor: Cursor, out: Output) -> None:   # cc 361
        found = self.intersection_z(cursor.at.imag)
        if not found:
            return
        if not self.ccw:
            if found[-1] > self.center.real:
                return
            cursor.at = complex(found[-1], cursor.at.imag)
            out.straight_move(cursor.at)
            if abs(cursor.at - self.end) > 1e-3:
                out.circular_move(False, self.center, self.end)
            cursor.at = self.end
            return
        if found[0] < self.center.real:
            return
        cursor.at = complex(found[0], cursor.at.imag)
        out.straight_move(cursor.at)
        top = self._top()
        if abs(cursor.at - top) > 1e-3:
            out.circular_move(True, self.center, top)
        cursor.at = top

    def draw(self, out: Output) -> None:
        out.circular_move(self.ccw, self.center, self.end)

    def offset(self, distance: float) -> None:                  # cc 220
        r = abs(self.start - self.center)
        factor = (r + (1 if self.ccw else -1) * distance) / r
        self.start = factor * (self.start - self.center) + self.center
        self.end = factor * (self.end - self.center) + self.center

    def intersect_end(self, prev: Segment) -> None:
        if isinstance(prev, Round):                              # cc 472
            a, b = abs(self.start - self.center), abs(prev.start - prev.center)
            c = abs(self.center - prev.center)
            cos_b = (c * c + a * a - b * b) / 2.0 / a / c
            rot = complex(cos_b, math.sqrt(1 - min(cos_b * cos_b, 1.0)))
            self.start = prev.end = rot * (prev.center - self.center) / c * a + self.center
            return
        if abs(self.start - prev.end) < TOLERANCE:               # cc 446
            return
        rot = (prev.start - prev.end).conjugate() / abs(prev.start - prev.end)
        self.start = prev.end = _nearest(self.start, (self.end - prev.end) * rot, (self.center - prev.end) * rot,
                                         rot, prev.end)


class Fillet(Round):
    """A on a profile line: an arc of radius A at its end (cc 490)."""
    def __init__(self, size: float, at: complex) -> None:
        super().__init__(False, at, at, at)
        self.finish = size

    def do_finish(self, prev: Segment, nxt: Segment) -> None:
        self.center = self.corner_finish(prev, nxt)
        self.ccw = (self.start - self.center).imag > 0 or (self.end - self.center).imag > 0
        self.finish = 0.0


class Chamfer(Straight):
    """C on a profile line: a straight with the fillet's end points (cc 503)."""
    def __init__(self, size: float, at: complex) -> None:
        super().__init__(at, at)
        self.finish = size

    def do_finish(self, prev: Segment, nxt: Segment) -> None:
        self.corner_finish(prev, nxt)
