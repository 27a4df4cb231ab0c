"""The module library (design notes §5): line similarity, the nightly refactor, importing proven
NC programs as standard code, and `engine seed` loading the standard code and sample data."""
