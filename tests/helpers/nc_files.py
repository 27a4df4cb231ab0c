"""The real NC programs of tests/data/nc as the import tests use them: the files with their
parameters, the class each becomes, and the rows and programs read back from the database."""
from __future__ import annotations

import atexit
import shutil
import tempfile
from pathlib import Path

import psycopg

from engine.nc.layout import class_layout, nc_text
from engine.templates.decision_table import compiled_template
from engine.templates.store import load_template
from helpers.shared_data import shared_data

REAL = shared_data() / "nc"   # the files as their repositories have them


def _as_imported(real: Path) -> Path:
    """The real programs as a user imports them: a file with tabs is refused by import-nc, naming
    the line (issue 27), and comes in once its tabs are spaces, as the refusal says. A copy of
    tests/data/nc with each tab replaced by one space, made once per test process."""
    copy = Path(tempfile.mkdtemp(prefix="real_nc_"))
    atexit.register(shutil.rmtree, copy, True)
    for path in real.rglob("*"):
        if path.is_file():
            target = copy / path.relative_to(real)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(path.read_bytes().replace(b"\t", b" "))
    return copy


DATA = _as_imported(REAL)
NOT_PROGRAMS = (".tsv", ".expected")   # the provenance table; LinuxCNC's expected interpreter output
TABBED = sorted(str(path.relative_to(REAL)) for path in REAL.rglob("*")
                if path.is_file() and path.suffix not in NOT_PROGRAMS and b"\t" in path.read_bytes())
FAMILY = "linuxcnc/plasmac_family/"
MACROS = "linuxcnc/lathe_macros/"

# The job parameters of each file: values read off the file by hand (comments, the
# PlasmaC material line, the macro conversions).
PARAMS = {
    FAMILY + "metric_wrench.ngc": {"holes": 4, "path_tolerance": 0.125, "hole_x": 149.739, "hole_y": 27.45},
    FAMILY + "imperial_wrench.ngc": {"holes": 4, "path_tolerance": 0.005, "hole_x": 5.8952, "hole_y": 1.0807},
    FAMILY + "metric_ramp_pierce.ngc": {
        "path_tolerance": 0.254, "tracking_tolerance": 0.025, "pierce_end_height": 2.5, "gouge_speed": 980,
        "gouge_distance": 5, "creep_speed": 245, "cut_length": 60},
    FAMILY + "imperial_ramp_pierce.ngc": {
        "scale": 25.4, "path_tolerance": 0.005, "pierce_end_height": 2.5, "gouge_speed": 980,
        "gouge_distance": 5, "creep_speed": 245, "cut_length": 60},
    MACROS + "turning.ngc": {"mm_per_inch": 25.4, "m_per_ft": 0.3048, "finish_fraction": 0.6},
    MACROS + "facing.ngc": {"mm_per_inch": 25.4, "m_per_ft": 0.3048},
    MACROS + "boring.ngc": {"mm_per_inch": 25.4, "m_per_ft": 0.3048, "finish_factor": 1.5},
    MACROS + "threading.ngc": {"mm_per_inch": 25.4, "m_per_ft": 0.3048, "depth_factor": 1.0825,
                               "infeed_angle": 29.5, "feed_per_rev": 0.1, "max_rpm": 200},
    "linuxcnc/lathe_pawn.ngc": {},
    "linuxcnc/lathe_g70_71_demo.ngc": {"feed": 400, "stock_x": 15},
    "linuxcnc/ngcgui_lathe/od.ngc": {"clearance": 0.025},
    "linuxcnc/ngcgui_lathe/id.ngc": {"clearance": 0.025},
    # issue 27's LinuxCNC lathe programs: imported as they are (their values sit in expressions and
    # call arguments, which no plain parameter binds)
    **{f"linuxcnc/{name}": {} for name in (
        "lathe-g76.ngc", "lathe_g7x_quadrants.ngc", "lathe_g7x_face_boring.ngc", "lathecomp.ngc",
        "lathe_macros/chamfer.ngc", "lathe_macros/radius.ngc", "lathe_macros/drill.ngc",
        "ngcgui_lathe/taper-od.ngc", "ngcgui_lathe/g76diam.ngc", "ngcgui_lathe/g76base.ngc",
        "ngcgui_lathe/lathe_std.ngc", "lathe_macros/go_to_position.ngc", "lathe_macros/probe-hole.ngc",
        *(f"gmoccapy_lathe/{macro}.ngc" for macro in (
            "boring", "chamfer", "drilling", "facing", "grooving", "radius", "threading", "turning")))},
    # LinuxCNC's own interpreter tests of G70-G72 and G76 (tests/interp), as they are
    **{f"linuxcnc/interp_tests/{name}.ngc": {} for name in (
        "g71-with-g70", "g72-iterations-present", "g72-iterations-missing", "g71-endless-loop",
        "g71-endless-loop2", "g71-endless-loop_2", "g76only")},
    "sinumerik/cam_840dsl/CAM_TEST.MPF": {"feed": 250, "clear_z": 60, "approach_z": 53, "spindle_speed": 1061},
    "emco_from_dxf/testNegDXF.cnc": {"feed": 100, "z_clear": 3000, "arc_k": -500},
    "emco_from_dxf/testg02hemisphere.cnc": {"feed": 100, "z_clear": 3000},
    "emco_from_dxf/testg03hemisphere.cnc": {"feed": 100, "z_clear": 3000},
    "fanuc/FANUC0T.nc": {"feed": 0.3},
    "fanuc/0100.nc": {"feed": 0.35},
    "fanuc/TOKARKA.NC": {"feed": 0.3},
    "fanuc/PHILIPS.nc": {},
    # issue 27's corpus of other people's lathe programs (tests/test_real_lathe_corpus.py): imported
    # as they are, no value bound to a parameter
    **{name: {} for name in (
        "linuxcnc_extra/lathe-comp_test.ngc", "linuxcnc_extra/axis-lathe.ngc", "linuxcnc_extra/g76.ngc",
        "linuxcnc_extra/threading.ngc", "linuxcnc_extra/bad_spirals_lathe.ngc", "linuxcnc_extra/g33_blend.ngc",
        "linuxcnc_extra/g33_simple.ngc", "linuxcnc_extra/millturn_example.ngc",
        "lathe_easystep/Test_Bohren.ngc", "lathe_easystep/Test_Gewinde.ngc", "lathe_easystep/Test_Gewinde_innen.ngc",
        "lathe_easystep/Test_Innendrehen_mit_Gewinde.ngc", "lathe_easystep/test.ngc", "liblathe/profile.gcode",
        *(f"lathe_easystep/ngc/{name}.ngc" for name in ("Abdrehen", "Bohren", "Einstich", "Gewinde", "Planen")))},
}


def binds(o: str, name: str) -> bool:
    """Whether a stored row `o` prints parameter `name` into a word (engine.templates.nc_number)."""
    return "{" + name + ":~" in o


def bound_count(o: str, name: str) -> int:
    return o.count("{" + name + ":~")


def real_files():
    assert DATA.is_dir(), f"the real NC files are missing: {DATA} (tests/data/README.md)"
    found = sorted(str(p.relative_to(DATA)) for p in DATA.rglob("*") if p.is_file() and p.suffix not in NOT_PROGRAMS)
    assert set(found) == set(PARAMS), "a real file without parameters in PARAMS (or one gone)"
    return found


def class_name(relative: str) -> str:
    return "nc_" + Path(relative).stem.lower().replace("-", "_")   # lathe-g76.ngc: a class name has no -


def instantiate(conn, gear_class: str, params: dict) -> str:
    return "\n".join(compiled_template(load_template(conn, gear_class)).run(params).lines) + "\n"


def write(tmp_path, text: str, name: str = "program.nc") -> Path:
    path = tmp_path / name
    path.write_bytes(text.encode())
    return path


def stored_at(url):
    with psycopg.connect(url) as connection:
        return stored(connection)


def written_back(conn, gear_class: str, params: dict) -> bytes:
    """The class's program with the import's parameters, written with the class's layout."""
    lines = compiled_template(load_template(conn, gear_class)).run(params).lines
    return nc_text(lines, class_layout(conn, gear_class)).encode()


def stored_rows(conn, gear_class: str) -> dict[int, str]:
    """Line number → the stored `o` of its template row (row id 10 per line)."""
    return {row_id // 10: o for row_id, o in conn.execute(
        "SELECT t.id, c.o FROM class_template(%s) t JOIN component c ON c.id = t.component_id ORDER BY t.id",
        (gear_class,))}


def instantiated(conn, gear_class: str, params: dict) -> list[str]:
    return compiled_template(load_template(conn, gear_class)).run(params).lines


def stored(conn):
    return conn.execute("SELECT (SELECT count(*) FROM gear_class), (SELECT count(*) FROM assembly), "
                        "(SELECT count(*) FROM component)").fetchone()


class ImportedLibrary:
    """A private copy of the seeded database into which each real file is imported per test
    process (its class_name, its PARAMS), committed, its ImportReport kept (issue 28: TOKARKA.NC
    alone takes seconds to import, and several tests of several files import each real file the
    same way). Two files share a class name (lathe_macros/turning.ngc and gmoccapy_lathe/turning.ngc
    are both nc_turning): the class holds the file imported last, and asking for the other imports
    it again over it, as a user re-importing would. Tests read the library through a connection
    rolled back at their end (real_conn in tests/conftest.py), so what one test changes no other
    sees; the imports are the engine's, made when a test asks for the file, so a broken import
    fails that test."""

    def __init__(self, url: str):
        self.url = url
        self.holder: dict[str, tuple[str, object]] = {}   # class name → (file, its ImportReport)

    def imported(self, relative: str):
        """The ImportReport of importing DATA / relative as class_name(relative) with PARAMS[relative]."""
        held = self.holder.get(class_name(relative))
        if held is None or held[0] != relative:
            from engine.library.nc_import import import_nc
            with psycopg.connect(self.url) as conn:
                report = import_nc(conn, DATA / relative, class_name(relative), PARAMS[relative])
                conn.commit()
            held = self.holder[class_name(relative)] = (relative, report)
        return held[1]
