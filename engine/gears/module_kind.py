"""The module a gear drawing states: normal, or (worm wheels) the worm's axial module m_x, which
worm-gear drawings usually give (DIN 3975); the wheel's normal module is m_n = m_x·cos γ
(engine.gears.records.normal_module). Checked at the gear import, one problem per row."""
from __future__ import annotations

from typing import Any

MODULE_KINDS = ("normal", "axial")
WORM_WHEEL = "worm_wheel"


def check_module_kind(gear: dict[str, Any], classes: dict[str, bool]) -> str | None:
    """A worm wheel must say whether its module is the worm's axial module (as worm drawings give
    it) or the normal module: read the wrong way, m3 at a 4° lead angle cuts 0.15 mm shallow, so
    it is asked, never guessed. Other gears' module is normal (the default); axial means nothing
    for them and is refused."""
    kind, is_worm_wheel = gear["module_kind"], gear["gear_class"] == WORM_WHEEL
    if gear["gear_class"] is None:   # no class found: that problem is said already
        return None
    if kind is None and is_worm_wheel:
        return ("module_kind is missing; a worm wheel needs axial (the worm's axial module m_x, as worm "
                "drawings give it) or normal")
    if kind == "axial" and not is_worm_wheel:
        return (f"module_kind axial is for worm wheels (the worm's axial module); "
                f"a {gear['gear_class']} gear's module is normal")
    gear["module_kind"] = kind or "normal"
    return None
