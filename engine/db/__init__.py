"""The database: where it is (connection, the embedded server), migrations, rows read as records.
Seeding the standard code, which needs the gears and templates above, is engine.library.seed."""
