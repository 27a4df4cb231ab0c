-- Safe names (issue 13): program, drawing, hob, class and machine names leave the database
-- as text the machine reads. A program name becomes the 840D program %_N_<name>_MPF and the
-- file <name>.MPF; the others are printed inside the program's comments. A newline in one
-- of them starts a new NC block after the comment (G0 X9999 Z-9999 reached stored programs
-- that way), and a / or .. in a program name writes a file outside --out. The patterns are
-- the table of engine/names.py (NAME_RULES), which checks them where names enter and are
-- used; here they hold for every row, however it is written.

-- Does `name` fit the rule of its kind (program, drawing, hob, class, machine)? An unknown
-- kind or a NULL name does not.
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

-- Rows written before names were checked: the migration stops and names them, so that they
-- are renamed (or deleted) rather than silently kept or altered.
DO $$
DECLARE
    unsafe text;
BEGIN
    SELECT string_agg(found.what, '; ') INTO unsafe
    FROM (SELECT format('gear_class %s', to_json(name)) FROM gear_class WHERE NOT safe_name('class', name)
          UNION ALL
          SELECT format('machine %s', to_json(name)) FROM machine WHERE NOT safe_name('machine', name)
          UNION ALL
          SELECT format('hob %s', to_json(id)) FROM hob WHERE NOT safe_name('hob', id)
          UNION ALL
          SELECT format('job %s params.%s = %s', j.id, named.key, j.params -> named.key)
          FROM job j,
               (VALUES ('program_name', 'program'), ('drawing', 'drawing'), ('machine', 'machine'),
                       ('gear_class', 'class'), ('hob_id', 'hob')) AS named (key, kind)
          WHERE j.params ? named.key
            AND NOT (jsonb_typeof(j.params -> named.key) = 'string' AND safe_name(named.kind, j.params ->> named.key))
          UNION ALL
          SELECT format('job %s: a text in params or module_params holds a line break or control character', id)
          FROM job WHERE json_text_breaks_lines(params) OR json_text_breaks_lines(module_params)
          LIMIT 20) AS found (what);
    IF unsafe IS NOT NULL THEN
        RAISE EXCEPTION 'unsafe names (rules: engine/names.py; a program name is an 840D name of at most 24 '
                        'characters): %; rename them in SQL (UPDATE job SET params = jsonb_set(params, ''{program_name}'', '
                        '''"NEW_NAME"'') WHERE id = …) and migrate again', unsafe;
    END IF;
END
$$;

ALTER TABLE gear_class ADD CONSTRAINT gear_class_safe_name CHECK (safe_name('class', name));
ALTER TABLE machine ADD CONSTRAINT machine_safe_name CHECK (safe_name('machine', name));
ALTER TABLE hob ADD CONSTRAINT hob_safe_id CHECK (safe_name('hob', id));
ALTER TABLE job ADD CONSTRAINT job_safe_params CHECK (job_params_safe(params, module_params));

-- Stored programs are records: those stored before this migration keep their names and lines
-- (NOT VALID: not checked); every program stored from now on is.
ALTER TABLE program ADD CONSTRAINT program_safe_name CHECK (safe_name('program', name)) NOT VALID;
ALTER TABLE program ADD CONSTRAINT program_lines_unbroken CHECK (NOT breaks_lines(array_to_string(lines, ''))) NOT VALID;
