"""Importers that create jobs (design notes §3): `importers.dxf` makes a lathe drawing one turning
job (`engine import-dxf`), `importers.sample` the sample drawing's job (`engine demo --turning`).

They stand above the engine's library (they use engine.drawings, engine.turning and
engine.programs) and below its command line: only engine.cli imports them, and nothing of the
engine below the command line does (tests/test_house.py)."""
