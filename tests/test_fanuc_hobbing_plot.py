"""Both plots draw Fanuc hobbing programs (issue 30, "Must show"): the seeded templates' 840D
program for a gear and its Fanuc twin (tests/helpers/fanuc_stored.py: G81 T<z2> L<±z0> [Q P] /
G80, on a copy of the 840D hobber's record with dialect "fanuc") are drawn from the same data:
every path, outline, arrow and number of the picture is built from the same coordinates, and
the coupling is labelled in each program's own words (`EGON(…)`, `G81 T19 L-1`, its T and L
computed here from the reference, fanuc-egb.md §F5). What the 840D program has and the Fanuc
grammar has not (the G25/G26 working area) is the only thing missing. A line the plot cannot
read is refused in one line naming it and the dialect.

The twin stored by hand serves the comparisons on any record's senses and helix sign, and the
programs no template writes (a line left in 840D form, Q/P on a record without egb_helix_sign);
the library's load_scene reads it. `engine plot` plots only a program that is its template's
rendering (engine.programs.rendering, issue 26), so the CLI test plots the program
`engine instantiate --machine hobber-fanuc` makes, and its job."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import psycopg
import pytest
from helpers.fanuc_programs import g81
from helpers.fanuc_stored import fanuc_twin

from engine.errors import EngineError
from engine.gears.records import load_gear, load_hobs
from engine.hobbing.choices import Choices
from engine.hobbing.job_plot import plot_hobbing_job
from engine.hobbing.program_plot import load_scene, program_figure
from engine.machines.records import load_machine
from engine.programs.instantiate import instantiate_gear

SPUR = 42                       # seeded spur gear: m 2, z 19, its hob one-start right hand
HELICAL = 43                    # seeded helical gear, right hand: m 3, z 41, β 15°
NO_TAILSTOCK = Choices(tailstock=False)   # the Fanuc grammar has no tailstock M code
HELIX = "hand coupling helix"   # the helix the program's coupling generates, in the hand check
ONLY_840D = "working area"      # gids of the G25/G26 limits, which a Fanuc hobbing program has not
PNG = b"\x89PNG\r\n\x1a\n"


def plotted(figure) -> list:
    """Per panel, the coordinates every line, outline and arrow is drawn from (data units), with
    its name: what the picture shows, not its pixels. A move's path is named by its program line
    (`line 17`), which the twin numbers otherwise; the 840D-only working area is left out."""
    panels = []
    for axes in figure.axes:
        drawn = [(line.get_gid(), line.get_xydata()) for line in axes.lines]
        drawn += [(patch.get_gid(), patch.get_patch_transform().transform(patch.get_path().vertices))
                  for patch in axes.patches]
        drawn += [(text.get_gid(), np.array([text.xy, text.xyann])) for text in axes.texts if hasattr(text, "xyann")]
        panels.append([(re.sub(r"\bline \d+$", "line", gid or ""), data) for gid, data in drawn
                       if ONLY_840D not in (gid or "")])
    return panels


def assert_same_paths(siemens, fanuc) -> None:
    """Every coordinate the same, but the generated helix's (assert_same_helix)."""
    left, right = plotted(siemens), plotted(fanuc)
    assert [[gid for gid, _ in panel] for panel in left] == [[gid for gid, _ in panel] for panel in right]
    for panel, other in zip(left, right):
        for (gid, data), (_, same) in zip(panel, other):
            assert gid == HELIX or np.allclose(data, same, atol=1e-9, equal_nan=True), gid


def assert_same_helix(siemens, fanuc, gear) -> None:
    """The helix each coupling generates, drawn at the same angle to what each program can write:
    the 840D's EGON Z term k to 1e-6 °/mm, a β within ½·1e-6·π·m_n·z2/(360·cos β) rad of the
    gear's (β = asin(k·π·m_n·z2/360), fanuc-egb.md §F4), the Fanuc P to 0.001°, within 0.0005°."""
    beta = math.radians(gear.helix_angle)
    egon = math.degrees(0.5e-6 * math.pi * gear.module * gear.teeth / (360 * math.cos(beta)))
    assert helix_direction(siemens) == pytest.approx(helix_direction(fanuc), abs=egon + 0.0005 + 1e-9)


def helix_direction(figure) -> float:
    """The generated helix's first line in the hand check, degrees from +Y toward +Z."""
    line = next(line for line in figure.axes[4].lines if line.get_gid() == HELIX)
    (y0, z0), (y1, z1) = line.get_xydata()[:2]
    return math.degrees(math.atan2(z1 - z0, y1 - y0))


def numbers(figure) -> list[str]:
    return said_alike([text.get_text() for text in figure.axes[3].texts])


def said_alike(texts: list[str]) -> list[str]:
    """Texts with their line numbers and the 840D's `A=` form left out (the twin has other line
    numbers and writes `A1.763`; a panel wraps the shorter text elsewhere), and without the
    840D-only working area."""
    return [re.sub(r"line \d+", "line N", " ".join(text.replace("A=", "A").split())) for text in texts
            if not text.startswith(ONLY_840D)]


def helix_label(figure) -> str:
    return next(line.get_label() for line in figure.axes[4].lines if line.get_gid() == HELIX)


def twins(conn, gear_id: int, helix_sign: int | None = None):
    """(840D scene, Fanuc scene) of the gear's program and its Fanuc twin."""
    program_id = stored(conn, gear_id)
    _, twin = fanuc_twin(conn, program_id, helix_sign)
    return load_scene(conn, program_id), load_scene(conn, twin)


def stored(conn, gear_id: int) -> int:
    """The id of the 840D program the seeded templates make for the gear (proved, stored)."""
    program_id = instantiate_gear(conn, gear_id, choices=NO_TAILSTOCK).program_id
    assert program_id is not None
    return program_id


@pytest.mark.parametrize("gear_id, helix_sign", [(SPUR, None), (HELICAL, 1), (HELICAL, -1)],
                         ids=["spur", "helical sign +1", "helical sign -1"])
def test_the_fanuc_twin_is_drawn_from_the_same_paths_and_numbers(conn, gear_id, helix_sign):
    siemens, fanuc = twins(conn, gear_id, helix_sign)
    assert fanuc.machine.dialect == "fanuc" and siemens.machine.dialect == "840d"
    (left, said), (right, drawn) = program_figure(siemens), program_figure(fanuc)
    assert "it proves the program" in drawn[-1] and "REFUSED" not in right.get_suptitle()
    assert_same_paths(left, right)
    assert_same_helix(left, right, siemens.gear)
    assert numbers(left) == numbers(right)
    assert said_alike(said) == said_alike(drawn)


@pytest.mark.parametrize("gear_id, helix_sign", [(SPUR, None), (HELICAL, -1)], ids=["spur", "helical"])
def test_the_coupling_is_labelled_in_the_programs_own_words(conn, gear_id, helix_sign):
    """T = z2, L = −h_hob·c·b·z0 and, helical, Q = m_n, P = −h_gear·c·z·egb_helix_sign·β (§F5),
    computed by the helper from the records; the swivel as the program writes it."""
    siemens, fanuc = twins(conn, gear_id, helix_sign)
    left, right = program_figure(siemens)[0], program_figure(fanuc)[0]
    egon = next(text for text in load_lines(conn, siemens.program_id) if text.startswith("EGON("))
    assert helix_label(left).startswith(f"helix the program's {egon} generates: ")
    words = g81(fanuc.gear, fanuc.hob, fanuc.machine)
    assert fanuc.hob.hand == "R" and (fanuc.machine.c_direction, fanuc.machine.b_direction) == (1, 1)
    assert words.startswith(f"G81 T{fanuc.gear.teeth} L{-fanuc.hob.starts}")   # DIN record, right-hand hob
    assert helix_label(right).startswith(f"helix the program's {words} generates: ")
    assert helix_label(left).split(" generates: ")[1] == helix_label(right).split(" generates: ")[1]
    swivel = next(text.get_text() for text in right.axes[3].texts if text.get_gid() == "number swivel")
    assert re.match(r"swivel A-?\d+\.\d{3}° \(line \d+, as written", swivel)


def load_lines(conn, program_id: int) -> list[str]:
    return conn.execute("SELECT lines FROM program WHERE id = %s", (program_id,)).fetchone()[0]


def test_a_line_the_fanuc_reading_refuses_is_refused_naming_the_line_and_the_dialect(conn):
    program_id = stored(conn, SPUR)
    swivel = next(line for line in load_lines(conn, program_id) if line.startswith("G0 A="))
    written = swivel.replace("A=", "A")
    _, twin = fanuc_twin(conn, program_id, mistake=(written, swivel))   # the 840D form left in
    with pytest.raises(EngineError) as refused:
        load_scene(conn, twin)
    message = str(refused.value)
    assert "\n" not in message and f"program {twin} is not drawn" in message
    assert f"'{swivel}'" in message and "dialect fanuc" in message and "Fanuc hobbing" in message


def test_a_helical_coupling_the_record_cannot_sign_is_refused_naming_the_dialect(conn):
    """Q and P on a record without egb_helix_sign: the reading cannot tell the hand they cut
    (fanuc-egb.md §F5), so the picture is refused before anything is drawn."""
    _, twin = fanuc_twin(conn, stored(conn, HELICAL))
    with pytest.raises(EngineError, match=rf"^program {twin} is not drawn \(read in .*'s dialect fanuc\): GEAR43 line "
                                          r"\d+ 'G81 T41 L-1 Q3\. P-?15\.000': the sign of the Fanuc helical "
                                          r"compensation is not stated"):
        load_scene(conn, twin)


def test_the_job_plot_draws_the_fanuc_job(conn, tmp_path):
    job, twin = fanuc_twin(conn, stored(conn, SPUR))
    drawn = plot_hobbing_job(conn, job, tmp_path / "job.png")
    assert drawn[0].startswith(f"program {twin} (") and "it proves the program" in drawn[-1]
    assert (tmp_path / "job.png").read_bytes()[:8] == PNG


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_engine_plot_writes_a_png_of_a_fanuc_program_and_job(run, tmp_path):
    """The program the templates make on the seeded Fanuc hobber, and its job, through the CLI
    with the rendering check in place: the stored program is its template's rendering."""
    made = json.loads(run("instantiate", "--gear", SPUR, "--machine", "hobber-fanuc", "--no-tailstock",
                          "--json").stdout)
    with psycopg.connect(run.url) as conn:
        lines = load_lines(conn, made["program_id"])
        hob_id = conn.execute("SELECT hob_id FROM job WHERE id = %s", (made["job_id"],)).fetchone()[0]
        words = g81(load_gear(conn, SPUR), next(hob for hob in load_hobs(conn) if hob.id == hob_id),
                    load_machine(conn, "hobber-fanuc"))
    assert lines[0] == "%" and words in lines   # T = z2, L = −h_hob·c·b·z0 (§F5)
    for option, subject in (("--program", made["program_id"]), ("--job", made["job_id"])):
        result = run("plot", option, subject, "-o", tmp_path / f"{option[2:]}.png")
        assert result.exit_code == 0, result.output
        assert (tmp_path / f"{option[2:]}.png").read_bytes()[:8] == PNG
        assert "working area G25" not in result.stdout and "working area: none" in result.stdout
        assert "it proves the program" in result.stdout
