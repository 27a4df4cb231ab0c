"""The material walk: the (z, r) half-plane (r ≥ 0) holds the blank minus what the tool has
removed; the finished part (never to be cut) lies inside it. Every move of the program is
followed in order (shapely geometry):

* a rapid (G0/G00) must run through air: one that runs more than AIR_TOLERANCE_MM through the
  material left or the part is refused (a rapid into material breaks the tool or the machine);
  behind a stored blank's back end (params.stock_z_back) the bar runs on into the chuck at the
  blank's radius (bar_behind): it is material too;
* a cut behind a stored blank's back end by more than the run-out (the job's params.clearance, the
  overtravel the planner gives a pass at either end, at most run.BEHIND_RUN_OUT_MM) is refused
  unless its operation is PART (parting off at the back end): it would cut the bar that holds the part;
* a cut (G1/G2/G3, a thread pass G32/G33) must not enter the finished part by more than
  CUT_TOLERANCE_MM; a thread pass must touch the drawn thread (its THREAD operation's crest and
  root lines) and may run inside the part only between the root's and the crest's radius, over
  the drawn thread and its run-in from where the pass starts (a thread is cut from the part's
  free end, design notes §8), never on past the drawn thread's far end; the thread's groove
  is air for the rapid that pulls the tool out;
* what a cut removes: an outside tool's body stands radially above its tip, so the column
  above the path is air afterwards (a plunge removes its own line), widened by AIR_TOLERANCE_MM
  so a rapid back up the line a plunge just fed runs in air — as design notes §8 model the chip.

The section is drawn on both sides of the axis (work.whole), so a cut along the axis runs inside
the part, not on its edge. The tolerances cover the program's rounding (X to 0.001 mm on the diameter, arc ends and
radius to 0.001 mm, so a centre moves by a few µm), far below a tool's touch."""
from __future__ import annotations

from shapely.geometry import LineString, Point, Polygon, box
from shapely.geometry.base import BaseGeometry
from shapely.ops import unary_union

from .blending import corner
from .follow import RAPID, THREAD, Move
from .report import TurningReport
from .work import TurningRecords, whole

AIR_TOLERANCE_MM = 0.01
CUT_TOLERANCE_MM = 0.005
ABOVE_EVERYTHING_MM = 1.0e4     # the column a cut clears reaches past any lathe's travel


def path(move: Move) -> BaseGeometry:
    points = move.points
    return Point(points[0]) if len(set(points)) == 1 else LineString(points)


def column(move: Move) -> BaseGeometry:
    """The material a cut leaves as air: everything radially above its path."""
    pieces: list[BaseGeometry] = []
    for (z0, r0), (z1, r1) in zip(move.points, move.points[1:]):
        if abs(z1 - z0) > 1e-9:
            pieces.append(Polygon([(z0, r0), (z1, r1), (z1, ABOVE_EVERYTHING_MM), (z0, ABOVE_EVERYTHING_MM)]))
        pieces.append(LineString([(z0, min(r0, r1)), (z0, ABOVE_EVERYTHING_MM)]))
    return whole(unary_union(pieces).buffer(AIR_TOLERANCE_MM))


def thread_band(drawn: BaseGeometry, move: Move) -> BaseGeometry:
    """Between the drawn thread's root and crest radius, over its Z and the pass's run-in: from
    where the pass starts (the free end it is cut from, design notes §8), never past the drawn
    thread's far end (beyond it a relief groove is air anyway, a shoulder is the part)."""
    z0, r0, z1, r1 = drawn.bounds
    start = move.points[0][0]
    return box(min(z0, start), r0, max(z1, start), r1).buffer(CUT_TOLERANCE_MM)


def bar_behind(blank: BaseGeometry) -> BaseGeometry:
    """The bar behind the blank's back end, at the blank's radius, on into the chuck that holds it."""
    z_back, low, _, high = blank.bounds
    return box(z_back - ABOVE_EVERYTHING_MM, low, z_back, high)


class MaterialWalk:
    def __init__(self, records: TurningRecords, blank: BaseGeometry, report: TurningReport, run_out: float):
        """`run_out`: mm a cut may run on behind a stored blank's back end (params.clearance, bounded)."""
        self.records, self.report, self.run_out = records, report, run_out
        self.z_back = blank.bounds[0] if records.stock is not None else None
        bar = [bar_behind(blank)] if self.z_back is not None else []
        self.material = unary_union([blank, *bar]).difference(records.part)
        self.inside_part = records.part.buffer(-CUT_TOLERANCE_MM)
        self.solid_part = self.inside_part       # less the thread grooves cut so far
        self.threads = {n: region.buffer(CUT_TOLERANCE_MM) for n, region in records.threads.items()}
        self.last: Move | None = None
        self.grown: dict[float, BaseGeometry] = {}    # inside_part grown by each blend tolerance

    def take(self, move: Move) -> None:
        line = path(move)
        before, self.last = self.last, move
        if move.kind == RAPID:
            self._rapid(move, line)
            self._corner(before, move)
            return
        self._corner(before, move)
        self.report.cut_moves += 1
        self._behind(move, line)
        self._cut(move, line)
        self.material = self.material.difference(column(move))

    def _corner(self, before: Move | None, move: Move) -> None:
        """A blended junction (LinuxCNC G64 P, engine.simulation.turning.blending) runs inside the
        angle of its two moves: next to a rapid it must be air, and it must never enter the part."""
        if RAPID not in (move.kind, before.kind if before is not None else None):
            return       # between two cuts the corner lies within the cuts' own blend (_cut)
        region = corner(before, move, RAPID)
        if region is None:
            return
        solid = self.material.buffer(-AIR_TOLERANCE_MM).union(self.solid_part)
        if region.intersection(solid).area > 0:
            self.report.add(move.number, move.line, f"the corner blended into this move at rapid (G64 P{move.blend:g} "
                            "mm: the tool rounds it anywhere inside the angle, that far from the path) runs through "
                            "material: keep the rapid that far clear of it, or write G61")

    def _rapid(self, move: Move, line: BaseGeometry) -> None:
        self.report.rapids += 1
        solid = self.material.buffer(-AIR_TOLERANCE_MM)
        through = line.intersection(solid).length + line.intersection(self.solid_part).length
        if through > 0:
            self.report.add(move.number, move.line, f"a rapid through material for {through:.3f} mm "
                            "(the blank not cut yet or the finished part): it breaks the tool")

    def _behind(self, move: Move, line: BaseGeometry) -> None:
        """Only a parting operation cuts at the back end (down to the axis); beyond the run-out
        behind it any other cut goes into the bar the chuck holds, not into the blank the job turns."""
        op = self.records.operations.get(move.operation) if move.operation else None
        if self.z_back is None or (op is not None and op.kind == "PART"):
            return       # an assumed blank: nothing is known of what lies behind it
        behind = self.z_back - line.bounds[0]
        if behind > self.run_out + CUT_TOLERANCE_MM:
            self.report.add(move.number, move.line, f"a cut {behind:.3f} mm behind the blank's back end "
                            f"Z{self.z_back:.3f}: it cuts the bar the chuck holds, not the blank")

    def _within(self, blend: float) -> BaseGeometry:
        """Where a cut's line may not run: the part (less the cut tolerance) grown by the blend
        tolerance, since the tool may run anywhere within it of the line (blending.tube)."""
        if blend not in self.grown:
            self.grown[blend] = self.inside_part.buffer(blend) if blend > 0 else self.inside_part
        return self.grown[blend]

    def _cut(self, move: Move, line: BaseGeometry) -> None:
        inside = line.intersection(self._within(move.blend))
        if move.kind == THREAD and move.operation in self.threads:
            drawn = self.threads[move.operation]
            if line.intersection(drawn).is_empty:
                self.report.add(move.number, move.line, f"a thread pass away from the drawn thread of operation "
                                f"{move.operation} (its crest and root lines)")
            groove = thread_band(drawn, move)
            inside = inside.difference(groove)
            self.solid_part = self.solid_part.difference(column(move).intersection(groove.buffer(AIR_TOLERANCE_MM)))
        if inside.length > 0:
            self.report.add(move.number, move.line, f"a cut into the finished part for {inside.length:.3f} mm "
                            f"of its path{_blended(move)}: the part's profile is spoiled")


def _blended(move: Move) -> str:
    """A cut under G64 P may run anywhere within P of its path (engine.simulation.turning.blending)."""
    if move.blend <= 0:
        return ""
    return (f" (its G64 P{move.blend:g} mm lets the tool run that far off the path: a finishing pass on the "
            "part's profile is cut under G61 or a P within the cut tolerance)")
