"""The hob's envelope next to a gear unit it must not cut (duplex and taper gears): the seeded
cylindrical hobs, a machine wide enough for any gear, cutting data, and the hob's surface in the gear's frame (mm)."""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from engine.gears.cutting_data import CuttingData
from engine.gears.records import Hob
from engine.machines.records import Machine

SEED_HOBS = Path(__file__).resolve().parents[2] / "seed_templates" / "hobs.csv"


MACHINE = Machine("wide", "hobber", "840d", 0, 2000, -300, 300, -2000, 500, 1000, None, None)
CUTTING = CuttingData(60, 200, 2.5, 1.5, 1.0, "test")


def hob_surface(radius: float, half_length: float, eta: float) -> np.ndarray:
    """Points on the hob's tip cylinder and end discs, relative to its centre (the contact
    point's axial station), axis (0, cos η, sin η). Built as arrays (issue 28: the lists of
    tuples this was made of took a tenth of the taper tests' time); the same points, same order."""
    phi = np.linspace(0, 2 * np.pi, 181)[:-1]
    along = np.linspace(-half_length, half_length, 61)
    rho = np.linspace(0, radius, 12)
    lateral = [np.repeat(along, phi.size), np.full(along.size * phi.size, radius), np.tile(phi, along.size)]
    ends = np.array([-half_length, half_length])
    discs = [np.repeat(ends, rho.size * phi.size), np.tile(np.repeat(rho, phi.size), 2), np.tile(phi, 2 * rho.size)]
    t, r, p = (np.concatenate(pair) for pair in zip(lateral, discs))
    axis, across = np.array([0, math.cos(eta), math.sin(eta)]), np.array([0, -math.sin(eta), math.cos(eta)])
    return (np.outer(t, axis) + np.outer(r * np.cos(p), [1, 0, 0]) + np.outer(r * np.sin(p), across))


def seeded_hobs() -> list[Hob]:
    with SEED_HOBS.open() as rows:
        return [Hob(r["id"], float(r["module"]), float(r["pressure_angle"]), int(r["starts"]),
                    float(r["tip_diameter"]), float(r["length"]), r["hand"], r["accuracy_class"],
                    r["material"], r["coating"], r["purpose"])
                for r in csv.DictReader(rows) if r["purpose"] == "cylindrical"]
