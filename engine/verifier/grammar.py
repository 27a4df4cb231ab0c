"""The dialects the verifier reads, declared as data: for each machine kind and controller
dialect of the machine record (machine.kind, machine.dialect), the header lines (and the
program name and number they carry), the comment form, the addresses and the kind of value
each takes (and which need a decimal point), the G codes and M codes allowed with their modal
groups, the keywords and statements, the word that gives a thread's lead, and the machine
state each motion needs (engine.verifier.machine_state).

Only what the seeded templates emit (and the controller reads the way the verifier assumes) is
in a dialect. Anything else is refused: a code such as G91 changes what every later position
means in a way a block-by-block reading cannot see, so it is not guessed at. The hobber selects
its work offset G54…G57 from the machine record (design notes §7); the positions are read in
that frame, the frame the working area and travel of the record are stated in. The door M
functions are the machine record's own (dialect_for)."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

import msgspec
from msgspec.structs import replace

from .machine_state import (
    FANUC_G81_4_HOBBING_STATE,
    FANUC_HOBBING_STATE,
    HOBBING_STATE,
    LATHE_840D_STATE,
    LATHE_ISO_STATE,
    LINUXCNC_STATE,
    StateRules,
)
from .refusals import Refused

if TYPE_CHECKING:
    from ..machines.records import Machine

# Value kinds of addresses (engine.verifier.words reads and checks each).
POSITION, ANGLE, FEED, SPEED, CODE, TOOL, TOOL_AND_OFFSET, OFFSET, RADIUS, PITCH = (
    "position", "angle", "feed", "speed", "code", "tool", "tool and offset", "offset", "radius", "pitch")
SPINDLE_POSITION = "spindle position"   # SPOS=<degrees>: orients the stopped spindle, moves no axis
SPEED_LIMIT = "speed limit"     # LIMS=<r/min>: the clamp of constant cutting speed G96 (reference sinumerik-lathe §S6)
TOOL_OR_NAME = "tool or name"   # 840D lathe: T1, or T="ROUGH" (a tool named in the tool list)
MOTION = "motion"          # the modal group of G0, G1, G2, G3 and threading
AXES = ("X", "Y", "Z")

# 840D program names (reference §A1): letters, digits and _, read in through `%_N_<name>_MPF`;
# the name read is then held to the program's own name and to engine.names (program).
NAME = r"(?P<name>[A-Za-z0-9_]+)"
# ISO: a comment ends at the first ")", so no "(" or ")" inside; and no "%", which ends the
# file on a memory card or tape (other characters are printable ASCII anyway:
# engine.verifier.characters reads every line first).
ISO_COMMENT_TEXT = r"[ -$&-'*-~]*"
# ISO dimension words without a decimal point are read in the control's least input increment
# on Fanuc-type controls with decimal-point input type I: X114 is 0.114 mm. An F without a point
# is read by a parameter's unit, or as a one-digit feed code F1…F9.
POINT_REASON = ("needs a decimal point: a Fanuc-type control with decimal-point input type I reads "
                "a number without one in its least input increment (X114 is 0.114 mm), and F by a "
                "parameter's unit or as a one-digit feed code")


class Header(msgspec.Struct, frozen=True):
    """A whole line of fixed form that may stand only at the given places ("first", "second",
    "last" line of the program), and must stand at those of `required`: a second `%_N_…_MPF`
    would start another program, and a program without its own would be stored by the
    control under whatever name it last read."""
    what: str
    pattern: re.Pattern[str]
    places: frozenset[str]
    required: frozenset[str] = frozenset()


class Synchronisation(msgspec.Struct, frozen=True):
    """A Fanuc electronic-gear-box command "compatible with a hobbing machine" (Fanuc 15i/150i-MA
    operator's manual §19.9.2; the M-series form G81.4 of the 16i/18i/21i): a G code whose block
    is the command alone, its words its arguments, not the dialect's addresses (in G81 T is the
    gear's number of teeth, not a tool). `on` starts the table's synchronisation with the hob
    spindle, or changes its ratio when it is on; otherwise the block cancels it. The table turns
    |threads|/teeth turns per hob turn, the sign of the threads giving its direction. The paired
    words (module and helix angle of the helical compensation) are read with their decimal point,
    in mm and degrees (engine.verifier.synchronisation)."""
    code: str                        # after the G, leading zeros aside: "81", "80.4"
    on: bool                         # starts or re-rates the synchronisation; False: cancels it
    teeth: str = ""                  # the address of the gear's number of teeth
    teeth_range: range = range(0)
    threads: str = ""                # the address of the hob's number of threads (starts), signed, never 0
    threads_range: range = range(0)
    paired: tuple[str, ...] = ()     # given both or neither (Fanuc alarm PS0594 for one alone)

    @property
    def event(self) -> str:
        """Its name in the machine-state rules and the walk ("G81")."""
        return f"G{self.code}"


class DwellWord(msgspec.Struct, frozen=True):
    """A word that gives a dwell G4's time (engine.verifier.dwell): `seconds` per unit written
    (1 for seconds, 0.001 for milliseconds) and its decimal point (True: required, False:
    refused, None: as the dialect's point_required says)."""
    address: str
    seconds: float
    point: bool | None = None


class Dialect(msgspec.Struct, frozen=True):
    """What the verifier reads a machine's programs as: headers, comments, addresses, G and M codes, state rules."""
    name: str
    headers: tuple[Header, ...]
    comment: str                          # "semicolon": `; text` to the end; "parentheses": `(text)`;
                                          # "parentheses without ;": `(text)`, no `;` in it (Fanuc hobbing)
    addresses: dict[str, str]             # address -> value kind
    g_codes: dict[int, str]               # code -> modal group: two of one group in a block are refused
    m_codes: dict[int, str]               # code -> group: M3 and M5 in one block are both spindle
    state: StateRules                     # what each motion and statement needs, what each event does
    keywords: frozenset[str] = frozenset()   # words without a value: WALIMON, DIAMON
    statements: frozenset[str] = frozenset()   # NAME(arguments) lines (engine.verifier.statements)
    shift_clamp: str | None = None        # the hob-shift-per-part clamp's variable, R11 or #500
                                          # (engine.verifier.shift_clamp CLAMPS)
    equals_allowed: bool = False          # 840D: `X=12.5` is `X12.5`; names of two letters need it (`CR=5`)
    arc_radius: str | None = None         # the address of an arc's radius
    needs_words: dict[int, str] = {}   # G code -> the words its block must hold
    thread_lead: dict[int, str] = {}   # thread G code -> the address of its lead (mm/rev)
    point_required: frozenset[str] = frozenset()      # addresses whose number must hold a decimal point
    program_numbers: range | None = None  # ISO O numbers a program may have
    reserved_numbers: range | None = None  # … but these (the machine builder's macros)
    framing_optional: bool = False        # ISO: the tape marks % may be left out; then the O line comes first
    expander: str | None = None           # the bounded interpreter of engine.verifier.expansion that turns
                                          # cycles, subprograms, parameters and jumps into plain lines
    synchronisations: tuple[Synchronisation, ...] = ()   # Fanuc hobbing: the EGB command blocks (G81/G80)
    record_work_offset: bool = False      # only the record's work offset of G54…G57 (machine.work_offset)
    dwell_words: tuple[DwellWord, ...] = (DwellWord("F", 1.0),)   # G4's time: one of these, alone
    refused_g_codes: dict[int, str] = {}   # this dialect's own reasons (Fanuc G60)

    def code_group(self, letter: str, code: int) -> str:
        codes = self.m_codes if letter == "M" else self.g_codes
        if code not in codes:
            known = ", ".join(f"{letter}{c}" for c in sorted(codes))
            refused = (self.refused_g_codes.get(code) or REFUSED_G_CODES.get(code)) if letter == "G" else None
            raise Refused((refused or f"{letter}{code} is not a{'n' if letter == 'M' else ''} {letter} code of the "
                           f"{self.name} grammar") + f" (it has {known})")
        return codes[code]


# G codes that are refused with a reason: what they would do to the positions the verifier reads.
REFUSED_G_CODES = {
    91: "incremental G91 moves cannot be verified; program absolute positions (G90)",
    70: "G70 programs inches (840D) or runs a finishing cycle (ISO); neither can be verified",
    20: "G20 programs inches; every limit is in mm (G21)",
    95: "G95 feeds per revolution; F is bounded in mm/min (G94)",
    99: "G99 feeds per revolution; F is bounded in mm/min (G98)",
    96: "G96 constant cutting speed leaves the spindle speed unbounded; program r/min (G97)",
    **{code: f"G{code} shifts every position by a work offset the verifier cannot see"
       for code in (54, 55, 56, 57, 58, 59, 92, 500)},
    **{code: f"G{code} moves by way of a reference point the verifier cannot see" for code in (28, 74, 75)},
}

# A block that holds one of these G codes holds no other G code and only these words (a dwell
# G4 holds its time alone: Dialect.dwell_words, engine.verifier.dwell).
BLOCK_SHAPES = {
    25: ("lower working-area limit", frozenset(AXES)),
    26: ("upper working-area limit", frozenset(AXES)),
}
WORKING_AREA = {25: "lower", 26: "upper"}
DWELL = 4                   # its word is a time (Dialect.dwell_words), not a feed or a position
# Words that mean something only together with one of these G codes in the same block.
WORD_NEEDS_CODE = {"R": frozenset({2, 3}), "CR": frozenset({2, 3}), "K": frozenset({33})}
# M codes by what they switch: two of one group in a block contradict each other (M3 M5).
M_GROUPS = {3: "spindle", 4: "spindle", 5: "spindle", 8: "coolant", 9: "coolant", 20: "tailstock", 21: "tailstock",
            30: "program end"}
# The M codes real ISO lathe programs use (Fanuc/Haas, reference iso-lathe.md §M), as data: stops,
# spindle, coolant, chuck, tailstock, thread chamfer, chip conveyor, gear range. M98/M99/M97 are
# the expander's (subprograms); they never reach a plain line.
ISO_M_GROUPS = {0: "stop", 1: "stop", 2: "program end", 30: "program end", 3: "spindle", 4: "spindle",
                5: "spindle", 8: "coolant", 9: "coolant", 88: "coolant", 89: "coolant", 10: "chuck", 11: "chuck",
                21: "tailstock", 22: "tailstock", 23: "thread chamfer", 24: "thread chamfer",
                31: "chip conveyor", 33: "chip conveyor", 41: "gear range", 42: "gear range"}
WORK_OFFSETS = (54, 55, 56, 57)   # the settable work offsets a hobber's record may name (machine.work_offset)
DOOR_GROUP = "door"
PROGRAM_HEADER_840D = Header("program header %_N_<NAME>_MPF", re.compile(rf"%_N_{NAME}_MPF"),
                             frozenset({"first"}), frozenset({"first"}))
PATH_LINE_840D = Header("path line ;$PATH=/_N_MPF_DIR", re.compile(r";\$PATH=/_N_MPF_DIR"), frozenset({"second"}))
# 840D lathe programs as stored on the control have no header (reference sinumerik-lathe §S1): it is optional,
# and when it is there it must still name the program itself; the path line may name the
# program folder or a workpiece folder.
LATHE_HEADER_840D = replace(PROGRAM_HEADER_840D, required=frozenset())
LATHE_PATH_LINE_840D = Header("path line ;$PATH=/_N_MPF_DIR or /_N_WKS_DIR/_N_<NAME>_WPD",
                              re.compile(r";\$PATH=/_N_(?:MPF_DIR|WKS_DIR/_N_[A-Za-z0-9_]+_WPD)"),
                              frozenset({"second"}))

HOBBING_840D = Dialect(
    name="840D hobbing",
    headers=(PROGRAM_HEADER_840D, PATH_LINE_840D),
    comment="semicolon",
    addresses={"X": POSITION, "Y": POSITION, "Z": POSITION, "A": ANGLE, "F": FEED, "S": SPEED,
               "T": TOOL, "D": OFFSET, "SPOS": SPINDLE_POSITION, "G": CODE, "M": CODE},
    g_codes={0: MOTION, 1: MOTION, 4: "dwell", 25: "working area", 26: "working area", 71: "units",
             90: "distance", 94: "feed type", **{code: "work offset" for code in WORK_OFFSETS},
             60: "path mode", 64: "path mode"},
    m_codes={code: M_GROUPS[code] for code in (3, 5, 8, 9, 20, 21, 30)},
    state=HOBBING_STATE,
    keywords=frozenset({"WALIMON"}),
    statements=frozenset({"EGDEF", "EGON", "EGOFS", "EGDEL"}),
    shift_clamp="R11",
    equals_allowed=True,
)

# The plain lines the 840D lathe expander ("840d-lathe", engine.verifier.expanders.sinumerik)
# makes of a program as stored on the control: G95 feed per turn, G96 constant cutting speed
# with its clamp LIMS, G4 dwells, M4, the record's work offset and named tools are read here;
# parameters, jumps and loops never reach the grammar.
LATHE_840D = Dialect(
    name="840D lathe",
    headers=(LATHE_HEADER_840D, LATHE_PATH_LINE_840D),
    comment="semicolon",
    addresses={"X": POSITION, "Z": POSITION, "F": FEED, "S": SPEED, "T": TOOL_OR_NAME, "D": OFFSET, "CR": RADIUS,
               "K": PITCH, "LIMS": SPEED_LIMIT, "G": CODE, "M": CODE},
    g_codes={0: MOTION, 1: MOTION, 2: MOTION, 3: MOTION, 33: MOTION, 4: "dwell", 18: "plane", 40: "tool radius",
             71: "units", 90: "distance", 94: "feed type", 95: "feed type", 96: "spindle speed",
             97: "spindle speed", **{code: "work offset" for code in WORK_OFFSETS}},
    m_codes={code: M_GROUPS[code] for code in (3, 4, 5, 8, 9, 30)},
    state=LATHE_840D_STATE,
    keywords=frozenset({"DIAMON"}),
    equals_allowed=True,
    arc_radius="CR",
    needs_words={2: "CR", 3: "CR", 33: "K"},
    thread_lead={33: "K"},
    expander="840d-lathe",
)

ISO_HEADERS = (Header("tape mark %", re.compile(r"%"), frozenset({"first", "last"}), frozenset({"first", "last"})),
               Header("program number O<nnnn> (NAME)",
                      re.compile(rf"O(?P<number>\d{{1,5}})(?: \((?P<name>{ISO_COMMENT_TEXT})\))?"),
                      frozenset({"first", "second"}), frozenset({"second"})))
# O9000 … O9999 hold the builder's macros on Fanuc-type controls: a program there replaces one.
ISO_PROGRAM_NUMBERS, ISO_RESERVED_NUMBERS = range(1, 100000), range(9000, 10000)

LATHE_ISO = Dialect(
    name="ISO lathe",
    headers=ISO_HEADERS,
    comment="parentheses",
    addresses={"X": POSITION, "Z": POSITION, "F": FEED, "S": SPEED, "T": TOOL_AND_OFFSET, "R": RADIUS,
               "G": CODE, "M": CODE},
    g_codes={0: MOTION, 1: MOTION, 2: MOTION, 3: MOTION, 32: MOTION, 4: "dwell", 18: "plane", 21: "units",
             40: "tool radius", 90: "distance", 97: "spindle speed", 98: "feed type"},
    m_codes=ISO_M_GROUPS,
    state=LATHE_ISO_STATE,
    arc_radius="R",
    needs_words={2: "R", 3: "R", 32: "F"},
    thread_lead={32: "F"},
    point_required=frozenset({"X", "Z", "R", "F"}),
    program_numbers=ISO_PROGRAM_NUMBERS,
    reserved_numbers=ISO_RESERVED_NUMBERS,
    framing_optional=True,
    expander="iso",
)

# LinuxCNC lathe (docs/reference/linuxcnc-lathe.md): a program is read as the plain lines the
# expander "linuxcnc" makes of it (engine.verifier.expanders.linuxcnc): in mm, absolute, X a
# diameter, each move with its motion code, an arc with its radius R, G33 with its lead K, G96
# with S the clamp D (the most the spindle turns), a tool change T M6 and its length offset G43.
LINUXCNC_M_GROUPS = {2: "program end", 30: "program end", 3: "spindle", 4: "spindle", 5: "spindle",
                     6: "tool change", 7: "coolant", 8: "coolant", 9: "coolant"}
LATHE_LINUXCNC = Dialect(
    name="LinuxCNC lathe",
    headers=(),
    comment="parentheses",
    addresses={"X": POSITION, "Z": POSITION, "F": FEED, "S": SPEED, "T": TOOL, "R": RADIUS, "K": PITCH,
               "G": CODE, "M": CODE},
    g_codes={0: MOTION, 1: MOTION, 2: MOTION, 3: MOTION, 33: MOTION, 18: "plane", 21: "units",
             40: "tool radius", 43: "tool length", 49: "tool length", 94: "feed type", 95: "feed type",
             96: "spindle speed", 97: "spindle speed"},
    m_codes=LINUXCNC_M_GROUPS,
    state=LINUXCNC_STATE,
    arc_radius="R",
    needs_words={2: "R", 3: "R", 33: "K"},
    thread_lead={33: "K"},
    expander="linuxcnc",
)

# Fanuc hobbing (issue 30): a hobber's program in ISO framing (% … %, O<n> (NAME)), absolute mm
# (G21 G90), feed per minute (G94; G95 refused as on the 840D hobber), the record's work offset
# G54…G57, hob spindle M3/M5 S, coolant M8/M9, tailstock M20/M21 (the builder's, as on the 840D
# hobber), a tool call T<n>, and the table synchronised to the hob by the electronic gear box:
# G81 T<teeth> L<±threads> [Q<module> P<helix angle>] … G80 (Fanuc 15i/150i-MA operator's manual
# §19.9.2; a second G81 while on changes the ratio). Fanuc's G25/G26 detect spindle-speed
# fluctuation, so there is no working area: positions are held to the travel. The dwell is
# `G04 X<seconds>` (with its point) or `G04 P<milliseconds>` (a whole number), the path modes
# G61 (exact stop mode) and G64 (cutting mode), the 840D's G60/G64 (reference fanuc-egb.md §F8);
# Fanuc's G60 is single-direction positioning, refused by name.
FANUC_G81 = Synchronisation("81", True, "T", range(1, 1001), "L", range(-21, 22), ("Q", "P"))
FANUC_G80 = Synchronisation("80", False)
FANUC_DWELL = (DwellWord("X", 1.0, point=True), DwellWord("P", 0.001, point=False))
FANUC_REFUSED_G_CODES = {60: "G60 is single-direction positioning on a Fanuc control, not the 840D's exact stop; "
                             "write G61 (exact stop mode), reference fanuc-egb.md §F8"}
HOBBING_FANUC = Dialect(
    name="Fanuc hobbing",
    headers=ISO_HEADERS,
    comment="parentheses without ;",
    addresses={"X": POSITION, "Y": POSITION, "Z": POSITION, "A": ANGLE, "F": FEED, "S": SPEED, "T": TOOL,
               "G": CODE, "M": CODE},
    g_codes={0: MOTION, 1: MOTION, 4: "dwell", 21: "units", 90: "distance", 94: "feed type",
             **{code: "work offset" for code in WORK_OFFSETS}, 61: "path mode", 64: "path mode"},
    m_codes={code: M_GROUPS[code] for code in (3, 5, 8, 9, 20, 21, 30)},
    state=FANUC_HOBBING_STATE,
    point_required=frozenset({"X", "Y", "Z", "A", "F"}),
    program_numbers=ISO_PROGRAM_NUMBERS,
    reserved_numbers=ISO_RESERVED_NUMBERS,
    synchronisations=(FANUC_G81, FANUC_G80),
    record_work_offset=True,
    dwell_words=FANUC_DWELL,
    refused_g_codes=FANUC_REFUSED_G_CODES,
    shift_clamp="#500",
)
# The M-series form (Fanuc 16i/18i/21i, where G81 is the drilling cycle): G81.4 R<teeth 1…500>
# L<±threads 1…30> [Q P] … G80.4; otherwise as HOBBING_FANUC.
HOBBING_FANUC_G81_4 = replace(
    HOBBING_FANUC, name="Fanuc hobbing G81.4", state=FANUC_G81_4_HOBBING_STATE,
    synchronisations=(Synchronisation("81.4", True, "R", range(1, 501), "L", range(-30, 31), ("Q", "P")),
                      Synchronisation("80.4", False)))

# machine.kind, machine.dialect -> the grammar its programs are read with.
DIALECTS = {("hobber", "840d"): HOBBING_840D, ("lathe", "840d"): LATHE_840D, ("lathe", "iso"): LATHE_ISO,
            ("lathe", "linuxcnc"): LATHE_LINUXCNC, ("hobber", "fanuc"): HOBBING_FANUC,
            ("hobber", "fanuc-g81.4"): HOBBING_FANUC_G81_4}


def dialect_for(machine: Machine) -> Dialect:
    """The grammar of a machine's programs: its dialect, and on a hobber the door M functions
    its record names (they are the machine builder's, so no dialect holds them)."""
    found = dialect_of(machine.kind, machine.dialect)
    if found.record_work_offset:
        found = _in_record_work_offset(found, machine.work_offset)
    doors = tuple(code for code in (machine.door_close_m, machine.door_open_m) if code is not None)
    if machine.kind != "hobber" or not doors:
        return found
    codes = {**found.m_codes, **{int(code): DOOR_GROUP for code in doors}}
    name = f"{found.name} with doors {'/'.join(f'M{int(code)}' for code in doors)}"
    return replace(found, name=name, m_codes=codes)


def _in_record_work_offset(found: Dialect, work_offset: str) -> Dialect:
    """Fanuc hobbing: of G54…G57 only the record's, the frame its travel is stated in (another
    would shift every position by an offset the verifier cannot see; the 840D hobber's is held to
    the record by the simulation, which reads no Fanuc program yet). Named by it, as the lines
    read are remembered per grammar name (engine.verifier.lines)."""
    codes = {code: group for code, group in found.g_codes.items()
             if group != "work offset" or f"G{code}" == work_offset}
    return replace(found, name=f"{found.name} in {work_offset}", g_codes=codes)


def dialect_of(kind: str, dialect: str) -> Dialect:
    """The grammar of a machine record; a record the verifier has no grammar for makes no program."""
    found = DIALECTS.get((kind, dialect))
    if found is None:
        known = ", ".join(f"{k}/{d}" for k, d in DIALECTS)
        raise Refused(f"no verifier grammar for a {kind} with dialect {dialect!r} (known: {known}); "
                      "set machine.kind and machine.dialect")
    return found
