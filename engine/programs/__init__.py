"""Programs (design notes §7): instantiation, storage and output files; each program is read by the verifier (engine.verifier) first."""
