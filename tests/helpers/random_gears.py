"""Random spur and helical gears for the feed tests' populations (feed marks, chip thickness):
m1–4 (the seeded machine's range), 12–120 teeth, b 6–12·m, β 0 (half of them) or 10–20°."""
from __future__ import annotations

MODULES = (1, 1.5, 2, 2.5, 3, 4)
INSERT = ("INSERT INTO gear (id, gear_class, module, teeth, pressure_angle, helix_angle, hand, face_width, "
          "material, hardness, quality_grade) VALUES (%s, %s, %s, %s, 20, %s, %s, %s, %s, 200, %s)")


def insert_gears(conn, rng, first: int, count: int, grade: int) -> list[int]:
    """`count` gears with ids from `first`, graded `grade`, drawn with `rng`; their ids."""
    ids = []
    for number in range(count):
        module, beta = rng.choice(list(MODULES)), rng.choice([0, 0, 10, 15, 20])
        conn.execute(INSERT, (first + number, "helical" if beta else "spur", module, rng.randint(12, 120), beta,
                              rng.choice("RL") if beta else None, round(rng.uniform(6, 12) * module),
                              rng.choice(["45", "40Cr", "20CrMnTi"]), grade))
        ids.append(first + number)
    return ids
