"""Feed marks as the reference gives them (docs/reference/hobbing.md §B6), computed here from the
reference's formulas and never from the engine: the depth δ = f_a²·sin α_n/(4·d_a0), the helix
form tolerance of ISO 1328-1:2013 formula (11), f_fβT = (0.07·√d + 0.45·√b + 4)·√2^(A − 5) µm,
and the share of it the marks may take (half, §B6 [K])."""
from __future__ import annotations

import math

SHARE = 0.5


def depth(feed_per_rev: float, pressure_angle: float, hob_tip_diameter: float) -> float:
    """δ [mm] (§B6)."""
    return feed_per_rev ** 2 * math.sin(math.radians(pressure_angle)) / (4 * hob_tip_diameter)


def limit(grade: int, module: float, teeth: int, helix_angle: float, face_width: float) -> float:
    """The deepest marks [mm] the grade allows: half of f_fβT for d = z·m_n/cos β and b."""
    d = teeth * module / math.cos(math.radians(helix_angle))
    tolerance = (0.07 * math.sqrt(d) + 0.45 * math.sqrt(face_width) + 4) * math.sqrt(2) ** (grade - 5)
    return SHARE * tolerance / 1000


def bound(grade: int, module: float, teeth: int, helix_angle: float, face_width: float, pressure_angle: float,
          hob_tip_diameter: float, cone_angle: float = 0.0) -> float:
    """The most f_a [mm per workpiece revolution] of the last cut: δ solved for f_a at the limit;
    a taper's marks lie f_a/cos δ apart along its slant (§B12), so f_a is lowered by cos δ."""
    most = limit(grade, module, teeth, helix_angle, face_width)
    feed = math.sqrt(4 * hob_tip_diameter * most / math.sin(math.radians(pressure_angle)))
    return feed * math.cos(math.radians(cone_angle))
