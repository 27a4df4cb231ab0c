"""Programs (design notes §7): instantiation, the fail-closed program verifier, storage and output files."""
