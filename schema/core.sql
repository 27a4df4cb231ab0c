-- schema/core.sql: the rules every other file leans on. Loaded first (the order is in
-- docs/database.md and tests/test_migrations.py SCHEMA_FILES): names that leave the database as
-- NC text, who acts, and the refusal that makes a table a record. The files of schema/ are the
-- database as migrations/ leave it, each object once, in its final form; tests/test_migrations.py
-- checks them against the migrations object by object. Change both in the same commit.

-- Safe names (engine/names.py NAME_RULES): program, drawing, hob, class and
-- machine names leave the database as text the machine reads (the 840D program name and its
-- file name; the others inside the program's comments). A newline in one would start a new NC
-- block; a / or .. in a program name, a file outside --out. Does `name` fit its kind's rule?
CREATE FUNCTION safe_name(kind text, name text) RETURNS boolean
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN coalesce(name ~ CASE kind
    WHEN 'program' THEN '^(?:[A-Za-z]{2}|_[A-Za-z])[A-Za-z0-9_]{0,22}$'
    WHEN 'drawing' THEN '^[A-Za-z0-9_][A-Za-z0-9_. -]{0,79}$'
    WHEN 'hob' THEN '^[A-Za-z0-9][A-Za-z0-9_.-]{0,31}$'
    WHEN 'class' THEN '^[a-z][a-z0-9_]{0,62}$'
    WHEN 'machine' THEN '^[A-Za-z][A-Za-z0-9_.-]{0,31}$'
END, false);

-- Does the text hold a character that ends or hides an NC line (C0 controls but tab, DEL,
-- C1 controls, U+2028, U+2029)? engine/names.py LINE_BREAKING.
CREATE FUNCTION breaks_lines(value text) RETURNS boolean
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN value ~ '[\x01-\x08\x0a-\x1f\x7f-\x9f\u2028\u2029]';

-- Does any text inside the JSON value (at any depth) hold such a character?
CREATE FUNCTION json_text_breaks_lines(value jsonb) RETURNS boolean
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN jsonb_path_exists(value,
    'lax $.** ? (@.type() == "string" && @ like_regex "[\\x01-\\x08\\x0a-\\x1f\\x7f-\\x9f\\u2028\\u2029]")');

-- A name inside JSON: absent (SQL NULL), or a string that fits its kind's rule.
CREATE FUNCTION safe_json_name(kind text, value jsonb) RETURNS boolean
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN value IS NULL OR (jsonb_typeof(value) = 'string' AND safe_name(kind, value #>> '{}'));

-- A job's parameters that are names (printed in the program, or its file name) fit their
-- rule when present, and no text of the job breaks a line.
CREATE FUNCTION job_params_safe(params jsonb, module_params jsonb) RETURNS boolean
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN safe_json_name('program', params -> 'program_name') AND safe_json_name('drawing', params -> 'drawing')
    AND safe_json_name('machine', params -> 'machine') AND safe_json_name('class', params -> 'gear_class')
    AND safe_json_name('hob', params -> 'hob_id')
    AND NOT json_text_breaks_lines(params) AND NOT json_text_breaks_lines(module_params);

-- Who made a change: the role the session acts as (SET ROLE), also inside the SECURITY
-- DEFINER functions of the other files, where current_user is their owner. Audit rows,
-- stored programs, versions, releases and near-duplicate marks all record it.
CREATE FUNCTION template_editor() RETURNS text LANGUAGE sql STABLE
RETURN CASE WHEN current_setting('role') = 'none' THEN session_user::text ELSE current_setting('role') END;

-- Records are appended, never changed: programs, the audit trail, stored template versions,
-- releases, drawings. Their tables' BEFORE UPDATE/DELETE/TRUNCATE triggers call this.
CREATE FUNCTION refuse_changing_a_record() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    RAISE EXCEPTION '% of %: its rows are records, never changed or deleted (%)', TG_OP, TG_TABLE_NAME,
                    CASE TG_TABLE_NAME
                        WHEN 'program' THEN 'make a new program with engine instantiate'
                        WHEN 'template_audit' THEN 'the audit trail is append-only'
                        WHEN 'drawing' THEN 'import the drawing again with engine import-dxf'
                        ELSE 'a new version is stored when a template changes' END
        USING ERRCODE = 'insufficient_privilege';
END
$$;
