"""The simulation that proves each hobbing program (design notes §7, issue 14): it reads only
the program text, the gear, the hob and the machine (never the model code that made the
program) and follows every axis block by block in the DIN 66217 frame: the hob envelope against
the blank, its units, the fixture and the tailstock; the coupling's teeth, hand and lead and the
swivel against the gear; the depth per cut, the run-out, the table speed, the feed per workpiece
revolution and the cycle time.

One part per machine kind, each in its subfolder: hobbing/, and turning/ (a lathe program
against its job's drawing, blank and operations: engine.simulation.turning.run). The simulation imports the
verifier's reader, never the models that made the program (engine.hobbing, engine.turning):
tests/test_house.py enforces it."""
from typing import TYPE_CHECKING

from .hobbing.report import Finding, Report, SimulationError
from .hobbing.run import prove_program, simulate_program

if TYPE_CHECKING:
    from .hobbing.stored import simulate_stored_program

__all__ = ["Finding", "Report", "SimulationError", "prove_program", "simulate_program", "simulate_stored_program"]


def __getattr__(name: str):
    """simulate_stored_program, imported when first named: it loads a stored program's records,
    which a command making programs never does (issue 28: a start-up imports what it uses)."""
    if name == "simulate_stored_program":
        from .hobbing.stored import simulate_stored_program

        return simulate_stored_program
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
