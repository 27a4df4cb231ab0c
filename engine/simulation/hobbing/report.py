"""What the simulation says about a program: its findings (each with the line it concerns) and
its summary (teeth, hand and lead of the helix, depth per cut, run-out, table speed, feed per
workpiece revolution, cycle time). A finding that makes the program wrong refuses it."""
from __future__ import annotations

import msgspec
from msgspec.structs import asdict

from ...errors import EngineError
from ...verifier.refusals import shown, shown_name


class SimulationError(EngineError):
    """A program the simulation refuses: a collision, a wrong coupling or swivel, a depth not
    reached, a run-out short of the generating zone, a table too fast, a feed (axial or radial, at
    the current spindle speed) above §C, a shift, swivel or T/D word while coupled, an offset other
    than D1, a unit re-cut by a new coupling, a generating zone off the hob, records other than the
    ones proved against, a header fact not in its canonical form, stated twice or after the first
    motion, a wrong or missing cycle time, a hob that does not fit the gear, a hob speed above §C
    or other than the header's n0, a cut with the tailstock released, a working area set again,
    a header fact or cut word that is not the records' or the program's own, or a line it cannot
    read (engine.simulation.hobbing.facts)."""


def where(name: str, number: int, line: str) -> str:
    return f"{shown_name(name)} line {number} {shown(line)}"


class Finding(msgspec.Struct, frozen=True):
    """What the simulation found at one line: a refusal (refuses) or a note."""
    number: int
    line: str
    message: str
    refuses: bool = True

    def sentence(self, name: str) -> str:
        return f"{where(name, self.number, self.line)}: {self.message}"


class CutSummary(msgspec.Struct):
    """One cut as simulated: its centre distance, depth, stock left and feeds (mm, mm per workpiece revolution)."""
    number: int          # the cut's first line
    unit: str
    centre_distance: float
    depth: float         # below the unit's tip, at the deepest
    stock_left: float    # the most it leaves above the intended root over the face
    run_out: float | None          # mm the hob centre passes the face it leaves (None: no axial/tangential pass)
    radial_feed: float | None      # mm per workpiece revolution
    pass_feed: float | None        # axial (or tangential) mm per workpiece revolution
    mark_feed: float | None = None  # mm per workpiece revolution along an axial pass's path (§B6 feed marks)


class FirstRefusal(Exception):
    """A report that stops at its first refusal has it (Report.first_only)."""


class Report(msgspec.Struct):
    """The simulation's report of one program: its findings, couplings, cuts, table speed and cycle time."""
    name: str
    findings: list[Finding] = []
    teeth: list[str] = []       # per coupling: "19 (unit 1)"
    helix: list[str] = []       # per coupling: "right-hand β 15.000° lead 1427.2 mm"
    cuts: list[CutSummary] = []
    table_speed: float = 0.0          # r/min, the most while coupled
    cycle_time: float = 0.0           # minutes
    header_time: float | None = None  # the program's `; CYCLE TIME … MIN`
    # Stop at the first refusal (FirstRefusal): a search trying choices asks only whether a program
    # is refused and why; finding a colliding program's every other collision and its depth cost
    # a refused gear's search seconds (issue 28). A program not refused is followed to its end.
    first_only: bool = False

    @property
    def refusals(self) -> list[Finding]:
        return [finding for finding in self.findings if finding.refuses]

    @property
    def refused(self) -> bool:
        return bool(self.refusals)

    def add(self, number: int, line: str, message: str, refuses: bool = True) -> None:
        finding = Finding(number, line, message, refuses)
        if finding not in self.findings:
            self.findings.append(finding)
        if refuses and self.first_only:
            raise FirstRefusal

    def error(self, where_listed: str = "") -> SimulationError:
        """The first refusal, the others counted; `where_listed` says where they are shown (e.g.
        ', listed above' by engine simulate). A program refused before it is stored is listed
        nowhere else, so no command is pointed to (new-user review 29: one pointed to engine
        simulate, which has no program to simulate then)."""
        first = self.refusals[0]
        more = len(self.refusals) - 1
        extra = f" (and {more} more finding{'s' if more > 1 else ''}{where_listed})" if more else ""
        return SimulationError(f"the simulation refuses {first.sentence(self.name)}{extra}")

    def lines(self) -> list[str]:
        """One line per finding, then the summary."""
        out = [("refused: " if f.refuses else "note: ") + f.sentence(self.name) for f in self.findings]
        out.append(f"teeth {', '.join(self.teeth) or '-'}; helix {', '.join(self.helix) or '-'}")
        for cut in self.cuts:
            out.append(f"cut at line {cut.number} on {cut.unit}: X{cut.centre_distance:.3f} depth {cut.depth:.3f} mm, "
                       f"stock left {cut.stock_left:.3f} mm, run-out {_mm(cut.run_out)}, "
                       f"feed/rev radial {_mm(cut.radial_feed)} pass {_mm(cut.pass_feed)}")
        header = "none" if self.header_time is None else f"{self.header_time:g} min"
        out.append(f"table speed at most {self.table_speed:.2f} r/min; cycle time {self.cycle_time:.2f} min "
                   f"(header {header}); {'REFUSED' if self.refused else 'clean'}")
        return out

    def as_dict(self) -> dict:
        return {"program": self.name, "refused": self.refused,
                "findings": [asdict(f) for f in self.findings], "teeth": self.teeth, "helix": self.helix,
                "cuts": [asdict(cut) for cut in self.cuts], "table_speed": round(self.table_speed, 4),
                "cycle_time": round(self.cycle_time, 4), "header_cycle_time": self.header_time}


def _mm(value) -> str:
    return "-" if value is None else f"{value:.3f}"
