-- SQL-style conditions translated once and kept (design notes §4): the Python expression that
-- sqlglot made of a condition's text, keyed by a hash of the translator's version and the text,
-- so a template whose conditions are all translated runs without loading sqlglot. Written by the
-- engine's own role (the table's owner) when templates are imported, seeded or linted; no engine_*
-- role may write it (a translation written by hand could give a condition another meaning than its
-- text shows; engine lint reports one that is not sqlglot's). A text without a translation is
-- translated when it is used. Rows are never changed: a new translator or sqlglot version gives new
-- keys. Every translation is checked by the expression gate when it is read.
CREATE TABLE sql_translation (
    text_hash  text PRIMARY KEY,
    sql        text NOT NULL,
    python     text NOT NULL,
    created_at timestamptz NOT NULL DEFAULT now()
);

GRANT SELECT ON sql_translation TO engine_reader, engine_runner, engine_editor;
