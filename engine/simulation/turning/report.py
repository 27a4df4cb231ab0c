"""What the turning simulation says about a lathe program: one finding per refused line (in the
style of the hobbing report, engine.simulation.hobbing.report) and a summary of what it followed."""
from __future__ import annotations

from ..hobbing.report import Report, SimulationError

# What a user does about a blank the simulation assumed (a class job without stock_* params).
STATE_THE_BLANK = ("the blank {blank} is assumed from the program's own cuts; if the bar is larger, "
                   "state it with the params stock_diameter, stock_z_front and stock_z_back (mm, the program's "
                   "frame) and instantiate again")


class TurningReport(Report):
    rapids: int = 0
    cut_moves: int = 0       # feeds and thread passes followed
    blank: str = ""          # "Ø42.000 Z-70.000…0.000 (assumed)"
    not_checked: list[str] = []   # what it could not prove (a class job: no drawing)

    def error(self, where_listed: str = "") -> SimulationError:
        """The first refusal, all of them counted (a refused program is not stored, so the count is
        said here rather than left to `engine simulate`; `where_listed` as Report.error), and what
        to do about an assumed blank."""
        first, more = self.refusals[0], len(self.refusals) - 1
        extra = f" (and {more} more finding{'s' if more > 1 else ''}{where_listed})" if more else ""
        hint = f"; {STATE_THE_BLANK.format(blank=self.blank.removesuffix(' (assumed)'))}" \
            if self.blank.endswith("(assumed)") else ""
        return SimulationError(f"the simulation refuses {first.sentence(self.name)}{extra}{hint}")

    def lines(self) -> list[str]:
        out = [("refused: " if f.refuses else "note: ") + f.sentence(self.name) for f in self.findings]
        out += [f"not checked: {what}" for what in self.not_checked]
        out.append(f"followed {self.rapids} rapid(s) and {self.cut_moves} cut(s) through the blank {self.blank}; "
                   f"{'REFUSED' if self.refused else 'clean'}")
        return out

    def as_dict(self) -> dict:
        return {"program": self.name, "refused": self.refused,
                "findings": [{"number": f.number, "line": f.line, "message": f.message, "refuses": f.refuses}
                             for f in self.findings],
                "rapids": self.rapids, "cuts": self.cut_moves, "blank": self.blank,
                "not_checked": list(self.not_checked)}
