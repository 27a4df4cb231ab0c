"""The bound every number the engine reads is held to, the same for a CSV file (engine.csv_reader)
and a record read from the database (engine.db.records). A module of its own so that reading a
record does not import the CSV reader (issue 28: start-up)."""

# No dimension of a gear, hob or machine reaches a kilometre (mm), no speed a million (r/min):
# a larger number is a slip of the keyboard, and 1e999, a valid numeric in PostgreSQL, is no
# float at all (the models would compute with infinities).
MAX_MAGNITUDE = 1e6
