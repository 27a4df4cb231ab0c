"""The hand check of a hobbing picture (issue 27): the gear's teeth and the hob's thread where
they meet, seen from the hob's side (along X: Y to the right, Z up, reference §A7), so that a
wrong hand or a wrong swivel sign shows at a glance. A schematic, not to scale:

* the gear's tooth direction, from the gear record: at β from the work axis, rising to the right
  for a right hand (a right-hand helix at +X runs +Y as it rises), to the left for a left hand;
* the hob's axis turned by the swivel the program writes (DIN A, about X), and its thread at the
  contact: at γ from the plane across its axis (the hob record's hand), turned with the axis;
  the thread lies along the teeth exactly when A = h_hob·γ − h_gear·β (§A7, §B2);
* dashed, the helix the program's coupling generates (its Z term, §A5), for a cylindrical gear,
  named as the program writes it (`EGON(…)` on an 840D, `G81 T… L… Q… P…` on a Fanuc, issue 30).

Angles are measured from +Y toward +Z: the teeth at 90° − h_gear·β, the thread at
90° − h_hob·γ + A."""
from __future__ import annotations

import math
import textwrap

import numpy as np
from matplotlib.patches import Polygon, Rectangle

from ..pictures import literal
from ..simulation.hobbing.coupling import ANGLE_TOLERANCE, expected_swivel, hand_name, hand_sign, helix_of, lead_angle
from ..simulation.hobbing.frame import Senses
from .side_view import BLANK_FILL

FACE = (1.0, 0.7)            # half width (Y) and half height (Z) of the gear's face in the sketch
HOB = (0.9, 0.3)             # half length and radius of the hob in the sketch
TOOTH_PLACES = np.linspace(-0.8, 0.8, 5)
HELIX_PLACES = TOOTH_PLACES[:-1] + 0.2      # between the tooth lines: both stay visible
VERDICT_COLOURS = {True: "tab:green", False: "red"}
VERDICT_WIDTH = 60           # characters of a verdict line


def tooth_angle(hand: str | None, beta: float) -> float:
    """The teeth's direction from +Y toward +Z, degrees (a spur gear's teeth stand upright)."""
    return 90.0 - hand_sign(hand) * beta


def thread_angle(hob, swivel_din: float) -> float:
    """The hob's thread where it meets the gear, turned with its axis by A (DIN), degrees."""
    return 90.0 - hand_sign(hob.hand) * lead_angle(hob) + swivel_din


def crossing(thread: float, tooth: float) -> float:
    """The angle between two undirected lines, −90° … 90°."""
    return (thread - tooth + 90.0) % 180.0 - 90.0


def draw_hand_check(axes, scene) -> str:
    """→ the report line: whether the thread lies along the teeth."""
    gear, hob, swivel = scene.gear, scene.hob, scene.recording.final_swivel
    axes.add_patch(Rectangle((-FACE[0], -FACE[1]), 2 * FACE[0], 2 * FACE[1], facecolor=BLANK_FILL, edgecolor="0.3",
                             linewidth=0.7, gid="hand gear face"))
    tooth = tooth_angle(gear.hand, gear.helix_angle)
    helix = "spur" if not gear.helix_angle else f"{hand_name(gear.hand)} β {gear.helix_angle:.3f}°"
    draw_lines(axes, tooth, "0.25", "-", "hand gear teeth", f"gear {gear.id} teeth: {helix} (gear record)")
    draw_generated_helix(axes, scene)
    if not any(move.cutting for move in scene.recording.moves):
        return draw_words(axes, "the program makes no cut the simulation follows: no swivel to check", False)
    draw_hob(axes, scene, swivel)
    return draw_verdict(axes, scene, crossing(thread_angle(hob, swivel), tooth))


def draw_lines(axes, angle: float, colour: str, style, gid: str, label: str, places=TOOTH_PLACES) -> None:
    """Parallel lines across the face at `angle`: one artist (NaN between the lines)."""
    along = (math.cos(math.radians(angle)), math.sin(math.radians(angle)))
    reach = FACE[1] / max(abs(along[1]), 1e-6)
    ys, zs = [], []
    for place in places:
        ys += [place - reach * along[0], place + reach * along[0], np.nan]
        zs += [-reach * along[1], reach * along[1], np.nan]
    axes.plot(ys, zs, color=colour, linewidth=1.0, linestyle=style, gid=gid, label=literal(label))


def draw_generated_helix(axes, scene) -> None:
    """The helix the program's (last) coupling generates with its Z term, for a cylindrical gear,
    labelled with the coupling as the program writes it (an 840D EGON, a Fanuc G81 T L Q P)."""
    couplings = scene.recording.couplings
    if not couplings or scene.hob.purpose == "worm_wheel":
        return
    coupling = couplings[-1]
    teeth = round(coupling.teeth(scene.hob.starts)) or 1
    beta, hand, _ = helix_of(coupling.factors.get("Z", 0.0), scene.gear, teeth)
    made = "spur" if hand is None else f"{hand_name(hand)} β {beta:.3f}°"
    draw_lines(axes, tooth_angle(hand, beta), "tab:purple", (0, (4, 3)), "hand coupling helix",
               f"helix the program's {scene.recording.coupling_words[-1]} generates: {made}", HELIX_PLACES)


def draw_hob(axes, scene, swivel: float) -> None:
    """The hob's outline and axis at A, and its thread at the contact (through the middle)."""
    along = (math.cos(math.radians(swivel)), math.sin(math.radians(swivel)))
    across = (-along[1], along[0])
    corners = [(s * HOB[0] * along[0] + t * HOB[1] * across[0], s * HOB[0] * along[1] + t * HOB[1] * across[1])
               for s, t in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    axes.add_patch(Polygon(corners, closed=True, fill=False, edgecolor="black", linewidth=1.0, gid="hand hob"))
    axes.plot(*through_middle(swivel, 1.1 * HOB[0]), color="0.3", linewidth=0.8, linestyle="-.", gid="hand hob axis",
              label=literal(f"hob {scene.hob.id} axis at A {swivel:+.3f}° (DIN, as the program swivels it)"))
    thread = thread_angle(scene.hob, swivel)
    reach = HOB[1] / max(abs(math.sin(math.radians(thread - swivel))), 1e-6)   # across the hob, side to side
    axes.plot(*through_middle(thread, reach), color="tab:orange", linewidth=2.4, gid="hand hob thread",
              label=f"hob thread at the gear: {hand_name(scene.hob.hand)} γ {lead_angle(scene.hob):.3f}°")


def through_middle(angle: float, reach: float) -> tuple[list[float], list[float]]:
    """Y and Z of a segment through the sketch's middle at `angle`, `reach` to each side."""
    dy, dz = reach * math.cos(math.radians(angle)), reach * math.sin(math.radians(angle))
    return [-dy, dy], [-dz, dz]


def draw_verdict(axes, scene, apart: float) -> str:
    along = abs(apart) <= ANGLE_TOLERANCE
    if along:
        return draw_words(axes, f"the hob's thread lies along the teeth ({abs(apart):.3f}° apart)", True)
    wanted = expected_swivel(scene.gear, scene.hob) * Senses.of(scene.machine).a
    return draw_words(axes, f"THE HOB'S THREAD CROSSES THE TEETH BY {abs(apart):.3f}°: wrong swivel or hand "
                            f"(this gear and hob need {scene.recording.swivel_address}{wanted:.3f}° as written, "
                            "h_hob·γ − h_gear·β)", False)


def draw_words(axes, words: str, good: bool) -> str:
    """The verdict under the sketch, green or red; → the report line."""
    axes.set_title("hand check: teeth and hob thread seen from the hob (not to scale)", fontsize="medium")
    axes.text(0.5, 0.02, "\n".join(textwrap.wrap(words, VERDICT_WIDTH)), transform=axes.transAxes, ha="center",
              va="bottom", fontsize="small", color=VERDICT_COLOURS[good], gid="hand verdict",
              bbox=dict(facecolor="white", edgecolor=VERDICT_COLOURS[good], linewidth=0.8))
    finish(axes)
    return f"hand check: {words}"


def finish(axes) -> None:
    axes.set_xlim(-1.3, 1.3)
    axes.set_ylim(-FACE[1] - 0.45, FACE[1] + 0.1)
    axes.set_aspect("equal", adjustable="box")
    axes.set_ylabel("Z (work axis), Y to the right")
    axes.set_xticks([])
    axes.set_yticks([])
    axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.01), fontsize="x-small")
