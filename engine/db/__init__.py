"""The database: where it is (connection), migrations, and seeding the standard code."""
