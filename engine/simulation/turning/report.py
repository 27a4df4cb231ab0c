"""What the turning simulation says about a lathe program: one finding per refused line (in the
style of the hobbing report, engine.simulation.hobbing.report) and a summary of what it followed."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..hobbing.report import Report


@dataclass
class TurningReport(Report):
    rapids: int = 0
    cut_moves: int = 0       # feeds and thread passes followed
    blank: str = ""          # "Ø42.000 Z-70.000…0.000 (assumed)"
    not_checked: list[str] = field(default_factory=list)   # what it could not prove (a class job: no drawing)

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
