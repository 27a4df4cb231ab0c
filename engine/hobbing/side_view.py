"""The side view of a hobbing job (issue 17): the axial section through the work axis and the hob
centre, X (centre distance) to the right and Z (axial feed) up, as the machine's axes stand in
the DIN frame (design notes §7, reference §A6, §A7). It shows each unit of the blank (tip
diameter over face width, with its intended root dotted), the fixture below and the tailstock
above as the machine record gives them, the hob's outline at the approach and at full depth on
every unit, the hob centre's path (rapids dashed, each cut in its own colour) with an arrow in
the direction of each pass, and the working area G25/G26. A second panel shows the whole
working area with every move, the load position included. Every artist carries a gid (its
name in the SVG, and what the tests read)."""
from __future__ import annotations

from typing import Any

from matplotlib.patches import Polygon, Rectangle

from ..pictures import literal
from ..simulation.hobbing.reading import machine_dialect
from .plot_geometry import (
    approach_pose,
    axial_profile,
    cut_pass,
    full_depth_pose,
    hob_extent,
    hob_side_outline,
    unit_section,
)

BLANK_FILL = "0.82"
SETUP_FILL = "0.65"
RAPID_STYLE = (0, (4, 3))
AREA_STYLE: dict[str, Any] = dict(fill=False, edgecolor="tab:red", linestyle=(0, (8, 3)), linewidth=1.0)
CUT_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:olive")
HATCHES = {"the fixture": "//", "the tailstock": "\\\\"}
CROWNING_VISIBLE = 1.0  # mm: a pass whose X varies less than this is drawn magnified beside the view
INSET_PLACE = (0.1, 0.05, 0.3, 0.2)   # axes fraction: lower left, under the blank
MARGIN = 8.0            # mm of picture around what the side view frames
WORKING_AREA_CODES = {25, 26}   # G25/G26: the 840D's working-area limits (a Fanuc hobbing program has none)


def cut_colour(index: int) -> str:
    return CUT_COLOURS[index % len(CUT_COLOURS)]


def draw_side_view(axes, scene) -> list[str]:
    """The cutting zone: blank, set-up, hob outlines, cut paths and pass arrows; → report lines."""
    drawn = [draw_unit(axes, unit) for unit in scene.recording.units]
    drawn += draw_hob_poses(axes, scene)
    draw_paths(axes, scene.recording.moves)
    drawn += [draw_pass(axes, cut, cut_colour(n)) for n, cut in enumerate(scene.recording.cuts)]
    draw_area(axes, scene.recording)
    frame_side_view(axes, scene)
    drawn += [draw_setup(axes, solid) for solid in scene.recording.setup]
    axes.axvline(0.0, color="0.4", linewidth=0.6, linestyle="-.", gid="work axis")
    finish(axes, "side view: axial section (X centre distance, Z axial feed)")
    return drawn


def draw_unit(axes, unit) -> str:
    axes.add_patch(Polygon(unit_section(unit), closed=True, facecolor=BLANK_FILL, edgecolor="0.3",
                           linewidth=0.9, gid=unit.name, label="blank" if unit.name.startswith("unit 1") else None))
    if unit.intended_root is not None:
        axes.plot(unit.intended_root, unit.heights, color="0.3", linewidth=0.7, linestyle=":",
                  gid=f"root {unit.name}")
    tip = 2 * unit.largest_radius
    return (f"{unit.name}: blank tip ⌀{tip:.3f} × face {unit.z_high - unit.z_low:g} mm, "
            f"Z{unit.z_high:g} … {unit.z_low:g}")


def draw_setup(axes, solid) -> str:
    """The fixture or tailstock, from its face to the edge of the picture."""
    low, high = axes.get_ylim()
    z_low, z_high = max(solid.z_low, low), min(solid.z_high, high)
    if z_low >= z_high:
        return f"{solid.name}: ⌀{2 * solid.radius_at_top:g} (outside the picture)"
    r = solid.radius_at_top
    axes.add_patch(Rectangle((-r, z_low), 2 * r, z_high - z_low, facecolor=SETUP_FILL, edgecolor="0.25",
                             hatch=HATCHES.get(solid.name, "//"), linewidth=0.8, gid=solid.name,
                             label=literal(solid.name)))
    face = solid.z_high if solid.z_high < high else solid.z_low
    return f"{solid.name}: ⌀{2 * r:g} from Z{face:g}"


def draw_hob_poses(axes, scene) -> list[str]:
    """The hob at the approach (before the first feed move) and at full depth on every unit."""
    drawn = [draw_approach(axes, scene)] if approach_pose(scene.recording.cuts) else []
    first = scene.recording.units[0]
    for unit in scene.recording.units:
        cut = last_cut_of(scene.recording.cuts, unit.name)
        pose = full_depth_pose(cut, unit) if cut is not None else None
        if pose is not None:
            draw_hob(axes, scene, pose, f"hob at full depth {unit.name}", "black", "-", unit is first)
            drawn.append(f"hob at full depth on {unit.name}: X{pose['X']:.3f} Z{pose['Z']:.3f}")
    return drawn


def draw_approach(axes, scene) -> str:
    hob, approach = scene.hob, approach_pose(scene.recording.cuts)
    assert approach is not None   # drawn only where the recording has one
    draw_hob(axes, scene, approach, "hob at approach", "0.45", (0, (3, 2)))
    return (f"hob {hob.id} ⌀{hob.tip_diameter:g} × {hob.length:g} at approach X{approach['X']:.3f} "
            f"Z{approach['Z']:.3f}")


def last_cut_of(cuts, unit_name: str):
    return next((cut for cut in reversed(cuts) if unit_name in cut.units), None)


def draw_hob(axes, scene, pose: dict, gid: str, colour: str, style, in_legend: bool = True) -> None:
    xs, zs = hob_side_outline(pose["X"], pose["Z"], scene.hob.tip_diameter / 2, scene.hob.length / 2,
                              scene.recording.final_swivel)
    axes.plot(xs, zs, color=colour, linewidth=1.0, linestyle=style, gid=gid,
              label=literal(gid.split(" unit")[0]) if in_legend else None)
    axes.plot([pose["X"]], [pose["Z"]], marker="+", color=colour, gid=f"{gid} centre")


def draw_paths(axes, moves, prefix: str = "") -> None:
    """The hob centre's path: rapids dashed grey, feed moves solid; where X and Z are known."""
    for move in moves:
        if {"X", "Z"} <= move.start.keys():
            xs, zs = [move.start["X"], move.end["X"]], [move.start["Z"], move.end["Z"]]
            rapid = move.motion == 0
            axes.plot(xs, zs, color="0.55" if rapid else "0.15", linewidth=0.6 if rapid else 0.9,
                      linestyle=RAPID_STYLE if rapid else "-", gid=f"{prefix}line {move.number}")
    axes.plot([], [], color="0.55", linewidth=0.6, linestyle=RAPID_STYLE, label="hob centre, rapid G0")


def draw_pass(axes, cut, colour: str) -> str:
    xs, zs = [pose["X"] for pose in cut.poses], [pose["Z"] for pose in cut.poses]
    axes.plot(xs, zs, color=colour, linewidth=2.0, gid=f"cut {cut.label}", label=literal(cut.label))
    feed = cut_pass(cut)
    if feed is None or not {"X", "Z"} <= feed.start.keys():
        return f"{cut.label}: no feed move from a known position"
    crowning = draw_crowning(axes, cut, colour) if feed.axis == "Z" else ""
    if feed.axis in ("X", "Z"):
        axes.annotate("", xy=(feed.end["X"], feed.end["Z"]), xytext=(feed.start["X"], feed.start["Z"]),
                      arrowprops=dict(arrowstyle="-|>", color=colour, linewidth=1.6, mutation_scale=18),
                      gid=f"pass {cut.label}")
    return f"{cut.label}: {pass_words(feed)}{crowning}"


def draw_crowning(axes, cut, colour: str) -> str:
    """A crowned pass changes X by some hundredths of a millimetre (§B11), invisible at the
    picture's scale: drawn magnified, X above its least value along Z, in µm."""
    xs, zs = axial_profile(cut)
    spread = max(xs) - min(xs)
    if not (0 < spread < CROWNING_VISIBLE) or len(xs) < 4:
        return ""
    inset = axes.inset_axes(INSET_PLACE)
    inset.plot(zs, [(x - min(xs)) * 1000 for x in xs], color=colour, linewidth=1.2, marker=".", markersize=3,
               gid=f"crowning {cut.label}")
    label_inset(inset, f"X − {min(xs):.3f} (µm)")
    return f", X varies {spread * 1000:.0f} µm along it (crowning, drawn magnified)"


def label_inset(inset, y_label: str) -> None:
    inset.set_xlabel("Z (mm)", fontsize="x-small")
    inset.set_ylabel(y_label, fontsize="x-small")
    inset.set_title("crowning along the pass, magnified", fontsize="x-small")
    inset.tick_params(labelsize="xx-small")
    inset.grid(True, linewidth=0.3)


def pass_words(feed) -> str:
    axis = feed.axis
    sense = {"Z": ("up", "down"), "X": ("out", "in"), "Y": ("+Y", "−Y")}[axis]
    direction = sense[0] if feed.end[axis] > feed.start[axis] else sense[1]
    return f"{axis}{feed.start[axis]:.3f} → {axis}{feed.end[axis]:.3f} ({direction})"


def draw_area(axes, recording, gid: str = "working area") -> None:
    """The working area as G25 (lower) and G26 (upper) set X and Z."""
    lower, upper = recording.areas.get("lower", {}), recording.areas.get("upper", {})
    if {"X", "Z"} <= lower.keys() and {"X", "Z"} <= upper.keys():
        x0, x1 = sorted((lower["X"], upper["X"]))
        z0, z1 = sorted((lower["Z"], upper["Z"]))
        axes.add_patch(Rectangle((x0, z0), x1 - x0, z1 - z0, gid=gid, label="working area G25/G26",
                                 **AREA_STYLE))


def frame_side_view(axes, scene) -> None:
    """Frame the blank and the hob wherever it cuts or approaches, not the load position."""
    recording, r = scene.recording, scene.hob.tip_diameter / 2
    reach = hob_extent(r, scene.hob.length / 2, recording.final_swivel)
    xs = [x for unit in recording.units for x, _ in unit_section(unit)]
    zs = [z for unit in recording.units for _, z in unit_section(unit)]
    for pose in (pose for cut in recording.cuts for pose in cut.poses):
        xs.append(pose["X"] + r)
        zs += [pose["Z"] - reach, pose["Z"] + reach]
    axes.set_xlim(min(xs) - MARGIN, max(xs) + MARGIN)
    axes.set_ylim(min(zs) - MARGIN, max(zs) + MARGIN)


def draw_overview(axes, scene) -> str:
    """The whole working area with every move the program makes, the load position included."""
    for unit in scene.recording.units:
        axes.add_patch(Polygon(unit_section(unit), closed=True, facecolor=BLANK_FILL, edgecolor="0.3",
                               linewidth=0.6, gid=f"overview {unit.name}"))
    draw_paths(axes, scene.recording.moves, "overview ")
    for n, cut in enumerate(scene.recording.cuts):
        axes.plot([pose["X"] for pose in cut.poses], [pose["Z"] for pose in cut.poses], color=cut_colour(n),
                  linewidth=1.6)
    draw_area(axes, scene.recording, "overview working area")
    axes.axvline(0.0, color="0.4", linewidth=0.6, linestyle="-.")
    axes.autoscale_view()
    finish(axes, "working area (X, Z) and every move")
    return area_words(scene.recording, scene.machine)


def area_words(recording, machine) -> str:
    """The working area as the program sets it; a dialect without G25/G26 (Fanuc hobbing) has none."""
    words = recording.area_words
    if not words:
        grammar = machine_dialect(machine)
        if WORKING_AREA_CODES <= grammar.g_codes.keys():
            return "working area: the program sets no G25/G26"
        return f"working area: none, the {grammar.name} grammar has no working-area command (840D G25/G26)"
    said = ["G25 " + " ".join(f"{axis}{value:g}" for axis, value in sorted(words.get("lower", {}).items())),
            "G26 " + " ".join(f"{axis}{value:g}" for axis, value in sorted(words.get("upper", {}).items()))]
    return "working area " + " … ".join(said)


def finish(axes, title: str) -> None:
    axes.set_aspect("equal", adjustable="datalim" if "working" in title else "box")
    axes.set_xlabel("X (mm)")
    axes.set_ylabel("Z (mm)")
    axes.set_title(title, fontsize="medium")
    axes.grid(True, linewidth=0.3)
