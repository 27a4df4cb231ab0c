"""Hobbing model of worm wheels (reference §A5, §B10). The hob copies the mating worm, its
axis lies in the wheel's mid-plane at a shaft angle of 90°, and there is no axial pass. Its
swivel is the general A = h_hob·γ − h_gear·β (§A7): 0 when the hob's lead angle is the wheel's
helix, and the small difference otherwise (an oversize or resharpened hob, within the hob
match's tolerance), so the hob's thread lies along the teeth. Radial: X plunges to the full-depth
centre distance and dwells while the table turns.
Tangential: the centre distance is set in air, the hob feeds along its own axis (Y) through
the wheel, and the table gets the extra rotation 360·cos γ0/(π·m_n0·z2) = 360/(π·m_x0·z2) degrees
per mm of Y: the hob's own axial pitch π·m_x0 is one wheel tooth (§B10). A hob catalogued by its
worm's axial module has it as its record's module (engine.gears.records.Hob.module_kind)."""
from __future__ import annotations

import math

from msgspec.structs import replace

from ..errors import InputError
from ..gears.cutting_data import per_minute, programmed_feed
from ..gears.models import register_model
from . import conventions
from .cylindrical import RAPID_SHORT_OF_CUT, CylindricalModel, JobParameters
from .passes import APPROACH_SAFETY, plan_cuts, working_area

DWELL_TABLE_TURNS = 2.0   # table revolutions at full depth after a radial plunge (enveloping cuts)


@register_model("worm_wheel")
class WormWheelModel(CylindricalModel):
    hob_purpose = "worm_wheel"
    class_parameters = frozenset({"z_mid", "tangential", "y_start", "y_end", "tangential_factor"})
    cut_parameters = frozenset({"cut_name", "cut_x", "cut_on", "feed_radial", "dwell", "feed_tangential",
                                "x_air"})
    cut_shape = "worm"
    axial_passes = False   # fed radially or tangentially (--worm-feed): --feed-mode does not apply

    def shift_travel(self, choices) -> float:
        return 0.0   # a worm-wheel hob is not shifted; the tangential pass uses its whole length

    def job(self, gear, gear_class, hob, machine, cutting, choices) -> JobParameters:
        check_module_stated(gear)
        choices = choices.for_unit(1, 1, gear.id)   # a mode per unit is a cluster gear's
        setup = self.setup(gear, hob)
        tangential = choices.worm_feed == "tangential"
        if tangential:
            choices = one_tangential_cut(gear, choices)
        cuts = plan_cuts(gear.module, setup.full_depth, choices)
        table_speed = cutting.hob_speed * hob.starts / gear.teeth
        module_params = {f"cutmotion:{cut.number}": {
            "cut_name": cut.name, "cut_x": round(cut.centre_distance, 3), "cut_on": cut.on,
            "x_air": round(air_position(gear, hob, tangential, cut.centre_distance), 3),
            "dwell": round(DWELL_TABLE_TURNS * 60 / table_speed, 1),
            **cut_feeds(cut, cutting, hob.starts, gear.teeth)} for cut in cuts}
        y_clear = round(tangential_clearance(gear, hob, setup.full_depth), 3) if tangential else 0.0
        params = {**self.base_params(gear, gear_class, hob, machine, cutting, choices, setup),
                  "shift_on": False, "shift_y": 0.0, "shift_per_part": 0.0, "shift_min": 0.0, "shift_max": 0.0,
                  "z_mid": round(-gear.face_width / 2, 3), "tangential": tangential,
                  # the header's feed word: a worm wheel has no axial pass to be climb or conventional
                  # (new-user review 29: `climb` on a RADIAL cut, or relabelled by --feed-mode)
                  "feed_mode": choices.worm_feed,
                  "y_start": y_clear, "y_end": -y_clear,
                  "tangential_factor": round(conventions.tangential_factor(hob.module, gear.teeth, setup.lead), 6)}
        xs = [setup.x_retract] + [cut["cut_x"] for cut in module_params.values() if cut["cut_on"]]
        params.update(working_area(xs, [0.0, y_clear, -y_clear], [params["z_mid"]]))
        return self.for_machine(params, module_params, machine, hob)


def cut_feeds(cut, cutting, starts: int, teeth: int) -> dict:
    """Feeds of one cut in mm/min (G94). A radial cut's plunge is the cut itself (§B10: X plunges
    while the table turns), so the finishing plunge runs at the finishing radial feed, not the
    roughing one a cylindrical gear's infeed in air takes (issue 29); the tangential feed of a
    cut at its kind's axial feed (a tangential wheel is one cut, a rough one)."""
    finish = cut.name == "FINISH"
    radial = cutting.finish_radial_feed if finish else cutting.radial_feed
    axial = cutting.axial_feed_finish if finish else cutting.axial_feed_rough
    return {"feed_radial": programmed_feed(per_minute(radial, cutting.hob_speed, starts, teeth)),
            "feed_tangential": programmed_feed(per_minute(axial, cutting.hob_speed, starts, teeth))}


def one_tangential_cut(gear, choices):
    """A tangential pass feeds the hob through the wheel at full depth once (§B10): one cut, and
    the header says so (it said the module's two, and the simulation, following one, refused every
    tangential wheel over m 3: new-user review 29). Two cuts asked for are refused, not dropped."""
    if choices.cuts == 2:
        raise InputError(f"gear {gear.id}: two cuts with a tangential feed: a tangential pass cuts the full depth "
                          "once; give --cuts 1, or --worm-feed radial for a rough and a finishing plunge")
    return replace(choices, cuts=1)


def check_module_stated(gear) -> None:
    """A worm wheel's module must be stated as axial or normal (gear.module_kind): worm drawings
    usually give the worm's axial module m_x, and m_n = m_x·cos γ; a guess cuts the wrong depth."""
    if gear.module_kind is None:
        raise InputError(f"gear {gear.id}: worm wheel module {gear.module:g} is not stated as axial or normal; set "
                          "module_kind (axial: the worm's axial module, as worm drawings give it) in the gear file "
                          "and import it again, or UPDATE gear SET module_kind")


def tangential_clearance(gear, hob, centre_distance: float) -> float:
    """Y where the whole hob is clear of the wheel: the half-chord of the wheel's tip circle
    at the hob's tip-cylinder distance, plus half the hob length and a safety margin."""
    tip_radius, hob_radius = gear.tip_diameter / 2, hob.tip_diameter / 2
    reach = math.sqrt(max(0.0, tip_radius ** 2 - (centre_distance - hob_radius) ** 2))
    return reach + hob.length / 2 + APPROACH_SAFETY


def air_position(gear, hob, tangential: bool, centre_distance: float) -> float:
    """Where the rapid approach ends. Radial: the hob tip just outside the wheel's tip in the
    mid-plane, (d_a2 + d_a0)/2 plus the rapid's margin; the plunge from there is all cut.
    Tangential: the hob stands beside the wheel in Y, so the whole infeed is in air."""
    if tangential:
        return centre_distance + RAPID_SHORT_OF_CUT
    return (gear.tip_diameter + hob.tip_diameter) / 2 + RAPID_SHORT_OF_CUT
