"""Cycle time of a hobbing program, the header line `; CYCLE TIME <min> MIN` (issue 14).

The definition the simulation checks the header against, from the program text alone: over
the blocks in order, a G1 takes its path length √(ΔX²+ΔY²+ΔZ²)/F (G94, mm/min), a G0 takes
max(|ΔX|,|ΔY|,|ΔZ|)/rapid_rate (each axis at the rapid rate), `G4 F<s>` takes s seconds, and
rotary-only or non-motion blocks take nothing. The program starts at the machine's load
position where it has one; an axis whose start is unknown (no load position, or Y) moves
from wherever its first block puts it, which counts as no travel.

The models replay here every motion their templates emit, in the same order, so the time is
known before the program is written."""
from __future__ import annotations

import math

from ..errors import EngineError


class Clock:
    """Minutes of motion so far and the position the last block left."""

    def __init__(self, rapid_rate: float, start: dict):
        self.rapid_rate, self.position, self.minutes = rapid_rate, dict(start), 0.0

    def rapid(self, **axes: float) -> None:
        self.minutes += max(abs(v - self.position.get(a, v)) for a, v in axes.items()) / self.rapid_rate
        self.position.update(axes)

    def feed(self, rate: float, **axes: float) -> None:
        if not (isinstance(rate, (int, float)) and rate > 0):   # a runner's job may say F0 (issue 26)
            raise EngineError(f"a cut's feed is {rate!r} mm/min: no cut moves at that; give the job's feeds "
                              "(feed_axial, feed_radial, …) values above 0 mm/min, or plan the job anew")
        length = math.sqrt(sum((v - self.position.get(a, v)) ** 2 for a, v in axes.items()))
        self.minutes += length / rate
        self.position.update(axes)

    def dwell(self, seconds: float) -> None:
        self.minutes += seconds / 60


def axial_pass(clock: Clock, job: dict, cut: dict) -> None:
    """Rapid to the approach Z and to just outside the cut's X, infeed, axial pass, retract."""
    clock.rapid(Z=cut["z_from"])
    clock.rapid(X=cut["x_air"])
    clock.feed(cut["feed_radial"], X=cut["cut_x"])
    clock.feed(cut["feed_axial"], Z=cut["z_to"])
    clock.rapid(X=job["x_retract"])


def taper_pass(clock: Clock, job: dict, cut: dict) -> None:
    """Infeed, along Z to the polyline, the polyline tangent to the root cone (issue 29) with
    F along the slant, along Z to the run-out; the blocks along Z only where they move."""
    polyline_pass(clock, job, cut, "taper_x_", cut["feed_slant"])


def crowned_pass(clock: Clock, job: dict, cut: dict) -> None:
    """Infeed at the face depth, to the first face, the parabola a(Z) as a polyline, overrun."""
    polyline_pass(clock, job, cut, "crown_x_", cut["feed_axial"])


def polyline_pass(clock: Clock, job: dict, cut: dict, vertex: str, segment_feed: float) -> None:
    """A pass whose centre distance follows the cut's vertices `<vertex>0` … `<vertex>n`, evenly
    spaced in Z from face_from to face_to, each segment at `segment_feed` (mm/min)."""
    clock.rapid(Z=cut["z_from"])
    clock.rapid(X=cut["x_air"])
    clock.feed(cut["feed_radial"], X=cut[f"{vertex}0"])
    clock.feed(cut["feed_axial"], Z=cut["face_from"])
    segments = sum(name.startswith(vertex) for name in cut) - 1   # the polyline's vertices, 0…n
    for step in range(1, segments + 1):
        z = cut["face_from"] + (cut["face_to"] - cut["face_from"]) * step / segments
        clock.feed(segment_feed, X=cut[f"{vertex}{step}"], Z=z)
    clock.feed(cut["feed_axial"], Z=cut["z_to"])
    clock.rapid(X=job["x_retract"])


def worm_pass(clock: Clock, job: dict, cut: dict) -> None:
    """Radial: rapid to just outside the wheel, plunge, dwell. Tangential: infeed in air beside
    the wheel, feed along Y through it, retract and return to the Y start."""
    clock.rapid(X=cut["x_air"])
    clock.feed(cut["feed_radial"], X=cut["cut_x"])
    if job["tangential"]:
        clock.feed(cut["feed_tangential"], Y=job["y_end"])
    else:
        clock.dwell(cut["dwell"])
    clock.rapid(X=job["x_retract"])
    if job["tangential"]:
        clock.rapid(Y=job["y_start"])


PASSES = {"axial": axial_pass, "taper": taper_pass, "crowned": crowned_pass, "worm": worm_pass}


def cycle_time(job: dict, cuts: list[dict], shape: str, rapid_rate: float) -> float:
    """Minutes of the whole program: to the start position, Y, every cut in order, the load
    position. `job` and `cuts` in program values (engine.hobbing.conventions)."""
    load = {"X": job["load_x"], "Z": job["load_z"]} if job["load_position"] else {}
    clock = Clock(rapid_rate, load)
    start_z = job["z_mid"] if shape == "worm" else job["z_start"]
    if load:   # out in X above the work, then down: one rapid in both would sweep the hob over the gear
        clock.rapid(X=job["x_retract"])
        clock.rapid(Z=start_z)
    else:
        clock.rapid(X=job["x_retract"], Z=start_z)
    clock.rapid(Y=job["y_start"] if shape == "worm" else job["shift_y"])
    for cut in cuts:
        PASSES[shape](clock, job, cut)
    if load:   # up at the retract X, then in: the same the other way round
        clock.rapid(Z=load["Z"])
        clock.rapid(X=load["X"])
    return clock.minutes
