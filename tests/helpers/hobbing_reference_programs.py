"""Hand-computed correct hobbing programs, to prove the reference checks pass what is right and
catch planted faults. Every number below was worked out by hand from the reference:

* spur m2 z30 b20 d_a 64 d_f 55, hob R z0 1 d_a0 70: γ = asin(2/65) = 1.763°, A = +1.763, B −1:30,
  full depth (55 + 70)/2 = 62.5, h 4.5, §B7 E = √(4.5·65.5) = 17.17 → approach Z20; S300 → n2 10 r/min,
  F25 = 2.5 mm/rev ≤ 3.0 (§C m2);
* helical R m3 z41 β15 (d_a 133.339, d_f 119.839), hob R d_a0 80 on a machine with A, C and Z reversed:
  γ = 2.372°, A_DIN = 2.372 − 15 = −12.628 → A=12.628; k_B −1:41 × c → +1:41; k_Z = −0.241126 × c·z
  (= +1) → −0.241126; full depth 99.919; §B7 E ≤ 29.34 → Z_DIN 31 = Z_prog −31;
* tangential worm wheel L m3 z40 β = γ = 4.048° (d_a 126.3, d_f 112.8), hob L z0 1 d_a0 50 L90:
  B +1:40, k_Y = +360 cos γ/(π·3·40) = 0.952548, A 0, full depth 81.4, hob clear of the wheel for
  |Y| ≥ 45 + √(63.15² − 56.4²) = 73.41 → Y ±76;
* duplex m2: unit 1 z30 b20 d_a 64 over unit 2 z19 b15 d_a 42 (top Z−75), hob R d_a0 70 L100:
  unit 2's infeed at Z−57 is 18 ≥ 17.17 above its face, and its hob (swivel 1.763°: ±1.54 mm along Z)
  stays hypot(51.5 − 32, 57 − 1.54 − 20) = 40.5 ≥ 35 from unit 1's bottom tip corner (at Z−45: 30.5).
"""
from __future__ import annotations

from helpers.hobbing_checks import (
                                    Case,
                                    Job,
                                    approach_problems,
                                    contract_problems,
                                    coupling_problems,
                                    depth_problems,
                                    envelope_problems,
                                    feed_problems,
)
from helpers.hobbing_machine_checks import cycle_time_problems, obstacle_problems, table_speed_problems
from helpers.hobbing_reference import Gear, Hob, Machine, Unit

SPUR = """%_N_REFSPUR_MPF
;$PATH=/_N_MPF_DIR
; CYCLE TIME 2.3 MIN
; GEAR hand-written
G90 G71 G94
G25 X20.000 Y-1.000 Z-30.000
G26 X300.000 Y1.000 Z120.000
WALIMON
T1 D1
G54
G0 X80.000 Z20.000
G0 Y0.000
G0 A=1.763
EGDEF(C,B,1)
EGON(C,"FINE",B,-1,30)
M3 S300
M8
G1 X62.500 F36
G1 Z-24.000 F25
G0 X80.000
M9
EGOFS(C)
EGDEL(C)
M5
G0 X300.000 Z100.000
M30"""

HELICAL_MIRROR = """%_N_REFHEL_MPF
;$PATH=/_N_MPF_DIR
; CYCLE TIME 4.2 MIN
G90 G71 G94
G25 X20.000 Y-1.000 Z-120.000
G26 X300.000 Y1.000 Z40.000
WALIMON
T1 D1
G54
G0 X112.000 Z-31.000
G0 Y0.000
G0 A=12.628
EGDEF(C,B,1,Z,1)
EGON(C,"FINE",B,1,41,Z,-0.241126,1)
M3 S338
M8
G1 X99.919 F8.0
G1 Z36.000 F24.7
G0 X112.000
M9
EGOFS(C)
EGDEL(C)
M5
G0 X300.000 Z-100.000
M30"""

WORM_TANGENTIAL_LEFT = """%_N_REFWORM_MPF
;$PATH=/_N_MPF_DIR
; CYCLE TIME 5.8 MIN
G90 G71 G94
G25 X20.000 Y-80.000 Z-100.000
G26 X300.000 Y80.000 Z120.000
WALIMON
T1 D1
G54
G0 X94.000 Z-12.500
G0 Y76.000
G0 A=0.000
EGDEF(C,B,1,Y,1)
EGON(C,"FINE",B,1,40,Y,0.952548,1)
M1=3 S1=460
M8
G1 X81.400 F11.1
G1 Y-76.000 F32.8
G0 X94.000
M9
EGOFS(C)
EGDEL(C)
M5
G0 X300.000 Z100.000
M30"""

DUPLEX = """%_N_REFDUPLEX_MPF
;$PATH=/_N_MPF_DIR
; CYCLE TIME 3.8 MIN
G90 G71 G94
G25 X20.000 Y-1.000 Z-100.000
G26 X300.000 Y1.000 Z120.000
WALIMON
G54
T1 D1
G0 X80.000 Z18.000
G0 Y0.000
G0 A=1.763
EGDEF(C,B,1)
EGON(C,"FINE",B,-1,30)
M3 S310
M8
G1 X62.500 F36
G1 Z-24.000 F25.8
G0 X80.000
EGOFS(C)
EGON(C,"FINE",B,-1,19)
G0 Z-57.000
G1 X51.500 F36
G1 Z-94.000 F40.8
G0 X80.000
M9
EGOFS(C)
EGDEL(C)
M5
G0 X300.000 Z100.000
M30"""

SPUR_CASE = Case(Gear("spur", 2, 0.0, None, (Unit(30, 20, 64.0, 55.0),)), Hob(1, 70.0, "R", 100.0))
HELICAL_CASE = Case(Gear("helical", 3, 15.0, "R", (Unit(41, 30, 133.339, 119.839),)), Hob(1, 80.0, "R", 120.0),
                    Machine("mirror", a=-1, c=-1, z=-1))
WORM_CASE = Case(Gear("worm_wheel", 3, 4.048, "L", (Unit(40, 25, 126.3, 112.8),)), Hob(1, 50.0, "L", 90.0),
                 job=Job(worm_feed="tangential"))
DUPLEX_CASE = Case(Gear("duplex", 2, 0.0, None, (Unit(30, 20, 64.0, 55.0), Unit(19, 15, 42.0, 33.0, -75.0))),
                   Hob(1, 70.0, "R", 100.0))

# name → (program, case, {fault: (text, replacement, the check that must find it)})
HAND_WRITTEN = {
    "spur": (SPUR, SPUR_CASE, {
        "no EGDEL": ("EGDEL(C)\n", "", contract_problems),
        "EGDEF twice": ("EGON(C", "EGDEF(C,B,1)\nEGON(C", contract_problems),
        "no work offset": ("G54\n", "", contract_problems),
        "no WALIMON": ("WALIMON\n", "", contract_problems),
        "Y not positioned": ("G0 Y0.000\n", "", contract_problems),
        "no M8": ("M8\n", "", contract_problems),
        "M30 not last": ("M30", "M30\nM5", contract_problems),
        "move outside G26": ("G26 X300.000", "G26 X250.000", contract_problems),
        "B sign": ("B,-1,30", "B,1,30", coupling_problems),
        "A sign": ("A=1.763", "A=-1.763", coupling_problems),
        "shallow": ("X62.500 F36", "X62.600 F36", depth_problems),
        "infeed in the blank": ("Z20.000", "Z16.000", approach_problems),
        "pass short of the far face": ("Z-24.000", "Z-19.000", approach_problems),
        "rough feed too high": ("F25", "F31", feed_problems),
        "rapid through the blank": ("G0 X300.000 Z100.000", "G0 X300.000 Z100.000\nG0 X40.000 Z-10.000",
                                    envelope_problems),
        "hob into the fixture": ("G0 X300.000 Z100.000", "G0 X300.000 Z-60.000\nG0 X40.000", obstacle_problems),
        "hob into the tailstock": ("G0 X300.000 Z100.000", "G0 X300.000 Z100.000\nG0 X40.000", obstacle_problems),
        "cycle time off": ("CYCLE TIME 2.3", "CYCLE TIME 2.6", cycle_time_problems),
        "no cycle time": ("; CYCLE TIME 2.3 MIN\n", "", cycle_time_problems),
    }),
    "helical on the mirrored machine": (HELICAL_MIRROR, HELICAL_CASE, {
        "Z factor with the DIN sign reversed": ("Z,-0.241126", "Z,0.241126", coupling_problems),
        "Z factor not 6 decimals": ("Z,-0.241126,1", "Z,-0.24113,1", coupling_problems),
        "B not transformed": ("B,1,41", "B,-1,41", coupling_problems),
        "A not transformed": ("A=12.628", "A=-12.628", coupling_problems),
        "approach short of §B7": ("Z-31.000", "Z-28.000", approach_problems),
        "table over its speed": ("M3 S338", "M3 S5000", table_speed_problems),
    }),
    "left-hand tangential worm wheel": (WORM_TANGENTIAL_LEFT, WORM_CASE, {
        "Y factor sign follows the hob hand": ("Y,0.952548", "Y,-0.952548", coupling_problems),
        "B sign": ("B,1,40", "B,-1,40", coupling_problems),
        "no Y leading axis": ("EGDEF(C,B,1,Y,1)", "EGDEF(C,B,1)", coupling_problems),
        "hob starts inside the wheel": ("G0 Y76.000", "G0 Y60.000", approach_problems),
        "plunge shallow": ("X81.400", "X81.500", depth_problems),
        "table over its speed": ("S1=460", "S1=5000", table_speed_problems),
    }),
    "duplex large over small": (DUPLEX, DUPLEX_CASE, {
        "unit 2 infeed too close to unit 1": ("G0 Z-57.000", "G0 Z-45.000", envelope_problems),
        "rapid up into unit 1": ("G1 Z-94.000 F40.8", "G1 Z-94.000 F40.8\nG0 Z-30.000", envelope_problems),
        "unit 2 shallow": ("X51.500", "X51.600", depth_problems),
        "unit 2 B ratio": ("B,-1,19", "B,-1,30", coupling_problems),
    }),
}
