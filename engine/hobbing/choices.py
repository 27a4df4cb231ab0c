"""Process choices of a hobbing job: what the engineer decides, switched on in template rows."""
from __future__ import annotations

from dataclasses import dataclass

SINGLE_CUT_MAX_MODULE = 3.0   # m_n ≤ about 3: one cut to full depth is common (§B14)


@dataclass(frozen=True)
class Choices:
    cuts: int | None = None            # 1 = finish only, 2 = rough then finish; None = by module
    finish_stock: float | None = None  # radial stock left by the rough cut, mm
    coolant: bool = True
    climb: bool = True
    shift_y: float = 0.0               # hob shift position for this part, mm (0 = no shift)

    def cut_count(self, module: float) -> int:
        if self.cuts is not None:
            return self.cuts
        return 1 if module <= SINGLE_CUT_MAX_MODULE else 2

    def stock(self, module: float) -> float:
        """0.3–1.0 mm, more for larger modules (§B14)."""
        if self.finish_stock is not None:
            return self.finish_stock
        return min(1.0, max(0.3, 0.15 * module))
