"""What a hobbing program's control dialect adds to its job (issue 30, docs/reference/fanuc-egb.md):
the coupling is computed once by the model (coupling_b = σ·z0, z2, the differential k_Z in the
machine's senses) and the class template renders it per dialect, its rows conditioned on
`dialect == '840d'` (EGDEF/EGON/EGOFS) or on `fanuc`, true for both Fanuc forms: `G81 T L [Q P]` /
`G80` (dialect fanuc, §F5: T = z2, L = coupling_b, Q = m_n, P = egb_helix_sign·β with the
differential's sign) or the M series' `G81.4 R L` / `G80.4` (dialect fanuc-g81.4, §F3: R = z2,
L = coupling_b, whose sign is C's direction there too). The rows write the form's words from
EGB_WORDS (egb_start, egb_teeth, egb_stop), so one set of Fanuc rows serves both. The Fanuc
parameters (program_number, egb_helix_sign, the words) are in every hobbing job, 0 or "" on an
840D, as a template row's output is evaluated for every job whatever its condition
(engine.templates.decision_table).

What a Fanuc form cannot write is refused before any program is made, one line each
(FANUC_REFUSALS, rules as data)."""
from __future__ import annotations

from collections.abc import Callable

import msgspec

from ..errors import EngineError
from ..gears.records import Gear
from ..machines.records import Machine
from .choices import Choices

FANUC, FANUC_M = "fanuc", "fanuc-g81.4"
# dialect -> (start command, its teeth address, cancel command) of the Fanuc EGB forms
# (fanuc-egb.md §F1: G81 T<1…1000> L<±1…21>; §F3: G81.4 R<1…500> L<±1…30>); the ranges are the
# verifier's (engine/verifier/grammar.py HOBBING_FANUC, HOBBING_FANUC_G81_4).
EGB_WORDS = {FANUC: ("G81", "T", "G80"), FANUC_M: ("G81.4", "R", "G80.4")}
NO_EGB_WORDS = ("", "", "")
# The classes whose seeded templates hold Fanuc rows (seed_templates/classes/*.csv); another
# class on a Fanuc hobber is refused by name rather than read as 840D lines by the Fanuc grammar.
FANUC_CLASSES = frozenset({"spur", "helical", "duplex", "worm_wheel", "taper", "crowned"})
# O numbers a Fanuc program may have: O1…O99999 without the builder's macros O9000…O9999
# (engine/verifier/grammar.py ISO_PROGRAM_NUMBERS, ISO_RESERVED_NUMBERS).
PROGRAM_NUMBERS, RESERVED_NUMBERS = range(1, 100000), range(9000, 10000)


def program_number(machine: Machine, gear_id: int) -> int:
    """The O number of the gear's program on the machine: program_number_base + gear id (§F7)."""
    return (machine.program_number_base or 0) + gear_id


def dialect_parameters(machine: Machine, gear_id: int) -> dict:
    """The job's dialect and, on a Fanuc hobber (either form), `fanuc` true, its O number
    (program_number_base + gear id, migration 0038), the record's helical-compensation sign
    (±1, migration 0037) and the form's EGB words; false, 0 and "" otherwise."""
    fanuc = machine.dialect in EGB_WORDS
    start, teeth, stop = EGB_WORDS.get(machine.dialect, NO_EGB_WORDS)
    return {"dialect": machine.dialect, "fanuc": fanuc,
            "program_number": program_number(machine, gear_id) if fanuc else 0,
            "egb_helix_sign": (machine.egb_helix_sign or 0) if fanuc else 0,
            "egb_start": start, "egb_teeth": teeth, "egb_stop": stop}


class Job(msgspec.Struct, frozen=True):
    """What the refusals read: the gear, its class's model, the user's choices and the machine."""
    gear: Gear
    model: object
    choices: Choices
    machine: Machine

    @property
    def program_number(self) -> int:
        return program_number(self.machine, self.gear.id)


def _worm_wheel(job: Job) -> bool:
    return not getattr(job.model, "axial_passes", True)


def _helical(job: Job) -> bool:
    """The program would need Q/P, the control's helical compensation (a worm wheel's β is the
    hob's lead, set by the swivel, and couples no Z term)."""
    return bool(job.gear.helix_angle) and not _worm_wheel(job)


# (the job cannot be written on a Fanuc hobber, why: the rest of the line after "gear <id>: ").
FANUC_REFUSALS: tuple[tuple[Callable[[Job], bool], Callable[[Job], str]], ...] = (
    (lambda job: job.gear.gear_class not in FANUC_CLASSES,
     lambda job: f"class {job.gear.gear_class} has no Fanuc rows in its template (Fanuc: "
                 f"{', '.join(sorted(FANUC_CLASSES))}); use --machine hobber-840d"),
    (lambda job: job.machine.program_number_base is None,
     lambda job: f"machine {job.machine.name} states no program_number_base, so its programs have no O number; "
                 "set machine.program_number_base"),
    (lambda job: job.program_number not in PROGRAM_NUMBERS or job.program_number in RESERVED_NUMBERS,
     lambda job: f"program number O{job.program_number} (program_number_base "
                 f"{job.machine.program_number_base} + gear id) is outside O1…O99999 or among the builder's "
                 "O9000…O9999; change machine.program_number_base"),
    (lambda job: _helical(job) and job.machine.dialect == FANUC_M,
     lambda job: f"a helical gear (beta {job.gear.helix_angle:g}°) needs Q/P in G81.4, whose units and "
                 "compensation are unconfirmed (fanuc-egb.md §F3); use a hobber of dialect fanuc or hobber-840d"),
    (lambda job: _helical(job) and job.machine.egb_helix_sign is None,
     lambda job: f"a helical gear needs G81's Q/P, whose sign machine {job.machine.name} does not state; "
                 "run the dry run of fanuc-egb.md §F5 and set machine.egb_helix_sign"),
    (lambda job: _worm_wheel(job) and job.choices.worm_feed == "tangential",
     lambda job: "a tangential worm-wheel feed moves Y while cutting and G81 has no Y term to turn the table "
                 "with it (fanuc-egb.md §F6); use --worm-feed radial or --machine hobber-840d"),
    (lambda job: job.machine.orient_before_coupling,
     lambda job: f"machine {job.machine.name} orients the spindle before coupling (840D SPOS), which has no "
                 "agreed Fanuc form; set machine.orient_before_coupling false"),
)


def refuse_for_dialect(gear: Gear, model, choices: Choices, machine: Machine) -> None:
    """EngineError (one line, nothing stored) when the job cannot be written in the machine's dialect."""
    if machine.dialect not in EGB_WORDS:
        return
    job = Job(gear, model, choices, machine)
    form = "Fanuc" if machine.dialect == FANUC else f"Fanuc {EGB_WORDS[machine.dialect][0]}"
    for refused, why in FANUC_REFUSALS:
        if refused(job):
            raise EngineError(f"gear {gear.id} on {machine.name} ({form}): {why(job)}; nothing stored")
