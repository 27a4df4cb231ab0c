"""The hob seen from its own side (along X: Y to the right, Z up; reference §A7, Y = Z × X): the
blank's silhouette, the hob at full depth on the first unit with its axis swivelled by A, the
generating zone L_gen = 2·h/tan α_n + π·m_n where it meets the gear (§B15), the length of the hob
the program's Y positions bring to the zone (the shift range: the part of the hob the shifting
uses), the hob centre's Y travel the working area G25/G26 allows, and a tangential pass's
arrow. Y moves the hob along its own axis, so the zone stays at the gear and a different part of
the hob reaches it (engine.simulation.hobbing.envelope)."""
from __future__ import annotations

import math

from matplotlib.patches import Polygon

from ..pictures import literal
from ..simulation.hobbing.rules import generating_length
from .plot_geometry import Pass, along_hob, cut_pass, full_depth_pose, hob_centre, hob_front_corners, unit_section
from .side_view import BLANK_FILL, cut_colour, last_cut_of

NO_PASS = Pass("", {}, {})


def draw_hob_view(axes, scene) -> list[str]:
    """→ report lines: the tangential passes, or else the shift range."""
    recording = scene.recording
    for unit in recording.units:
        axes.add_patch(Polygon(unit_section(unit), closed=True, facecolor=BLANK_FILL, edgecolor="0.3",
                               linewidth=0.7, gid=f"silhouette {unit.name}"))
    cut = last_cut_of(recording.cuts, recording.units[0].name)
    pose = full_depth_pose(cut, recording.units[0]) if cut is not None else None
    drawn = ["hob view: no cut to show the hob at"]
    if pose is not None:
        draw_hob(axes, scene, pose)
        drawn = draw_feeds_or_shift(axes, scene, pose)
        draw_travel(axes, scene, pose["Z"], recording.final_swivel)
    finish(axes)
    return drawn


def draw_hob(axes, scene, pose: dict) -> None:
    """The hob at full depth on the first unit, with its axis."""
    hob, swivel = scene.hob, scene.recording.final_swivel
    y, z, half = pose.get("Y", 0.0), pose["Z"], hob.length / 2
    axes.add_patch(Polygon(hob_front_corners(y, z, hob.tip_diameter / 2, half, swivel), closed=True, fill=False,
                           edgecolor="black", linewidth=1.0, gid="hob front", label=literal(f"hob {hob.id}")))
    axes.plot(*zip(along_hob(-half, y, z, swivel), along_hob(half, y, z, swivel)), color="0.3", linewidth=0.6,
              linestyle="-.", gid="hob axis")


def draw_feeds_or_shift(axes, scene, pose: dict) -> list[str]:
    """A tangential worm-wheel pass feeds along Y, so Y is no shift there; else the shift range."""
    swivel = scene.recording.final_swivel
    tangential = [(n, cut) for n, cut in enumerate(scene.recording.cuts) if (cut_pass(cut) or NO_PASS).axis == "Y"]
    return [draw_tangential(axes, scene, cut, n, swivel) for n, cut in tangential] or \
        [draw_shift_range(axes, scene, pose.get("Y", 0.0), pose["Z"], swivel)]


def band(y: float, z: float, swivel: float, u0: float, u1: float, radius: float) -> list:
    """The hob's cross-section between u0 and u1 along its axis."""
    corners = []
    for u, side in ((u0, -1), (u1, -1), (u1, 1), (u0, 1)):
        cy, cz = along_hob(u, y, z, swivel)
        corners.append((cy - side * radius * _sin(swivel), cz + side * radius * _cos(swivel)))
    return corners


def draw_shift_range(axes, scene, y: float, z: float, swivel: float) -> str:
    """The zone at the gear (Y = 0) lies −Y from the hob centre; over the program's Y range it
    sweeps −Y_max − L_gen/2 … −Y_min + L_gen/2 of the hob."""
    zone, r = generating_length(scene.gear), scene.hob.tip_diameter / 2
    low, high = scene.recording.cutting_y
    used = (-high - zone / 2, -low + zone / 2)
    axes.add_patch(Polygon(band(y, z, swivel, *used, r), closed=True, facecolor="tab:cyan", alpha=0.25,
                           edgecolor="tab:cyan", hatch="..", gid="shift range",
                           label=f"hob length used: Y{low:g} … Y{high:g}"))
    axes.add_patch(Polygon(band(y, z, swivel, -y - zone / 2, -y + zone / 2, r), closed=True, facecolor="tab:blue",
                           alpha=0.35, edgecolor="tab:blue", gid="generating zone",
                           label=f"generating zone {zone:.1f} mm"))
    return (f"shift range on the hob: Y{low:g} … Y{high:g}, {used[1] - used[0]:.1f} of {scene.hob.length:g} mm "
            f"used (generating zone {zone:.1f} mm, §B15)")


def draw_travel(axes, scene, z: float, swivel: float) -> None:
    """The hob centre's Y travel between G25 Y and G26 Y."""
    lower, upper = scene.recording.areas.get("lower", {}), scene.recording.areas.get("upper", {})
    if "Y" not in lower or "Y" not in upper:
        return None
    ends = [hob_centre(value, z, swivel) for value in sorted((lower["Y"], upper["Y"]))]
    axes.plot(*zip(*ends), color="tab:red", linewidth=1.4, marker="|", markersize=14, linestyle=(0, (8, 3)),
              gid="working area Y", label="hob centre Y limits G25/G26")


def draw_tangential(axes, scene, cut, index: int, swivel: float) -> str:
    """A tangential worm-wheel pass feeds the hob along its own axis (§B10): the hob where the
    pass begins and ends, and the arrow of its feed; no shift range (Y is the feed)."""
    feed, r, half = cut_pass(cut), scene.hob.tip_diameter / 2, scene.hob.length / 2
    assert feed is not None   # a tangential cut feeds along Y
    for pose, where in ((feed.start, "begins"), (feed.end, "ends")):
        axes.add_patch(Polygon(hob_front_corners(pose["Y"], pose["Z"], r, half, swivel), closed=True, fill=False,
                               edgecolor="0.45", linestyle=(0, (3, 2)), gid=f"hob where {cut.label} {where}"))
    start, end = (hob_centre(pose["Y"], pose["Z"], swivel) for pose in (feed.start, feed.end))
    axes.annotate("", xy=end, xytext=start, gid=f"pass {cut.label}",
                  arrowprops=dict(arrowstyle="-|>", color=cut_colour(index), linewidth=1.6, mutation_scale=18))
    axes.plot([], [], color=cut_colour(index), linewidth=1.6, label=literal(f"{cut.label}: Y feed"))
    return f"{cut.label}: the hob feeds along its axis Y{feed.start['Y']:g} → Y{feed.end['Y']:g} (no shift range)"


def finish(axes) -> None:
    axes.autoscale_view()
    axes.set_aspect("equal", adjustable="datalim")
    axes.set_xlabel("Y (mm)")
    axes.set_ylabel("Z (mm)")
    axes.set_title("the hob seen along X: shift range or Y feed", fontsize="medium")
    axes.grid(True, linewidth=0.3)
    axes.legend(loc="upper right", fontsize="x-small")



def _sin(swivel: float) -> float:
    return math.sin(math.radians(swivel))


def _cos(swivel: float) -> float:
    return math.cos(math.radians(swivel))
