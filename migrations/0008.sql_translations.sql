-- SQL-style conditions translated once and kept (design notes §4): the Python expression that
-- sqlglot made of a condition's text, keyed by a hash of the translator's version and the text,
-- so a template whose conditions are all translated runs without loading sqlglot. Written when
-- templates are imported, seeded or linked through the engine; a text edited in SQL that has no
-- translation yet is translated when it is used. Rows are never changed: a new translator version
-- gives new keys. Every translation is checked by the expression gate when it is read.
CREATE TABLE sql_translation (
    text_hash  text PRIMARY KEY,
    sql        text NOT NULL,
    python     text NOT NULL,
    created_at timestamptz NOT NULL DEFAULT now()
);

GRANT SELECT ON sql_translation TO engine_reader, engine_runner, engine_editor;
GRANT INSERT ON sql_translation TO engine_editor;
