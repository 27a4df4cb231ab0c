"""Turning cutting data (docs/reference/hobbing.md §E1): the window of cutting speed vc (m/min)
and feed per revolution f (mm/rev) a tool maker or handbook gives for one operation, tool
material and workpiece material group (ISO 513: P steel, K cast iron, N aluminium), and the
check of a cut against it. Both the turning planner (an early warning) and the turning
simulation (the proof, from the program text) call `turning_cut_problem`; neither owns the table.

vc = π·D·n/1000 with D the diameter the tool tip cuts at (mm) and n the spindle speed (r/min);
f = F/n for a feed F in mm/min (G94). What is refused:
* vc above the window: the edge overheats (HSS softens, carbide wears through its coating in
  seconds); a spindle speed several times the planned one is the typical slip.
* f outside the window: above it the edge or the insert breaks; below it the edge rubs, and
  a feed that far below is usually mm/rev written where mm/min is meant.
vc below the window is not refused: at a constant spindle speed vc falls to zero towards the
axis ("cutting speed declines to zero at the centre", a tool maker's parting-and-grooving
guide, scribd.com/document/230044235), and a small part on a lathe whose spindle cannot reach
the window runs below it; a low speed wears a tool sooner but overloads nothing. A thread's
feed per revolution is its lead, so for THREAD only vc is bounded. Callers pass vc at the
largest diameter an operation (or a move) cuts at, where a constant spindle speed is fastest.
"""
from __future__ import annotations

import msgspec

from ..errors import EngineError

OPERATIONS = ("ROUGH", "FINISH", "SLOT", "THREAD", "FACE", "PART")   # the drawings' @G kinds (design §8)
TOOL_MATERIALS = ("carbide", "hss")
WORKPIECE_MATERIALS = ("steel", "cast-iron", "aluminium")            # ISO 513 groups P, K, N
DEFAULT_TOOL_MATERIAL = "carbide"      # an indexable insert: what a CNC lathe runs unless the job says
DEFAULT_WORKPIECE_MATERIAL = "steel"   # ISO P: the shop's shafts and gear blanks
FPM = 0.3048                           # m/min per ft/min
IPR = 25.4                             # mm/rev per in/rev
RELATIVE_TOLERANCE = 1e-9              # F45 at S900 is 0.05 mm/rev, on the window's edge, not past it

# The sources (hobbing.md §E1 gives each in full).
KORLOY = "Korloy ISO P turning table (hooguu.com, turning parameter calculator), P10-P50"
MITSUBISHI = "Mitsubishi Materials catalogue 2020-2021 p. A014, mild steel, F and L cutting"
KENNAMETAL = "Kennametal recommended starting speeds, turning (publications.dgisupply.com/view/344098998/5)"
EASYENG = "easyengcalc.com, cutting conditions reference for lathe turning"
KYOCERA = "Kyocera catalogue 2016-2017 p. 461, GMG/GMM grooving, widths 2-8 mm"
ISCAR = "Iscar threading user guide 2022 p. 77, grades IC228-IC1007"


class Window(msgspec.Struct, frozen=True):
    vc_min: float          # m/min; shown, not refused (see the module's docstring)
    vc_max: float          # m/min
    f_min: float | None    # mm/rev; None for THREAD (the lead)
    f_max: float | None
    source: str


def _w(vc_min: float, vc_max: float, f_min: float | None, f_max: float | None, *sources: str) -> Window:
    return Window(float(vc_min), float(vc_max), f_min, f_max, "; ".join(sources))


# Carbide, steel (P): Korloy roughing P50…P10 vc 80-380, f 0.08-0.45; finishing vc 120-500,
# f 0.05-0.20, widened by Mitsubishi's light cutting of mild steel to f .013 in/rev.
_CARBIDE_STEEL_TURN = _w(80, 380, 0.08, 0.45, KORLOY)
_CARBIDE_STEEL_FINISH = _w(120, 500, 0.05, 0.013 * IPR, KORLOY, MITSUBISHI)
# Carbide, cast iron (K): easyengcalc rough 60-90, finish 90-130 m/min; Kennametal K1-K3 up to
# 1800 ft/min at .004 in/rev, feeds .004-.020 in/rev.
_CARBIDE_IRON_TURN = _w(60, 1800 * FPM, 0.004 * IPR, 0.020 * IPR, EASYENG, KENNAMETAL)
_CARBIDE_IRON_FINISH = _w(90, 1800 * FPM, 0.05, 0.020 * IPR, EASYENG, KENNAMETAL)
# Carbide, aluminium (N): Kennametal N1-N3 400-6900 ft/min, feeds .004-.016 in/rev; finishing
# down to easyengcalc's carbide finishing feed 0.05 mm/rev (its steel and cast-iron rows).
_CARBIDE_AL_TURN = _w(400 * FPM, 6900 * FPM, 0.004 * IPR, 0.016 * IPR, KENNAMETAL)
_CARBIDE_AL_FINISH = _w(400 * FPM, 6900 * FPM, 0.05, 0.016 * IPR, KENNAMETAL, EASYENG)
# HSS (easyengcalc): steel rough 35-45, finish 50-70; cast iron 18-25, 30-35; aluminium
# 150-200, 200-250 m/min; rough feed 0.2-0.3 mm/rev. Its finishing feed is "1/3 of the tool
# width" (a broad tool): bounded here by 0.025 mm/rev (its finishing depth) and the rough 0.3.
_HSS = {"steel": (35, 45, 50, 70), "cast-iron": (18, 25, 30, 35), "aluminium": (150, 200, 200, 250)}


def _carbide_rows() -> dict[tuple[str, str, str], Window]:
    turn = {"steel": _CARBIDE_STEEL_TURN, "cast-iron": _CARBIDE_IRON_TURN, "aluminium": _CARBIDE_AL_TURN}
    finish = {"steel": _CARBIDE_STEEL_FINISH, "cast-iron": _CARBIDE_IRON_FINISH, "aluminium": _CARBIDE_AL_FINISH}
    groove = {"steel": _w(70, 220, 0.05, 0.35, KYOCERA), "cast-iron": _w(70, 200, 0.05, 0.45, KYOCERA),
              "aluminium": _w(200, 500, 0.05, 0.30, KYOCERA)}
    thread = {"steel": _w(25, 230, None, None, ISCAR), "cast-iron": _w(30, 190, None, None, ISCAR),
              "aluminium": _w(40, 480, None, None, ISCAR)}
    rows = {}
    for material in WORKPIECE_MATERIALS:
        for operation, window in (("ROUGH", turn), ("FACE", turn), ("FINISH", finish), ("SLOT", groove),
                                  ("PART", groove), ("THREAD", thread)):
            rows[(operation, "carbide", material)] = window[material]
    return rows


def _hss_rows() -> dict[tuple[str, str, str], Window]:
    """HSS: the source gives turning only; its finishing speed, the fastest it lets HSS run on
    the material, bounds grooving, parting and threading too (hot hardness limits the tool
    whatever it cuts), with the grooving feeds of the carbide rows."""
    rows = {}
    for material, (rough_lo, rough_hi, finish_lo, finish_hi) in _HSS.items():
        turn = _w(rough_lo, rough_hi, 0.2, 0.3, EASYENG)
        groove = _carbide_rows()[("SLOT", "carbide", material)]
        rows.update({("ROUGH", "hss", material): turn, ("FACE", "hss", material): turn,
                     ("FINISH", "hss", material): _w(finish_lo, finish_hi, 0.025, 0.3, EASYENG),
                     ("SLOT", "hss", material): _w(rough_lo, finish_hi, groove.f_min, groove.f_max, EASYENG, KYOCERA),
                     ("THREAD", "hss", material): _w(rough_lo, finish_hi, None, None, EASYENG)})
        rows[("PART", "hss", material)] = rows[("SLOT", "hss", material)]
    return rows


# One row per (operation, tool material, workpiece material group).
CUTTING_DATA: dict[tuple[str, str, str], Window] = {**_carbide_rows(), **_hss_rows()}


def cutting_window(operation: str, tool_material: str, workpiece_material: str) -> Window:
    """The row for one cut, or an EngineError naming the unknown word and the known ones."""
    for value, known, what in ((operation, OPERATIONS, "operation"), (tool_material, TOOL_MATERIALS, "tool material"),
                               (workpiece_material, WORKPIECE_MATERIALS, "workpiece material")):
        if value not in known:
            raise EngineError(f"{what} {value!r} is not in the turning cutting-data table; known: {', '.join(known)}")
    return CUTTING_DATA[(operation, tool_material, workpiece_material)]


def turning_cut_problem(operation: str, tool_material: str, workpiece_material: str,
                        vc_m_min: float, f_mm_rev: float) -> str | None:
    """One line naming the value, the window and the source when the cut is outside the table
    (vc above it, or f outside it except for THREAD), else None."""
    window = cutting_window(operation, tool_material, workpiece_material)
    what = f"{operation} with {tool_material} on {workpiece_material}"
    if vc_m_min > window.vc_max * (1 + RELATIVE_TOLERANCE):
        return (f"cutting speed {vc_m_min:.0f} m/min is above the {window.vc_min:.4g}-{window.vc_max:.4g} m/min "
                f"window for {what} ({window.source})")
    if window.f_min is None or window.f_max is None:
        return None
    low, high = window.f_min * (1 - RELATIVE_TOLERANCE), window.f_max * (1 + RELATIVE_TOLERANCE)
    if not low <= f_mm_rev <= high:
        return (f"feed {f_mm_rev:.4g} mm/rev is outside the {window.f_min:.3g}-{window.f_max:.3g} mm/rev window "
                f"for {what} ({window.source})")
    return None


def job_materials(params: dict, module_params: dict, operation_number: int) -> tuple[str, str]:
    """(tool material, workpiece material) of one operation of a turning job: the tool's from
    module_params prep:<n>.tool_material, the part's from params.workpiece_material; either
    missing (a job stored before they existed) takes the default. Unknown names → EngineError."""
    prep = module_params.get(f"prep:{operation_number}") if isinstance(module_params, dict) else None
    tool = _named(prep if isinstance(prep, dict) else {}, "tool_material", DEFAULT_TOOL_MATERIAL, TOOL_MATERIALS,
                  f"module_params.prep:{operation_number}")
    workpiece = _named(params if isinstance(params, dict) else {}, "workpiece_material", DEFAULT_WORKPIECE_MATERIAL,
                       WORKPIECE_MATERIALS, "params")
    return tool, workpiece


def _named(values: dict, key: str, default: str, known: tuple[str, ...], where: str) -> str:
    value = values.get(key)
    if value is None:
        return default
    if value not in known:
        raise EngineError(f"{where}.{key} = {value!r} is not in the turning cutting-data table; known: "
                          f"{', '.join(known)}; set it in SQL (job.params / job.module_params)")
    return value
