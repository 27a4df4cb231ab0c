"""Reading lathe programs (ISO and 840D) for tests, independently of the engine: the blocks of
one operation, and the feed moves with their start and end points (Z, radius); the diameters a
job's finish turns; distances to the drawn geometry."""
from __future__ import annotations

import math
import re

import ezdxf
import ezdxf.path

WORD = re.compile(r"(?<![A-Z=])([GXZFSTRK])(-?\d+(?:\.\d*)?)")
OPERATION = re.compile(r"^(?:\(|; )OP (\d+) ")


def operation_lines(lines: list[str], number: int) -> list[str]:
    """The blocks of operation `number`: from its comment to the next operation or M05/M5."""
    found, inside = [], False
    for line in lines:
        match = OPERATION.match(line)
        if match:
            inside = int(match.group(1)) == number
            continue
        if line in ("M05", "M5"):
            inside = False
        if inside:
            found.append(line)
    return found


def words(line: str) -> dict[str, float]:
    """Address words of a block (comments removed); G as the motion number."""
    code = re.sub(r"\(.*?\)|;.*$", "", line)
    return {letter: float(value) for letter, value in WORD.findall(code)}


def motions(lines: list[str]) -> list[tuple[int, tuple[float, float], tuple[float, float]]]:
    """(G number, start (z, r), end (z, r)) of every G0/G1/G2/G3/G32/G33 block, the position
    carried from block to block (X read as a diameter)."""
    position, found = None, []
    for line in lines:
        found_words = words(line)
        g = found_words.get("G")
        if g not in (0, 1, 2, 3, 32, 33) or ("X" not in found_words and "Z" not in found_words):
            continue
        z = found_words.get("Z", position[0] if position else None)
        r = found_words["X"] / 2.0 if "X" in found_words else (position[1] if position else None)
        if position is not None:
            found.append((int(g), position, (z, r)))
        position = (z, r)
    return found


# Distances to drawn geometry, from the DXF file through ezdxf, mirrored onto the axis.
FLATTENING_MM = 0.0005   # chords within 0.5 µm of the drawn arcs


def drawn_polylines(path) -> list[list[tuple[float, float]]]:
    """Every LINE, ARC, LWPOLYLINE of model space as points (z, |radius|) in drawing units,
    arcs flattened by ezdxf within FLATTENING_MM."""
    found = []
    for entity in ezdxf.readfile(path).modelspace():
        if entity.dxftype() in ("LINE", "ARC", "LWPOLYLINE") and entity.dxf.layer == "0":
            points = ezdxf.path.make_path(entity).flattening(FLATTENING_MM)
            found.append([(p.x, abs(p.y)) for p in points])
    return found


def distance_to_drawn(point: tuple[float, float], polylines) -> float:
    return min(distance_to_chord(point, a, b) for line in polylines for a, b in zip(line, line[1:]))


def distance_to_chord(point, a, b) -> float:
    (z0, r0), (z1, r1) = a, b
    dz, dr = z1 - z0, r1 - r0
    length_sq = dz * dz + dr * dr
    t = 0.0 if length_sq == 0 else max(0.0, min(1.0, ((point[0] - z0) * dz + (point[1] - r0) * dr) / length_sq))
    return math.dist(point, (z0 + t * dz, r0 + t * dr))


def finish_diameters(run, job_id: int) -> list[float]:
    """The diameters the finish (operation 2 of a profile job) runs along Z at, read from the text."""
    made = run("instantiate", "--job", job_id, "--dry-run")
    assert made.exit_code == 0, made.output
    finish = operation_lines(made.stdout.splitlines(), 2)
    return sorted({round(2 * start[1], 3) for g, start, end in motions(finish)
                   if g == 1 and start[1] == end[1] and start[0] != end[0]})


# Sampling a move for material it crosses: points per move, and the depth (mm) that counts as inside.
INSIDE_MM = 0.01               # deeper than this inside the blank is through material
SAMPLES_PER_MOVE = 40
