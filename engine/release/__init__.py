"""Releasing templates (design notes §4, §7): the golden tests (a class's stored programs made
again and compared), the impact of a new version on the stored jobs, template coverage and the
release gate that runs them all. Above programs/, whose instantiation it drives."""
