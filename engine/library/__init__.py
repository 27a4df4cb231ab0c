"""The module library (design notes §5): NC tokens, line similarity, the nightly refactor and
importing proven NC programs as standard code."""
