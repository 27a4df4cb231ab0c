"""Hand-written hobbing programs for the simulation tests, every value computed here from the
reference (docs/reference/hobbing.md §A5, §A7, §B) and the gear, hob and machine records,
never from the engine: the program a careful programmer would write, and its mistakes."""
from __future__ import annotations

import math
from dataclasses import dataclass, field


def hand(h: str | None) -> int:
    return -1 if h == "L" else 1


def lead_angle(hob) -> float:
    """sin γ = z0·m_n/(d_a0 − 2.5·m_n) (§B1), degrees."""
    return math.degrees(math.asin(hob.starts * hob.module / (hob.tip_diameter - 2.5 * hob.module)))


def swivel(gear, hob) -> float:
    """A = h_hob·γ − h_gear·β (§A7)."""
    return hand(hob.hand) * lead_angle(hob) - hand(gear.hand) * gear.helix_angle


def k_z(gear, teeth: int) -> float:
    return -hand(gear.hand) * 360 * math.sin(math.radians(gear.helix_angle)) / (math.pi * gear.module * teeth)


def k_y(gear, hob, teeth: int) -> float:
    return 360 * math.cos(math.radians(lead_angle(hob))) / (math.pi * gear.module * teeth)


def least_run_out(gear, hob) -> float:
    """§B8: the generating zone reaches (h/tan α_n)·sin|η| past the hob centre, h = 2.25·m_n."""
    depth = 2.25 * gear.module
    return depth / math.tan(math.radians(gear.pressure_angle)) * math.sin(math.radians(abs(swivel(gear, hob))))


def full_depth(root_diameter: float, hob) -> float:
    """a = (d_f2 + d_a0)/2 (§B3)."""
    return (root_diameter + hob.tip_diameter) / 2


def approach(gear, hob) -> float:
    """§B7 conservative run-in at full depth plus 2 mm."""
    h = (gear.tip_diameter - gear.root_diameter) / 2
    eta = math.radians(abs(swivel(gear, hob)))
    spur = math.sqrt(h * (hob.tip_diameter - h))
    return spur / math.cos(eta) + math.tan(eta) * math.sqrt(h * (gear.tip_diameter - h)) + 2.0


@dataclass
class Hand:
    """An axial climb pass for a cylindrical gear (unit 1), in the DIN frame unless senses say
    otherwise; fields to change for a mistake."""
    gear: object
    hob: object
    speed: float = 246.0
    radial_feed: float = 36.0
    axial_feed: float = 38.0         # §C: at most 3.0 mm/rev at m2, table 246/19 r/min: 38.8 mm/min
    run_out: float | None = None       # default: 3 mm, or 1 mm past the §B8 least where that is more
    stock: float = 0.0                 # radial: the cut stops this far above full depth
    senses: dict = field(default_factory=lambda: {"a": 1, "b": 1, "c": 1, "y": 1, "z": 1})
    header: str | None = "auto"        # a `; CYCLE TIME … MIN` line; "auto": the program's own time, None: none
    tailstock: bool = True
    teeth: int | None = None           # the EGON denominator (default: the gear's)
    a_value: float | None = None       # the swivel written (DIN), default the reference
    z_term: float | None = None        # the Z factor written (DIN), default the reference

    @property
    def x_cut(self) -> float:
        return full_depth(self.gear.root_diameter, self.hob) + self.stock

    @property
    def x_retract(self) -> float:
        return (self.gear.tip_diameter + self.hob.tip_diameter) / 2 + 5.0

    @property
    def z_start(self) -> float:
        return approach(self.gear, self.hob)

    @property
    def z_end(self) -> float:
        run_out = max(3.0, least_run_out(self.gear, self.hob) + 1.0) if self.run_out is None else self.run_out
        return -self.gear.face_width - run_out

    def lines(self, cut: list[str] | None = None) -> list[str]:
        body = self._body(cut)
        if self.header == "auto":
            return body[:2] + [f"; CYCLE TIME {program_minutes(body, RAPID_RATE, LOAD):.1f} MIN"] + body[2:]
        return body[:2] + ([self.header] if self.header else []) + body[2:]

    def _body(self, cut: list[str] | None) -> list[str]:
        s = self.senses
        teeth = self.teeth or self.gear.teeth
        a_value = swivel(self.gear, self.hob) if self.a_value is None else self.a_value
        egon = f'EGON(C,"FINE",B,{-hand(self.hob.hand) * self.hob.starts * s["c"] * s["b"]},{teeth}'
        factor = k_z(self.gear, teeth) if self.z_term is None else self.z_term
        helical = self.gear.helix_angle != 0
        egon += f",Z,{factor * s['c'] * s['z']:.6f},1)" if helical else ")"
        z = s["z"]
        return ["%_N_TEST_MPF", ";$PATH=/_N_MPF_DIR",
                "G90 G71 G94", "G25 X20.000 Y-80.000 Z-350.000", "G26 X320.000 Y80.000 Z150.000", "WALIMON",
                *(["M20"] if self.tailstock else []),
                f"G0 X{self.x_retract:.3f} Z{self.z_start * z:.3f}", f"G0 A={a_value * s['a']:.3f}", "G0 Y0.000",
                "EGDEF(C,B,1,Z,1)" if helical else "EGDEF(C,B,1)", egon, f"M3 S{self.speed:g}",
                *(cut if cut is not None else self.cut()),
                "EGOFS(C)", "EGDEL(C)", "M5", *(["M21"] if self.tailstock else []), "M30"]

    def cut(self) -> list[str]:
        z = self.senses["z"]
        return [f"G1 X{self.x_cut:.3f} F{self.radial_feed:.1f}", f"G1 Z{self.z_end * z:.3f} F{self.axial_feed:.1f}",
                f"G0 X{self.x_retract:.3f}"]

    def cycle_time(self, rapid_rate: float, load: tuple) -> float:
        """The BRIEF's definition, from the load position."""
        x0, z0 = load
        minutes = max(abs(self.x_retract - x0), abs(self.z_start - z0)) / rapid_rate
        minutes += (self.x_retract - self.x_cut) / self.radial_feed
        minutes += (self.z_start - self.z_end) / self.axial_feed
        return minutes + (self.x_retract - self.x_cut) / rapid_rate


RAPID_RATE, LOAD = 8000.0, (300.0, 100.0)      # the seeded hobber-840d's G0 rate and load position


def program_minutes(lines: list[str], rapid_rate: float, load: tuple) -> float:
    """The BRIEF's cycle time of a program's blocks: G1 path length / F, G0 the longest axis travel
    / rapid rate, G4 F<s> s seconds, from the load position."""
    at, feed, motion, minutes = {"X": load[0], "Z": load[1]}, None, None, 0.0
    for line in lines:
        tokens = [w for w in line.partition(";")[0].split() if w[:1] in "GXYZF" and "=" not in w and "(" not in w]
        words = {w[0]: w[1:] for w in tokens if w[0] != "G"}
        codes = {w[1:] for w in tokens if w[0] == "G"}
        motion = 0 if "0" in codes else 1 if "1" in codes else motion
        if "4" in codes:
            minutes += float(words["F"]) / 60
            continue
        feed = float(words["F"]) if "F" in words else feed
        delta = [float(words[a]) - at.get(a, float(words[a])) for a in "XYZ" if a in words]
        at.update({a: float(words[a]) for a in "XYZ" if a in words})
        if delta and motion == 0:
            minutes += max(abs(d) for d in delta) / rapid_rate
        elif delta and motion == 1:
            minutes += math.sqrt(sum(d * d for d in delta)) / feed
    return minutes


def with_cycle_time(lines: list[str]) -> list[str]:
    """The program with its `; CYCLE TIME` header after the program name (on the seeded machine)."""
    return lines[:1] + [f"; CYCLE TIME {program_minutes(lines, RAPID_RATE, LOAD):.1f} MIN"] + lines[1:]


def number_of(lines: list[str], text: str) -> int:
    """The line number (from 1) of the line that is `text`."""
    return lines.index(text) + 1
