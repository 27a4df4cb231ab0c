"""The program the seeded templates make for a gear, stored without the simulation's proof: the
text the simulation tests then prove themselves (as written, or rewritten for another control)."""
from __future__ import annotations

from engine.hobbing.choices import Choices
from engine.programs import verified_run
from engine.programs.instantiate import instantiate_gear


def unproved(conn, monkeypatch, gear_id: int, choices: Choices):
    """instantiate_gear with the proof switched off for this call only (monkeypatch)."""
    with monkeypatch.context() as patch:
        patch.setattr(verified_run, "prove", lambda *args, **kwargs: None)
        return instantiate_gear(conn, gear_id, choices=choices)
