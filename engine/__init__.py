"""NC program template engine: templates in PostgreSQL, instantiated by a decision table."""
