"""Programs (design notes §7): instantiation, storage and output files; every program is read by
the fail-closed verifier (engine.verifier) before it is stored or written."""
