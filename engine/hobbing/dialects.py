"""What a hobbing program's control dialect adds to its job (issue 30, docs/reference/fanuc-egb.md):
the coupling is computed once by the model (coupling_b = σ·z0, z2, the differential k_Z in the
machine's senses) and the class template renders it per dialect, its rows conditioned on
`dialect`: EGDEF/EGON/EGOFS for the 840D, `G81 T L [Q P]` / `G80` for Fanuc (§F5: T = z2,
L = coupling_b, Q = m_n, P = egb_helix_sign·β with the differential's sign). The Fanuc parameters
(program_number, egb_helix_sign) are in every hobbing job, 0 on an 840D, as a template row's
output is evaluated for every job whatever its condition (engine.templates.decision_table).

What the Fanuc form cannot write is refused before any program is made, one line each
(FANUC_REFUSALS, rules as data)."""
from __future__ import annotations

from collections.abc import Callable

import msgspec

from ..errors import EngineError
from ..gears.records import Gear
from ..machines.records import Machine
from .choices import Choices

FANUC = "fanuc"
# The classes whose seeded templates hold Fanuc rows (seed_templates/classes/*.csv); another
# class on a Fanuc hobber is refused by name rather than read as 840D lines by the Fanuc grammar.
FANUC_CLASSES = frozenset({"spur", "helical", "duplex", "worm_wheel", "taper", "crowned"})
# O numbers a Fanuc program may have: O1…O99999 without the builder's macros O9000…O9999
# (engine/verifier/grammar.py ISO_PROGRAM_NUMBERS, ISO_RESERVED_NUMBERS).
PROGRAM_NUMBERS, RESERVED_NUMBERS = range(1, 100000), range(9000, 10000)


def dialect_parameters(machine: Machine, gear_id: int) -> dict:
    """The job's dialect and, on a Fanuc hobber, its O number (program_number_base + gear id,
    migration 0038) and the record's helical-compensation sign (±1, migration 0037); 0 otherwise."""
    fanuc = machine.dialect == FANUC
    return {"dialect": machine.dialect,
            "program_number": (machine.program_number_base or 0) + gear_id if fanuc else 0,
            "egb_helix_sign": (machine.egb_helix_sign or 0) if fanuc else 0}


class Job(msgspec.Struct, frozen=True):
    """What the refusals read: the gear, its class's model, the user's choices and the machine."""
    gear: Gear
    model: object
    choices: Choices
    machine: Machine

    @property
    def program_number(self) -> int:
        return (self.machine.program_number_base or 0) + self.gear.id


def _worm_wheel(job: Job) -> bool:
    return not getattr(job.model, "axial_passes", True)


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
    (lambda job: bool(job.gear.helix_angle) and not _worm_wheel(job) and job.machine.egb_helix_sign is None,
     lambda job: f"a helical gear needs G81's Q/P, whose sign machine {job.machine.name} does not state; "
                 "run the dry run of fanuc-egb.md §F5 and set machine.egb_helix_sign"),
    (lambda job: job.choices.shift_per_part > 0,
     lambda job: "hob shift per part is the 840D's R11 clamp (IF/ENDIF), which has no agreed Fanuc form; "
                 "use --shift-y or --machine hobber-840d"),
    (lambda job: _worm_wheel(job) and job.choices.worm_feed == "tangential",
     lambda job: "a tangential worm-wheel feed moves Y while cutting and G81 has no Y term to turn the table "
                 "with it (fanuc-egb.md §F6); use --worm-feed radial or --machine hobber-840d"),
    (lambda job: job.machine.orient_before_coupling,
     lambda job: f"machine {job.machine.name} orients the spindle before coupling (840D SPOS), which has no "
                 "agreed Fanuc form; set machine.orient_before_coupling false"),
)


def refuse_for_dialect(gear: Gear, model, choices: Choices, machine: Machine) -> None:
    """EngineError (one line, nothing stored) when the job cannot be written in the machine's dialect."""
    if machine.dialect != FANUC:
        return
    job = Job(gear, model, choices, machine)
    for refused, why in FANUC_REFUSALS:
        if refused(job):
            raise EngineError(f"gear {gear.id} on {machine.name} (Fanuc): {why(job)}; nothing stored")

