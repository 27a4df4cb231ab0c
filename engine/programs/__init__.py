"""Programs (design notes §7): instantiation, the machine-limit check, storage and output files."""
