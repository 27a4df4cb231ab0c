-- schema/schema.sql: the whole current schema in one readable file (design notes §3), what the
-- migrations produce: every table, function, trigger and view once, in its final form, with the
-- rule it enforces. It reads top to bottom in eight sections, each using only objects of the
-- sections above it: core, templates, versions, editing, records, programs, release, roles
-- (docs/database.md). tests/test_migrations.py loads it into an empty database and compares the
-- catalog with the one the migrations make, object by object.

-- ==============================================================================================
-- core
-- ==============================================================================================

-- Section core: the rules every other section leans on (first, docs/database.md): names that leave
-- the database as NC text, who acts, and the refusal that makes a table a record. This file is the
-- database as migrations/ leave it, each object once, in its final form; tests/test_migrations.py
-- checks it against the migrations object by object. Change both in the same commit.

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
                        WHEN 'program_request' THEN 'what a machine was sent is its history'
                        ELSE 'a new version is stored when a template changes' END
        USING ERRCODE = 'insufficient_privilege';
END
$$;

-- ==============================================================================================
-- templates
-- ==============================================================================================

-- Section templates: the template library (after section core). Gear classes form a tree; a
-- class's template is its assembly of components (row bodies stored once), inherited down the
-- tree; template_view shows it as the paper's table. Also the library's companions: kept SQL
-- condition translations and the near-duplicate pairs of the nightly refactor.
-- Editing (section editing) and versions (section versions) build on these.

-- The six control modules of the paper, in assembly order (design notes §4).
CREATE TABLE module_type (
    code     text PRIMARY KEY,
    position integer NOT NULL UNIQUE,
    title    text NOT NULL
);
INSERT INTO module_type (code, position, title) VALUES
    ('main',      1, 'main program: start, end, working-area limits'),
    ('prep',      2, 'preparation: positioning, swivel, tool, clamping'),
    ('sync',      3, 'synchronous motion: electronic gearbox coupling'),
    ('shift',     4, 'hob shift along its axis'),
    ('cutcond',   5, 'cutting conditions: spindle, coolant'),
    ('cutmotion', 6, 'cutting motion: infeed, axial pass, retract');

-- Group-technology tree of gear classes. Leaf classes carry templates. A class's name goes into
-- program comments, so it fits safe_name('class'); the layout of its NC file (line ending, final
-- newline) is part of its template and versioned with it (version_layout_change, section versions).
CREATE TABLE gear_class (
    name             text PRIMARY KEY CHECK (name ~ '^[a-z][a-z0-9_]*$'),
    parent           text REFERENCES gear_class (name),
    description      text NOT NULL DEFAULT '',
    template_version integer NOT NULL DEFAULT 0 CHECK (template_version >= 0),
    -- The parameter values of the proven program the class was imported from (engine
    -- import-nc); lint checks the template's names against them. NULL: not imported.
    import_params    jsonb CHECK (jsonb_typeof(import_params) = 'object'),
    -- How an imported NC file ended its lines: LF or CRLF, and whether its last line ended with
    -- one. The rows hold the lines without them, so `M17` of a CRLF file and of an LF file is one
    -- component; writing the class's program back uses these to give the file byte for byte.
    line_ending      text NOT NULL DEFAULT E'\n' CHECK (line_ending IN (E'\n', E'\r\n')),
    final_newline    boolean NOT NULL DEFAULT true,
    CONSTRAINT gear_class_safe_name CHECK (safe_name('class', name))
);

-- A component is the body of a template row (T, O, P_calc, S, P_emit). A body used by
-- several classes is stored once and referenced from each class's assembly.
CREATE TABLE component (
    id     bigserial PRIMARY KEY,
    t      text NOT NULL REFERENCES module_type (code),
    o      text,
    p_calc text,
    s      text,
    p_emit text,
    CONSTRAINT component_not_empty CHECK (nullif(btrim(o), '') IS NOT NULL
                                          OR nullif(btrim(s), '') IS NOT NULL)
);
-- Identity of a body: equal keys mean equal (t, o, p_calc, s, p_emit), NULLs included.
CREATE FUNCTION component_body_key(t text, o text, p_calc text, s text, p_emit text)
RETURNS text LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN md5(concat_ws(',', quote_literal(t), quote_nullable(o), quote_nullable(p_calc),
                     quote_nullable(s), quote_nullable(p_emit)));
CREATE INDEX component_body ON component (component_body_key(t, o, p_calc, s, p_emit));

-- A class's assembled template: row id (the paper's ID, evaluation order), module number N,
-- and the component that holds the row's body.
CREATE TABLE assembly (
    gear_class   text NOT NULL REFERENCES gear_class (name) ON DELETE CASCADE,
    id           integer NOT NULL CHECK (id >= 0),
    n            integer NOT NULL DEFAULT 1 CHECK (n >= 0),
    component_id bigint NOT NULL REFERENCES component (id),
    PRIMARY KEY (gear_class, id)
);
CREATE INDEX assembly_component ON assembly (component_id);

-- Every class's assembled template as the paper's table (design notes §10).
-- A class inherits its parent's assembled rows and adds (or overrides, by row id) only
-- what differs: a duplex class derives from its unit class. Inner nodes of the
-- group-technology tree have no rows, so for them this changes nothing.
CREATE FUNCTION class_template(class_name text)
RETURNS TABLE (id integer, n integer, component_id bigint, owner text)
LANGUAGE sql STABLE
AS $$
    WITH RECURSIVE lineage(name, parent, depth) AS (
        SELECT g.name, g.parent, 0 FROM gear_class g WHERE g.name = class_name
        UNION ALL
        SELECT g.name, g.parent, l.depth + 1
        FROM gear_class g JOIN lineage l ON g.name = l.parent
        WHERE l.depth < 50)
    SELECT DISTINCT ON (a.id) a.id, a.n, a.component_id, a.gear_class
    FROM lineage l JOIN assembly a ON a.gear_class = l.name
    ORDER BY a.id, l.depth
$$;

-- Every class's assembled rows in one set-based statement (class_template suits one class).
CREATE VIEW assembled_row AS
WITH RECURSIVE lineage(gear_class, ancestor, depth) AS (
    SELECT g.name, g.name, 0 FROM gear_class g
    UNION ALL
    SELECT l.gear_class, g.parent, l.depth + 1
    FROM lineage l JOIN gear_class g ON g.name = l.ancestor
    WHERE g.parent IS NOT NULL AND l.depth < 50)
SELECT DISTINCT ON (l.gear_class, a.id) l.gear_class, a.id, a.n, a.component_id, a.gear_class AS owner
FROM lineage l JOIN assembly a ON a.gear_class = l.ancestor
ORDER BY l.gear_class, a.id, l.depth;

-- The class's assembled rows as the paper's table, with how many classes share each body and
-- which class a row is inherited from. Edited in SQL through its INSTEAD OF trigger
-- (template_view_edit, section editing).
CREATE VIEW template_view AS
WITH body_use AS (
    SELECT component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit) AS body,
           count(DISTINCT a.gear_class)::integer AS classes
    FROM assembled_row a JOIN component c ON c.id = a.component_id
    GROUP BY 1)
SELECT a.gear_class, a.id, c.t, a.n, c.p_calc, c.s, c.o, c.p_emit, u.classes AS shared_by,
       a.owner AS inherited_from
FROM assembled_row a
JOIN component c ON c.id = a.component_id
JOIN body_use u ON u.body = component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit);

-- The component holding this body: an existing one (the library stores each body once; the
-- row is locked so a concurrent cleanup cannot delete it under us) or a new one.
CREATE FUNCTION component_for(b_t text, b_o text, b_p_calc text, b_s text, b_p_emit text)
RETURNS bigint LANGUAGE plpgsql
AS $$
DECLARE
    found bigint;
BEGIN
    SELECT c.id INTO found FROM component c
    WHERE component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit) = component_body_key(b_t, b_o, b_p_calc, b_s, b_p_emit)
      AND c.t = b_t AND c.o IS NOT DISTINCT FROM b_o AND c.p_calc IS NOT DISTINCT FROM b_p_calc
      AND c.s IS NOT DISTINCT FROM b_s AND c.p_emit IS NOT DISTINCT FROM b_p_emit
    ORDER BY c.id LIMIT 1
    FOR KEY SHARE;
    IF found IS NULL THEN
        INSERT INTO component (t, o, p_calc, s, p_emit) VALUES (b_t, b_o, b_p_calc, b_s, b_p_emit)
        RETURNING id INTO found;
    END IF;
    RETURN found;
END
$$;

-- Delete the component if no assembly row uses it any more (one a concurrent writer has
-- just started using stays).
CREATE FUNCTION delete_component_if_unused(unused_id bigint) RETURNS void
LANGUAGE plpgsql
AS $$
BEGIN
    DELETE FROM component c
    WHERE c.id = unused_id AND NOT EXISTS (SELECT 1 FROM assembly a WHERE a.component_id = c.id);
EXCEPTION WHEN foreign_key_violation THEN
    NULL;
END
$$;

-- A template row as the audit and the stored versions hold it.
CREATE FUNCTION template_row_json(id integer, t text, n integer, p_calc text, s text, o text, p_emit text)
RETURNS jsonb LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN jsonb_build_object('id', id, 't', t, 'n', n, 'p_calc', p_calc, 's', s, 'o', o, 'p_emit', p_emit);

-- The class's assembled rows (own and inherited) as {"<id>": row}, only row_ids if given.
CREATE FUNCTION class_rows_json(class_name text, row_ids integer[] DEFAULT NULL)
RETURNS jsonb LANGUAGE sql STABLE
RETURN (SELECT coalesce(jsonb_object_agg(r.id::text,
                            template_row_json(r.id, c.t, r.n, c.p_calc, c.s, c.o, c.p_emit)), '{}')
        FROM class_template(class_name) r JOIN component c ON c.id = r.component_id
        WHERE row_ids IS NULL OR r.id = ANY (row_ids));

-- The classes and every class below them (their assembled templates change together).
CREATE FUNCTION classes_and_below(classes text[]) RETURNS TABLE (name text)
LANGUAGE sql STABLE
AS $$
    WITH RECURSIVE below(name, depth) AS (
        SELECT g.name, 0 FROM gear_class g WHERE g.name = ANY (classes)
        UNION ALL
        SELECT g.name, b.depth + 1 FROM gear_class g JOIN below b ON g.parent = b.name WHERE b.depth < 50)
    SELECT DISTINCT name FROM below
$$;

-- A lineage is at most class_depth_limit() classes above a class and never a cycle, also when two
-- re-parents run in parallel.
-- The deepest lineage the recursions over gear_class follow: ancestors above a class.
CREATE FUNCTION class_depth_limit() RETURNS integer LANGUAGE sql IMMUTABLE PARALLEL SAFE RETURN 50;

-- How many classes lie below class_name on its longest branch (0 for a leaf), up to limit + 1.
CREATE FUNCTION class_height(class_name text) RETURNS integer
LANGUAGE sql STABLE
AS $$
    WITH RECURSIVE below(name, depth) AS (
        SELECT class_name, 0
        UNION ALL
        SELECT g.name, b.depth + 1 FROM gear_class g JOIN below b ON g.parent = b.name
        WHERE b.depth <= class_depth_limit())
    SELECT max(depth) FROM below
$$;

-- A class created under a parent, or moved under one: the parent's ancestors, each locked FOR
-- SHARE as it is read (so no one re-parents them until this transaction ends, and a re-parent
-- that got there first is read as committed), must not include the class, and the deepest class
-- below it must stay within class_depth_limit() ancestors.
CREATE FUNCTION check_class_lineage() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    ancestor text := NEW.parent;
    above integer := 0;
BEGIN
    WHILE ancestor IS NOT NULL LOOP
        IF ancestor = NEW.name THEN
            RAISE EXCEPTION 'class % cannot derive from %: % is % or derives from it', NEW.name, NEW.parent,
                            NEW.parent, NEW.name
                USING ERRCODE = 'check_violation', COLUMN = 'parent';
        END IF;
        above := above + 1;
        EXIT WHEN above > class_depth_limit();
        SELECT g.parent INTO ancestor FROM gear_class g WHERE g.name = ancestor FOR SHARE;
    END LOOP;
    IF above + class_height(NEW.name) > class_depth_limit() THEN
        RAISE EXCEPTION 'class % under % would be % or more levels deep (or classes below it would); a lineage '
                        'holds at most % classes above a class; choose a parent higher in the tree', NEW.name,
                        NEW.parent, above + class_height(NEW.name), class_depth_limit()
            USING ERRCODE = 'check_violation', COLUMN = 'parent';
    END IF;
    RETURN NULL;
END
$$;

CREATE TRIGGER gear_class_lineage_inserted AFTER INSERT ON gear_class
FOR EACH ROW WHEN (NEW.parent IS NOT NULL) EXECUTE FUNCTION check_class_lineage();
CREATE TRIGGER gear_class_lineage_reparented AFTER UPDATE OF parent ON gear_class
FOR EACH ROW WHEN (NEW.parent IS NOT NULL AND OLD.parent IS DISTINCT FROM NEW.parent)
EXECUTE FUNCTION check_class_lineage();

-- SQL-style conditions translated once and kept: the Python expression sqlglot made of a
-- condition's text, keyed by a hash of the translator's version and the text (never changed).
CREATE TABLE sql_translation (
    text_hash  text PRIMARY KEY,
    sql        text NOT NULL,
    python     text NOT NULL,
    created_at timestamptz NOT NULL DEFAULT now()
);

-- Near-duplicate pairs of the nightly refactor (issue 16): what earlier runs reported, so a run
-- lists the pairs it finds for the first time before the ones a person has already seen; and the
-- pairs a person marked intended (who, why, when), which the report no longer lists, only counts.
--
-- A pair is its module type and its two line texts, in either order (engine.library.intended);
-- pair_key is the engine's sha256 of that identity, the report shows its first 12 hex digits. The
-- texts are kept beside it so that whoever reads these tables in SQL sees the pair itself.

-- One row per pair a refactor run has listed: first_seen decides new (this run) or known.
CREATE TABLE near_duplicate_seen (
    pair_key   text PRIMARY KEY CHECK (pair_key ~ '^[0-9a-f]{64}$'),
    t          text NOT NULL,
    a          text NOT NULL,
    b          text NOT NULL,
    first_seen timestamptz NOT NULL DEFAULT now(),
    last_seen  timestamptz NOT NULL DEFAULT now()
);

-- A pair marked intended: kept on purpose (e.g. the spur and the helical coupling differ by the
-- helical differential). Withdrawing a mark keeps its row (who withdrew it, when): the decision
-- and its reversal stay readable; a pair has at most one mark in force.
CREATE TABLE near_duplicate_intended (
    id             bigserial PRIMARY KEY,
    pair_key       text NOT NULL CHECK (pair_key ~ '^[0-9a-f]{64}$'),
    t              text NOT NULL,
    a              text NOT NULL,
    b              text NOT NULL,
    why            text NOT NULL CHECK (btrim(why) <> ''),
    marked_at      timestamptz NOT NULL DEFAULT now(),
    marked_by      text NOT NULL DEFAULT session_user,       -- the login person
    marked_role    text NOT NULL DEFAULT template_editor(),  -- the role acting (SET ROLE)
    withdrawn_at   timestamptz,
    withdrawn_by   text,
    withdrawn_role text
);
CREATE UNIQUE INDEX near_duplicate_intended_in_force ON near_duplicate_intended (pair_key)
    WHERE withdrawn_at IS NULL;

-- Who and when are stamped by the database, not taken from the client; a mark is withdrawn once.
CREATE FUNCTION stamp_near_duplicate_intent() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    IF TG_OP = 'INSERT' THEN
        NEW.marked_at := now();
        NEW.marked_by := session_user;
        NEW.marked_role := template_editor();
        NEW.withdrawn_at := NULL;
        NEW.withdrawn_by := NULL;
        NEW.withdrawn_role := NULL;
        RETURN NEW;
    END IF;
    IF OLD.withdrawn_at IS NOT NULL THEN
        RAISE EXCEPTION 'near-duplicate mark % was withdrawn already', OLD.id USING ERRCODE = 'check_violation';
    END IF;
    NEW := OLD;
    NEW.withdrawn_at := now();
    NEW.withdrawn_by := session_user;
    NEW.withdrawn_role := template_editor();
    RETURN NEW;
END
$$;

CREATE TRIGGER near_duplicate_intended_stamped BEFORE INSERT OR UPDATE ON near_duplicate_intended
FOR EACH ROW EXECUTE FUNCTION stamp_near_duplicate_intent();

-- ==============================================================================================
-- versions
-- ==============================================================================================

-- Section versions: template versions (after section templates). The assembled template of every
-- committed version of every class, so `engine template history`, `diff` and `restore` can show
-- and bring back any of them, and a program records the version it was made from. Append-only: a
-- version's rows are written once, when the transaction that made the version commits (or when a
-- program of it is stored), and never changed (check_template_changes, at the end of this file).
-- Every change of a class's assembled rows or layout makes a new version, whoever writes it.

-- JSON text as Python's json.dumps writes it (ensure_ascii): PostgreSQL's JSON output escapes
-- what Python's does (", \, control characters); every character from DEL (0x7F) up becomes
-- \uXXXX, outside the BMP a surrogate pair.
CREATE FUNCTION json_ascii(json_text text) RETURNS text
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN CASE
    WHEN json_text ~ '^[ -~]*$' THEN json_text
    ELSE (SELECT string_agg(CASE
                     WHEN m.part[1] ~ '^[ -~]' THEN m.part[1]
                     WHEN ascii(m.part[1]) < 65536 THEN '\u' || lpad(to_hex(ascii(m.part[1])), 4, '0')
                     ELSE '\u' || to_hex(55296 + ((ascii(m.part[1]) - 65536) >> 10))
                          || '\u' || to_hex(56320 + ((ascii(m.part[1]) - 65536) & 1023)) END, '' ORDER BY m.position)
          FROM regexp_matches(json_text, '[ -~]+|[^ -~]', 'g') WITH ORDINALITY AS m (part, position))
END;

-- The content hash of an assembled template (rows as template_version_rows stores them):
-- sha256 of the JSON list of [id, t, n, p_calc, s, o, p_emit] in id order, without spaces, 16
-- hex digits; exactly engine.templates.rows.rows_hash, so a program's recorded hash is checked here.
CREATE FUNCTION template_rows_hash(rows jsonb) RETURNS text
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN (SELECT left(encode(sha256(convert_to(json_ascii('[' || coalesce(string_agg(
                   '[' || concat_ws(',', r->'id', r->'t', r->'n', r->'p_calc', r->'s', r->'o', r->'p_emit') || ']',
                   ',' ORDER BY e.position), '') || ']'), 'UTF8')), 'hex'), 16)
        FROM jsonb_array_elements(rows) WITH ORDINALITY AS e (r, position));

-- The row ids of an assembled template.
CREATE FUNCTION template_row_ids(rows jsonb) RETURNS integer[]
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN ARRAY(SELECT (r->>'id')::integer FROM jsonb_array_elements(rows) AS e (r));

-- rows: the assembled template (own and inherited rows) as a JSON array in id order of
-- {"id", "t", "n", "p_calc", "s", "o", "p_emit"} (template_row_json); hash and row_ids are
-- computed from them, so a stored version's hash cannot say anything else. The line layout
-- (line ending, final newline) is the class's when the version was stored: a stored program is
-- written with its version's layout, which never changes.
CREATE TABLE template_version_rows (
    gear_class text NOT NULL REFERENCES gear_class (name) ON DELETE CASCADE,
    version    integer NOT NULL,
    rows       jsonb NOT NULL,
    created_at timestamptz NOT NULL DEFAULT now(),
    created_by text NOT NULL DEFAULT current_user,
    hash       text GENERATED ALWAYS AS (template_rows_hash(rows)) STORED,
    row_ids    integer[] GENERATED ALWAYS AS (template_row_ids(rows)) STORED,
    line_ending text NOT NULL DEFAULT E'\n' CHECK (line_ending IN (E'\n', E'\r\n')),
    final_newline boolean NOT NULL DEFAULT true,
    -- Whether the version was released (release_template; its release is template_release's
    -- row): set once, never cleared, so the head office's publication filters on it and a version
    -- retired later is never deleted at a plant (docs/design.md §12).
    released boolean NOT NULL DEFAULT false,
    PRIMARY KEY (gear_class, version),
    CONSTRAINT template_version_rows_hash UNIQUE (gear_class, version, hash)
);
-- The replica identity holds `released`: a publication's row filter on UPDATE reads only its
-- columns (FULL would hold the generated columns, which PostgreSQL 18 refuses as unpublished).
CREATE UNIQUE INDEX template_version_rows_released ON template_version_rows (gear_class, version, released);
ALTER TABLE template_version_rows REPLICA IDENTITY USING INDEX template_version_rows_released;

-- The class's assembled rows as template_version_rows stores them.
CREATE FUNCTION class_rows_array(class_name text)
RETURNS jsonb LANGUAGE sql STABLE
RETURN (SELECT coalesce(jsonb_agg(template_row_json(r.id, c.t, r.n, c.p_calc, c.s, c.o, c.p_emit) ORDER BY r.id),
                        '[]')
        FROM class_template(class_name) r JOIN component c ON c.id = r.component_id);

-- A version's rows are a record: never changed, deleted only with its class (a cascade, run by a
-- trigger); only released is set, once (release_template). hash and row_ids are left out of the
-- comparison: a BEFORE trigger sees generated columns not yet computed (they follow from rows).
CREATE FUNCTION refuse_changing_a_version() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    IF TG_OP = 'UPDATE' AND NOT OLD.released AND NEW.released
       AND to_jsonb(NEW) - '{released,hash,row_ids}'::text[] = to_jsonb(OLD) - '{released,hash,row_ids}'::text[]
       AND EXISTS (SELECT 1 FROM template_release r WHERE r.gear_class = NEW.gear_class AND r.version = NEW.version)
    THEN
        RETURN NEW;
    END IF;
    RAISE EXCEPTION '% of %: its rows are records, never changed or deleted (a new version is stored when a '
                    'template changes; only release_template marks a version released, once, after recording '
                    'its release)', TG_OP, TG_TABLE_NAME
        USING ERRCODE = 'insufficient_privilege';
END
$$;

CREATE TRIGGER template_version_rows_is_a_record BEFORE UPDATE OR DELETE ON template_version_rows
FOR EACH ROW WHEN (pg_trigger_depth() < 1) EXECUTE FUNCTION refuse_changing_a_version();
CREATE TRIGGER template_version_rows_is_not_truncated BEFORE TRUNCATE ON template_version_rows
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- Per transaction, the classes whose assembled template it may have changed, and whether it
-- has bumped their version already. Written only by the functions below (no role has rights).
CREATE TABLE template_change (
    xact       xid8 NOT NULL,
    gear_class text NOT NULL,
    bumped     boolean NOT NULL DEFAULT false,
    PRIMARY KEY (xact, gear_class)
);

-- One row per transaction that noted a change: its insert queues the commit check, once however
-- many classes the transaction touched.
CREATE TABLE template_check_due (
    xact xid8 PRIMARY KEY
);

-- Note that the classes (and those below them) changed in this transaction, and queue the
-- commit check (check_template_changes) once per transaction.
CREATE FUNCTION note_template_change(classes text[]) RETURNS void
LANGUAGE sql
BEGIN ATOMIC
    INSERT INTO template_change (xact, gear_class)
    SELECT pg_current_xact_id(), b.name FROM classes_and_below(classes) b
    ON CONFLICT (xact, gear_class) DO NOTHING;
    INSERT INTO template_check_due (xact) SELECT pg_current_xact_id() WHERE cardinality(classes) > 0
    ON CONFLICT (xact) DO NOTHING;
END;

-- Statement triggers: which classes a change of assembly, component or gear_class touches.
CREATE FUNCTION assembly_changed() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    IF TG_OP IN ('UPDATE', 'DELETE') THEN
        PERFORM note_template_change(ARRAY(SELECT DISTINCT gear_class FROM old_rows));
    END IF;
    IF TG_OP IN ('UPDATE', 'INSERT') THEN
        PERFORM note_template_change(ARRAY(SELECT DISTINCT gear_class FROM new_rows));
    END IF;
    RETURN NULL;
END
$$;

CREATE TRIGGER assembly_inserted AFTER INSERT ON assembly REFERENCING NEW TABLE AS new_rows
FOR EACH STATEMENT EXECUTE FUNCTION assembly_changed();
CREATE TRIGGER assembly_updated AFTER UPDATE ON assembly REFERENCING OLD TABLE AS old_rows NEW TABLE AS new_rows
FOR EACH STATEMENT EXECUTE FUNCTION assembly_changed();
CREATE TRIGGER assembly_deleted AFTER DELETE ON assembly REFERENCING OLD TABLE AS old_rows
FOR EACH STATEMENT EXECUTE FUNCTION assembly_changed();

-- A body changed in place changes every class that uses it.
CREATE FUNCTION component_changed() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    PERFORM note_template_change(ARRAY(
        SELECT DISTINCT a.gear_class
        FROM old_rows o JOIN new_rows n ON n.id = o.id JOIN assembly a ON a.component_id = n.id
        WHERE (o.t, o.o, o.p_calc, o.s, o.p_emit) IS DISTINCT FROM (n.t, n.o, n.p_calc, n.s, n.p_emit)));
    RETURN NULL;
END
$$;

CREATE TRIGGER component_updated AFTER UPDATE ON component REFERENCING OLD TABLE AS old_rows NEW TABLE AS new_rows
FOR EACH STATEMENT EXECUTE FUNCTION component_changed();

-- A class created, re-parented or given a version touches its template and those below it.
CREATE FUNCTION gear_class_changed() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    IF TG_OP = 'INSERT' THEN
        PERFORM note_template_change(ARRAY(SELECT name FROM new_rows));
    ELSE
        PERFORM note_template_change(ARRAY(
            SELECT n.name FROM old_rows o JOIN new_rows n ON n.name = o.name
            WHERE (o.parent, o.template_version) IS DISTINCT FROM (n.parent, n.template_version)));
    END IF;
    RETURN NULL;
END
$$;

CREATE TRIGGER gear_class_inserted AFTER INSERT ON gear_class REFERENCING NEW TABLE AS new_rows
FOR EACH STATEMENT EXECUTE FUNCTION gear_class_changed();
CREATE TRIGGER gear_class_updated AFTER UPDATE ON gear_class REFERENCING OLD TABLE AS old_rows NEW TABLE AS new_rows
FOR EACH STATEMENT EXECUTE FUNCTION gear_class_changed();

-- TRUNCATE fires no row or statement trigger of DML: refused, so no change goes unnoticed.
CREATE FUNCTION refuse_truncating_the_library() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    RAISE EXCEPTION 'TRUNCATE of %: templates change through template_view or the engine, which version and '
                    'audit every change', TG_TABLE_NAME
        USING ERRCODE = 'insufficient_privilege';
END
$$;

CREATE TRIGGER assembly_is_not_truncated BEFORE TRUNCATE ON assembly
FOR EACH STATEMENT EXECUTE FUNCTION refuse_truncating_the_library();
CREATE TRIGGER component_is_not_truncated BEFORE TRUNCATE ON component
FOR EACH STATEMENT EXECUTE FUNCTION refuse_truncating_the_library();

-- Bump the version of the class and of every class below it, once per transaction and class
-- however many rows change (one committed state, one version): the marker is a row of
-- template_change, which no role can write. Returns the class's version.
CREATE FUNCTION bump_template_versions(class_name text) RETURNS integer
LANGUAGE plpgsql
AS $$
DECLARE
    this_xact xid8 := pg_current_xact_id();
BEGIN
    WITH due AS (
        SELECT b.name FROM classes_and_below(ARRAY[class_name]) b
        WHERE NOT EXISTS (SELECT 1 FROM template_change c
                          WHERE c.xact = this_xact AND c.gear_class = b.name AND c.bumped)),
    bumped AS (
        UPDATE gear_class g SET template_version = g.template_version + 1
        FROM due WHERE g.name = due.name
        RETURNING g.name)
    INSERT INTO template_change (xact, gear_class, bumped)
    SELECT this_xact, name, true FROM bumped
    ON CONFLICT (xact, gear_class) DO UPDATE SET bumped = true;
    RETURN (SELECT template_version FROM gear_class WHERE name = class_name);
END
$$;

-- The assembled rows of some classes in one statement, as template_version_rows stores them
-- (class_rows_array, set-based: the commit check of a refactor covers every class).
CREATE FUNCTION assembled_rows_of(classes text[]) RETURNS TABLE (gear_class text, rows jsonb)
LANGUAGE sql STABLE
AS $$
    WITH RECURSIVE lineage(gear_class, ancestor, depth) AS (
        SELECT g.name, g.name, 0 FROM gear_class g WHERE g.name = ANY (classes)
        UNION ALL
        SELECT l.gear_class, g.parent, l.depth + 1
        FROM lineage l JOIN gear_class g ON g.name = l.ancestor
        WHERE g.parent IS NOT NULL AND l.depth < 50),
    assembled AS (
        SELECT DISTINCT ON (l.gear_class, a.id) l.gear_class, a.id, a.n, a.component_id
        FROM lineage l JOIN assembly a ON a.gear_class = l.ancestor
        ORDER BY l.gear_class, a.id, l.depth),
    grouped AS (
        SELECT x.gear_class,
               jsonb_agg(template_row_json(x.id, c.t, x.n, c.p_calc, c.s, c.o, c.p_emit) ORDER BY x.id) AS rows
        FROM assembled x JOIN component c ON c.id = x.component_id
        GROUP BY x.gear_class)
    SELECT g.name, coalesce(r.rows, '[]') FROM gear_class g LEFT JOIN grouped r ON r.gear_class = g.name
    WHERE g.name = ANY (classes)
$$;

-- A stored version is the class's state when it is stored, whoever inserts it (the owner
-- included): its current version and its assembled rows then, and the class's layout as it is.
CREATE FUNCTION check_version_rows() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    IF NEW.version IS DISTINCT FROM (SELECT template_version FROM gear_class WHERE name = NEW.gear_class)
       OR NEW.rows IS DISTINCT FROM (SELECT r.rows FROM assembled_rows_of(ARRAY[NEW.gear_class]) r) THEN
        RAISE EXCEPTION 'class % version %: a stored version holds the class''s current version and its rows '
                        'as they are; the engine stores them', NEW.gear_class, NEW.version
            USING ERRCODE = 'integrity_constraint_violation';
    END IF;
    IF NEW.released THEN
        RAISE EXCEPTION 'class % version %: a version is stored as a draft; release_template marks it released '
                        'when it records its release (engine template release)', NEW.gear_class, NEW.version
            USING ERRCODE = 'integrity_constraint_violation';
    END IF;
    SELECT g.line_ending, g.final_newline INTO NEW.line_ending, NEW.final_newline
    FROM gear_class g WHERE g.name = NEW.gear_class;
    RETURN NEW;
END
$$;

CREATE TRIGGER template_version_rows_are_the_class BEFORE INSERT ON template_version_rows
FOR EACH ROW EXECUTE FUNCTION check_version_rows();

-- Store the class's current version with its rows now (a program is about to record it); a
-- later change in this transaction then makes a new version.
CREATE FUNCTION store_current_version(class_name text) RETURNS void
LANGUAGE sql
BEGIN ATOMIC
    INSERT INTO template_version_rows (gear_class, version, rows, created_by)
    SELECT g.name, g.template_version, r.rows, template_editor()
    FROM gear_class g CROSS JOIN assembled_rows_of(ARRAY[class_name]) r
    WHERE g.name = class_name;
    UPDATE template_change SET bumped = false WHERE xact = pg_current_xact_id() AND gear_class = class_name;
END;

-- At commit, once per transaction: every touched class's assembled rows equal the rows stored
-- for its version, or its version is new (above every stored one) and is stored now. A change
-- that made no version (a direct write, a refactor that changed rows) or a version set back is
-- refused, and the whole transaction with it.
CREATE FUNCTION check_template_changes() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    classes text[];
    touched record;
BEGIN
    DELETE FROM template_check_due WHERE xact = pg_current_xact_id();
    WITH done AS (DELETE FROM template_change WHERE xact = pg_current_xact_id() RETURNING gear_class)
    SELECT array_agg(gear_class) INTO classes FROM done;
    IF classes IS NULL THEN
        RETURN NULL;
    END IF;
    FOR touched IN
        SELECT r.gear_class, g.template_version AS version, r.rows, v.rows AS stored,
               (SELECT max(l.version) FROM template_version_rows l WHERE l.gear_class = r.gear_class) AS latest
        FROM assembled_rows_of(classes) r
        JOIN gear_class g ON g.name = r.gear_class
        LEFT JOIN template_version_rows v ON v.gear_class = r.gear_class AND v.version = g.template_version
        WHERE v.rows IS DISTINCT FROM r.rows
        ORDER BY r.gear_class
    LOOP
        IF touched.stored IS NOT NULL THEN
            RAISE EXCEPTION 'class %: its template rows differ from those stored for its version % (changed without a '
                            'new version); edit templates through template_view or the engine (engine template '
                            'import, restore, import-nc), which version and audit every change',
                            touched.gear_class, touched.version
                USING ERRCODE = 'integrity_constraint_violation';
        END IF;
        IF touched.latest >= touched.version THEN
            RAISE EXCEPTION 'class %: template version % is not above its latest stored version %; versions are '
                            'never set back or reused, the engine bumps them', touched.gear_class, touched.version,
                            touched.latest
                USING ERRCODE = 'integrity_constraint_violation';
        END IF;
        INSERT INTO template_version_rows (gear_class, version, rows, created_by)
        VALUES (touched.gear_class, touched.version, touched.rows, template_editor());
    END LOOP;
    RETURN NULL;
END
$$;

CREATE CONSTRAINT TRIGGER template_rows_match_version AFTER INSERT ON template_check_due
DEFERRABLE INITIALLY DEFERRED
FOR EACH ROW EXECUTE FUNCTION check_template_changes();

-- A change of the layout is a change of the class's template: it makes a new version, once per
-- transaction as a change of rows does (bump_template_versions; not the classes below, which
-- have layouts of their own), whoever writes it, so a released version's layout never changes.
CREATE FUNCTION version_layout_change() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    IF NOT EXISTS (SELECT 1 FROM template_change c
                   WHERE c.xact = pg_current_xact_id() AND c.gear_class = NEW.name AND c.bumped) THEN
        NEW.template_version := OLD.template_version + 1;
        INSERT INTO template_change (xact, gear_class, bumped) VALUES (pg_current_xact_id(), NEW.name, true)
        ON CONFLICT (xact, gear_class) DO UPDATE SET bumped = true;
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER gear_class_layout_versioned BEFORE UPDATE OF line_ending, final_newline ON gear_class
FOR EACH ROW WHEN ((OLD.line_ending, OLD.final_newline) IS DISTINCT FROM (NEW.line_ending, NEW.final_newline))
EXECUTE FUNCTION version_layout_change();

-- ==============================================================================================
-- editing
-- ==============================================================================================

-- Section editing: how a template changes (after section versions). Editing templates in SQL
-- (design notes §10) through template_view's INSTEAD OF trigger, the engine's imports
-- (replace_class_template) and re-parenting a class: each change bumps the versions
-- (bump_template_versions, section versions) and writes the audit trail, whoever makes it.
-- The triggers block the obvious problems (unknown class or module type, empty row, p_calc
-- without s, duplicate or negative id, negative n). Whether an expression parses and names
-- only known parameters is checked in Python: `engine lint` (run in CI and after hand edits)
-- and every `engine template import` / `engine import-nc`.

-- One row per change of a template row: who, when, which class and row, old and new row as
-- {"id", "t", "n", "p_calc", "s", "o", "p_emit"} (NULL for INSERT's old and DELETE's new).
-- template_version: the class's version after the change. Written by the template_view
-- triggers (one row per row changed through the view) and by the engine's imports (engine
-- template import, restore, import-nc: one row per assembled row that differs) and by
-- re-parenting a class. The nightly refactor (which changes no template) writes none. Who and
-- when are stamped by a trigger (the role: changed_by; the login person: login, session_user;
-- NULL in rows written before the audit stamped it); nobody writes them by hand, and no role changes or deletes a row.
CREATE TABLE template_audit (
    id               bigserial PRIMARY KEY,
    changed_at       timestamptz NOT NULL DEFAULT now(),
    changed_by       text NOT NULL DEFAULT current_user,
    login            text,
    gear_class       text NOT NULL,   -- no foreign key: history outlives a dropped class
    template_version integer,
    row_id           integer NOT NULL,
    operation        text NOT NULL CHECK (operation IN ('INSERT', 'UPDATE', 'DELETE')),
    old              jsonb,
    new              jsonb,
    CHECK ((operation = 'INSERT') = (old IS NULL) AND (operation = 'DELETE') = (new IS NULL))
);
CREATE INDEX template_audit_class ON template_audit (gear_class, id);
-- The audit trail is a record: append-only.
CREATE TRIGGER template_audit_is_a_record BEFORE UPDATE OR DELETE ON template_audit
FOR EACH ROW EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER template_audit_is_not_truncated BEFORE TRUNCATE ON template_audit
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- Who and when, whatever the writer put there: a trigger stamps every audit row.
CREATE FUNCTION stamp_template_audit() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    NEW.changed_by := template_editor();
    NEW.login := session_user;
    NEW.changed_at := now();
    RETURN NEW;
END
$$;

CREATE TRIGGER stamp_template_audit BEFORE INSERT ON template_audit
FOR EACH ROW EXECUTE FUNCTION stamp_template_audit();

-- Audit rows for everything that differs between `before` (class_rows_json of the class
-- taken before the change) and the class's rows now; only row_ids if given. The engine's
-- imports call it after replacing a class's rows and bumping its version.
CREATE FUNCTION audit_class_change(class_name text, before jsonb, row_ids integer[] DEFAULT NULL)
RETURNS integer LANGUAGE sql SECURITY DEFINER SET search_path = public, pg_temp
BEGIN ATOMIC
    WITH changes AS (
        SELECT coalesce(b.key, a.key)::integer AS row_id, b.value AS old, a.value AS new
        FROM jsonb_each(before) b
        FULL JOIN jsonb_each(class_rows_json(class_name, row_ids)) a ON a.key = b.key
        WHERE b.value IS DISTINCT FROM a.value),
    written AS (
        INSERT INTO template_audit (changed_by, gear_class, template_version, row_id, operation, old, new)
        SELECT template_editor(), class_name,
               (SELECT template_version FROM gear_class WHERE name = class_name), row_id,
               CASE WHEN old IS NULL THEN 'INSERT' WHEN new IS NULL THEN 'DELETE' ELSE 'UPDATE' END, old, new
        FROM changes ORDER BY row_id
        RETURNING 1)
    SELECT count(*)::integer FROM written;
END;

-- The obvious problems of a row written through template_view, as errors naming the class,
-- the row and the column (the same words as engine lint).
CREATE FUNCTION template_row_check(class_name text, row_id integer, t text, n integer,
                                   p_calc text, s text, o text)
RETURNS void LANGUAGE plpgsql STABLE
AS $$
BEGIN
    IF row_id IS NULL THEN
        RAISE EXCEPTION 'class % column id: every template row needs an id', class_name
            USING ERRCODE = 'not_null_violation', COLUMN = 'id';
    END IF;
    IF row_id < 0 THEN
        RAISE EXCEPTION 'class % row % column id: id must not be negative', class_name, row_id
            USING ERRCODE = 'check_violation', COLUMN = 'id';
    END IF;
    IF n IS NULL OR n < 0 THEN
        RAISE EXCEPTION 'class % row % column n: n must be a whole number >= 0, got %', class_name, row_id,
                        coalesce(n::text, 'NULL')
            USING ERRCODE = 'check_violation', COLUMN = 'n';
    END IF;
    IF t IS NULL OR NOT EXISTS (SELECT 1 FROM module_type m WHERE m.code = t) THEN
        RAISE EXCEPTION 'class % row % column t: unknown module type %; use one of %', class_name, row_id,
                        coalesce(quote_literal(t), 'NULL'),
                        (SELECT string_agg(code, ', ' ORDER BY position) FROM module_type)
            USING ERRCODE = 'check_violation', COLUMN = 't';
    END IF;
    IF o IS NULL AND s IS NULL THEN
        RAISE EXCEPTION 'class % row % column o: row has neither o nor s: it does nothing', class_name, row_id
            USING ERRCODE = 'check_violation', COLUMN = 'o';
    END IF;
    IF p_calc IS NOT NULL AND s IS NULL THEN
        RAISE EXCEPTION 'class % row % column p_calc: p_calc has no effect without s (use p_emit to decide output)',
                        class_name, row_id
            USING ERRCODE = 'check_violation', COLUMN = 'p_calc';
    END IF;
END
$$;

-- A blank expression cell is an absent expression, as in template CSV files.
CREATE FUNCTION blank_to_null(text) RETURNS text LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN CASE WHEN $1 ~ '^\s*$' THEN NULL ELSE $1 END;

-- INSERT, UPDATE, DELETE on template_view change only the class named in the row:
-- * UPDATE points the class's own assembly row at the component with the new body (an
--   existing one when the body is already stored); a row inherited from an ancestor gets an
--   own row for this class (copy-on-write); the ancestor and every other class keep theirs.
--   An own row set back to exactly what the class inherits is deleted (inherited again).
--   id and n may change on own rows; an inherited row's id may not.
-- * INSERT adds an own row with an id the class's assembled template does not have yet.
-- * DELETE removes an own row; an inherited row cannot be deleted from a derived class.
-- Components no longer used are deleted. Every change locks the library in the refactor's
-- order (engine/library/refactor.py LOCK), bumps the versions of the class and the classes
-- below it, and writes template_audit. Direct writes to component and assembly (the owner's
-- only) are refused at commit unless they leave every class's rows as its version stores them.
-- SECURITY DEFINER: editors need no rights on template_audit; the view's own privileges
-- (GRANT ... ON template_view) decide who may edit.
CREATE FUNCTION template_view_edit() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    class_name text;
    row_id     integer;
    own_id     bigint;   -- component of the class's own row at OLD.id; NULL: inherited
    owner_name text;
    same       boolean;
    old_row    jsonb;
    new_row    jsonb;
    new_version integer;
BEGIN
    IF TG_OP = 'DELETE' THEN
        class_name := OLD.gear_class;
    ELSE
        class_name := NEW.gear_class;
    END IF;
    IF TG_OP = 'UPDATE' AND NEW.gear_class IS DISTINCT FROM OLD.gear_class THEN
        RAISE EXCEPTION 'class % row % column gear_class: a row cannot move to another class', OLD.gear_class, OLD.id
            USING ERRCODE = 'check_violation', COLUMN = 'gear_class',
                  HINT = format('INSERT it into %s and DELETE it from %s', NEW.gear_class, OLD.gear_class);
    END IF;
    LOCK TABLE gear_class, component, assembly IN ROW EXCLUSIVE MODE;
    -- Serializes editors of one class; NO KEY: programs being stored (foreign keys) do not wait.
    PERFORM 1 FROM gear_class WHERE name = class_name FOR NO KEY UPDATE;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'class % row % column gear_class: gear class % does not exist', class_name,
                        coalesce(NEW.id, OLD.id), quote_nullable(class_name)
            USING ERRCODE = 'foreign_key_violation', COLUMN = 'gear_class',
                  HINT = 'create it first (INSERT INTO gear_class (name, parent) ...), see `engine template list`';
    END IF;

    IF TG_OP <> 'DELETE' THEN
        NEW.o := blank_to_null(NEW.o);
        NEW.s := blank_to_null(NEW.s);
        NEW.p_calc := blank_to_null(NEW.p_calc);
        NEW.p_emit := blank_to_null(NEW.p_emit);
        IF TG_OP = 'INSERT' THEN
            NEW.n := coalesce(NEW.n, 1);
        END IF;
        PERFORM template_row_check(class_name, NEW.id, NEW.t, NEW.n, NEW.p_calc, NEW.s, NEW.o);
        new_row := template_row_json(NEW.id, NEW.t, NEW.n, NEW.p_calc, NEW.s, NEW.o, NEW.p_emit);
    END IF;

    IF TG_OP = 'INSERT' THEN
        row_id := NEW.id;
        SELECT r.owner INTO owner_name FROM class_template(class_name) r WHERE r.id = NEW.id;
        IF FOUND THEN
            RAISE EXCEPTION 'class % row % column id: the class already has row % (%)', class_name, NEW.id, NEW.id,
                            CASE WHEN owner_name = class_name THEN 'its own' ELSE 'inherited from ' || owner_name END
                USING ERRCODE = 'unique_violation', COLUMN = 'id',
                      HINT = 'choose a free id, or UPDATE the row (an UPDATE of an inherited row overrides it for this class only)';
        END IF;
        INSERT INTO assembly (gear_class, id, n, component_id)
        VALUES (class_name, NEW.id, NEW.n, component_for(NEW.t, NEW.o, NEW.p_calc, NEW.s, NEW.p_emit));

    ELSIF TG_OP = 'UPDATE' THEN
        row_id := NEW.id;
        IF NEW.shared_by IS DISTINCT FROM OLD.shared_by OR NEW.inherited_from IS DISTINCT FROM OLD.inherited_from THEN
            RAISE EXCEPTION 'class % row % column %: shared_by and inherited_from are computed, they cannot be set',
                            class_name, OLD.id,
                            CASE WHEN NEW.shared_by IS DISTINCT FROM OLD.shared_by THEN 'shared_by' ELSE 'inherited_from' END
                USING ERRCODE = 'check_violation',
                      HINT = 'edit id, t, n, p_calc, s, o, p_emit; an UPDATE makes the row this class''s own';
        END IF;
        old_row := template_row_json(OLD.id, OLD.t, OLD.n, OLD.p_calc, OLD.s, OLD.o, OLD.p_emit);
        IF old_row = new_row THEN
            RETURN NEW;   -- nothing changes: no version, no audit
        END IF;
        SELECT a.component_id INTO own_id FROM assembly a
        WHERE a.gear_class = class_name AND a.id = OLD.id FOR UPDATE;
        IF own_id IS NULL THEN
            SELECT r.owner INTO owner_name FROM class_template(class_name) r WHERE r.id = OLD.id;
            IF NOT FOUND THEN
                RETURN NULL;   -- deleted meanwhile by another transaction: nothing to update
            END IF;
            IF NEW.id <> OLD.id THEN
                RAISE EXCEPTION 'class % row % column id: the row is inherited from %; its id cannot be changed in a derived class',
                                class_name, OLD.id, owner_name
                    USING ERRCODE = 'check_violation', COLUMN = 'id',
                          HINT = format('INSERT a row with id %s into %s (row %s stays inherited), or change the id in %s',
                                        NEW.id, class_name, OLD.id, owner_name);
            END IF;
            -- Copy-on-write: this class gets its own row; the ancestor keeps its own.
            INSERT INTO assembly (gear_class, id, n, component_id)
            VALUES (class_name, NEW.id, NEW.n, component_for(NEW.t, NEW.o, NEW.p_calc, NEW.s, NEW.p_emit));
        ELSE
            IF NEW.id <> OLD.id THEN
                SELECT r.owner INTO owner_name FROM class_template(class_name) r WHERE r.id = NEW.id;
                IF FOUND THEN
                    RAISE EXCEPTION 'class % row % column id: the class already has row % (%)', class_name, OLD.id, NEW.id,
                                    CASE WHEN owner_name = class_name THEN 'its own' ELSE 'inherited from ' || owner_name END
                        USING ERRCODE = 'unique_violation', COLUMN = 'id', HINT = 'choose a free id';
                END IF;
            END IF;
            -- Set back to exactly what the parent gives at this id: the row is inherited again.
            SELECT template_row_json(r.id, c.t, r.n, c.p_calc, c.s, c.o, c.p_emit) = new_row INTO same
            FROM gear_class g
            CROSS JOIN LATERAL class_template(g.parent) r
            JOIN component c ON c.id = r.component_id
            WHERE g.name = class_name AND g.parent IS NOT NULL AND r.id = NEW.id;
            IF same AND NEW.id = OLD.id THEN
                DELETE FROM assembly WHERE gear_class = class_name AND id = OLD.id;
            ELSE
                UPDATE assembly
                SET id = NEW.id, n = NEW.n,
                    component_id = component_for(NEW.t, NEW.o, NEW.p_calc, NEW.s, NEW.p_emit)
                WHERE gear_class = class_name AND id = OLD.id;
            END IF;
            PERFORM delete_component_if_unused(own_id);
        END IF;
        NEW.inherited_from := class_name;

    ELSE   -- DELETE
        row_id := OLD.id;
        old_row := template_row_json(OLD.id, OLD.t, OLD.n, OLD.p_calc, OLD.s, OLD.o, OLD.p_emit);
        DELETE FROM assembly WHERE gear_class = class_name AND id = OLD.id RETURNING component_id INTO own_id;
        IF own_id IS NULL THEN
            SELECT r.owner INTO owner_name FROM class_template(class_name) r WHERE r.id = OLD.id;
            IF NOT FOUND THEN
                RETURN NULL;   -- deleted meanwhile by another transaction
            END IF;
            RAISE EXCEPTION 'class % row %: the row is inherited from %; an inherited row cannot be deleted from a derived class',
                            class_name, OLD.id, owner_name
                USING ERRCODE = 'restrict_violation', COLUMN = 'id',
                      HINT = format('delete it from %s (every class deriving from %s loses it), or override it in %s '
                                    'with an UPDATE that makes it do nothing (e.g. SET p_emit = ''False'')',
                                    owner_name, owner_name, class_name);
        END IF;
        PERFORM delete_component_if_unused(own_id);
        SELECT r.owner INTO owner_name FROM class_template(class_name) r WHERE r.id = OLD.id;
        IF FOUND THEN
            RAISE NOTICE 'class % row %: the row inherited from % applies again', class_name, OLD.id, owner_name;
        END IF;
    END IF;

    new_version := bump_template_versions(class_name);
    INSERT INTO template_audit (changed_by, gear_class, template_version, row_id, operation, old, new)
    VALUES (template_editor(), class_name, new_version, row_id, TG_OP, old_row, new_row);
    IF TG_OP = 'DELETE' THEN
        RETURN OLD;
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER template_view_edit INSTEAD OF INSERT OR UPDATE OR DELETE ON template_view
FOR EACH ROW EXECUTE FUNCTION template_view_edit();

-- Re-parenting changes the class's assembled template and those below it: versioned and
-- audited like any edit; a class cannot derive from itself or from a class below it.
CREATE FUNCTION gear_class_reparented() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    before jsonb;
BEGIN
    IF NEW.parent IN (SELECT name FROM classes_and_below(ARRAY[NEW.name])) THEN
        RAISE EXCEPTION 'class % cannot derive from %: % is % or derives from it', NEW.name, NEW.parent,
                        NEW.parent, NEW.name
            USING ERRCODE = 'check_violation', COLUMN = 'parent';
    END IF;
    before := class_rows_json(OLD.parent) || (
        SELECT coalesce(jsonb_object_agg(a.id::text, template_row_json(a.id, c.t, a.n, c.p_calc, c.s, c.o, c.p_emit)),
                        '{}')
        FROM assembly a JOIN component c ON c.id = a.component_id WHERE a.gear_class = NEW.name);
    PERFORM bump_template_versions(NEW.name);
    PERFORM audit_class_change(NEW.name, before);
    RETURN NULL;
END
$$;

CREATE TRIGGER gear_class_reparented AFTER UPDATE OF parent ON gear_class
FOR EACH ROW WHEN (OLD.parent IS DISTINCT FROM NEW.parent) EXECUTE FUNCTION gear_class_reparented();

-- Replace a class's rows (engine template import, template restore, import-nc into a class):
-- `new_rows` is its whole assembled template as a JSON array of template rows; only the rows
-- that differ from what the class inherits are stored as its own. Locks the library in the
-- refactor's order, bumps the versions of the class and the classes below it (each import is a
-- version of its own, also several in one transaction, as `engine seed` makes them), audits
-- every row that changed. False (and nothing written) when the class's own rows are already these.
CREATE FUNCTION replace_class_template(class_name text, new_rows jsonb) RETURNS boolean
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    inherited jsonb;
    own jsonb;
    before jsonb;
    old_components bigint[];
    duplicate record;
BEGIN
    LOCK TABLE gear_class, component, assembly IN ROW EXCLUSIVE MODE;
    SELECT class_rows_json(g.parent) INTO inherited FROM gear_class g WHERE g.name = class_name FOR NO KEY UPDATE;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'gear class % does not exist; create it first', quote_nullable(class_name)
            USING ERRCODE = 'foreign_key_violation';
    END IF;
    IF jsonb_typeof(new_rows) IS DISTINCT FROM 'array' THEN
        RAISE EXCEPTION 'class %: the rows must be a JSON array of template rows', class_name
            USING ERRCODE = 'invalid_parameter_value';
    END IF;
    FOR duplicate IN SELECT x.id, count(*) AS times FROM jsonb_to_recordset(new_rows) AS x (id integer)
                    GROUP BY x.id HAVING count(*) > 1 LOOP
        RAISE EXCEPTION 'class % row %: the row id appears % times', class_name, duplicate.id, duplicate.times
            USING ERRCODE = 'unique_violation', COLUMN = 'id';
    END LOOP;
    SELECT coalesce(jsonb_agg(r.json ORDER BY r.id), '[]') INTO own
    FROM (SELECT x.id, template_row_json(x.id, x.t, x.n, blank_to_null(x.p_calc), blank_to_null(x.s),
                                         blank_to_null(x.o), blank_to_null(x.p_emit)) AS json
          FROM jsonb_to_recordset(new_rows) AS x (id integer, t text, n integer, p_calc text, s text, o text,
                                                   p_emit text)) r
    WHERE inherited->(r.id::text) IS DISTINCT FROM r.json;
    IF own = (SELECT coalesce(jsonb_agg(template_row_json(a.id, c.t, a.n, c.p_calc, c.s, c.o, c.p_emit)
                                        ORDER BY a.id), '[]')
              FROM assembly a JOIN component c ON c.id = a.component_id WHERE a.gear_class = class_name) THEN
        RETURN false;
    END IF;
    -- Only a row that breaks one of template_row_check's rules is checked (for its message), in the
    -- same order: a call per row took 1.3 s of a 100,000-line import-nc.
    PERFORM template_row_check(class_name, x.id, x.t, x.n, x.p_calc, x.s, x.o)
    FROM jsonb_to_recordset(own) AS x (id integer, t text, n integer, p_calc text, s text, o text)
    WHERE x.id IS NULL OR x.id < 0 OR x.n IS NULL OR x.n < 0 OR (x.o IS NULL AND x.s IS NULL)
       OR (x.p_calc IS NOT NULL AND x.s IS NULL) OR NOT EXISTS (SELECT 1 FROM module_type m WHERE m.code = x.t);
    before := class_rows_json(class_name);
    WITH gone AS (DELETE FROM assembly WHERE gear_class = class_name RETURNING component_id)
    SELECT array_agg(component_id) INTO old_components FROM gone;
    -- Each body stored once: a new component for a body not stored yet; those stored already are
    -- locked, so a concurrent cleanup cannot delete them under us (as component_for does).
    INSERT INTO component (t, o, p_calc, s, p_emit)
    SELECT DISTINCT x.t, x.o, x.p_calc, x.s, x.p_emit
    FROM jsonb_to_recordset(own) AS x (t text, o text, p_calc text, s text, p_emit text)
    WHERE NOT EXISTS (SELECT 1 FROM component c
                      WHERE component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit)
                            = component_body_key(x.t, x.o, x.p_calc, x.s, x.p_emit)
                        AND (c.t, c.o, c.p_calc, c.s, c.p_emit)
                            IS NOT DISTINCT FROM (x.t, x.o, x.p_calc, x.s, x.p_emit));
    INSERT INTO assembly (gear_class, id, n, component_id)
    SELECT class_name, x.id, x.n, found.id
    FROM jsonb_to_recordset(own) AS x (id integer, t text, n integer, p_calc text, s text, o text, p_emit text)
    CROSS JOIN LATERAL (
        SELECT c.id FROM component c
        WHERE component_body_key(c.t, c.o, c.p_calc, c.s, c.p_emit)
              = component_body_key(x.t, x.o, x.p_calc, x.s, x.p_emit)
          AND (c.t, c.o, c.p_calc, c.s, c.p_emit) IS NOT DISTINCT FROM (x.t, x.o, x.p_calc, x.s, x.p_emit)
        ORDER BY c.id LIMIT 1 FOR KEY SHARE) found;
    DELETE FROM component c
    WHERE c.id = ANY (old_components) AND NOT EXISTS (SELECT 1 FROM assembly a WHERE a.component_id = c.id);
    UPDATE template_change SET bumped = false
    WHERE xact = pg_current_xact_id() AND gear_class IN (SELECT name FROM classes_and_below(ARRAY[class_name]));
    PERFORM bump_template_versions(class_name);
    PERFORM audit_class_change(class_name, before);
    RETURN true;
END
$$;

-- ==============================================================================================
-- records
-- ==============================================================================================

-- Section records: the shop's records (after section editing): machines and their limits, the
-- hob library, workpieces, jobs (a workpiece on a machine with every parameter its template
-- needs) and the machining history that confirmed jobs add to. Programs are in section programs.

-- Machines and their limits. No program exceeding a limit is stored or written.
CREATE TABLE machine (
    name            text PRIMARY KEY,
    kind            text NOT NULL CHECK (kind IN ('hobber', 'lathe')),
    dialect         text NOT NULL,   -- with kind, the grammar the verifier reads programs with: hobber/840d,
                                     -- lathe/840d, lathe/iso (engine/programs/verifier/grammar.py); others make no program
    x_min           numeric NOT NULL,
    x_max           numeric NOT NULL,
    y_min           numeric NOT NULL DEFAULT 0,
    y_max           numeric NOT NULL DEFAULT 0,
    z_min           numeric NOT NULL,
    z_max           numeric NOT NULL,
    spindle_max     numeric NOT NULL CHECK (spindle_max > 0),  -- hob spindle (hobber) or main spindle, r/min
    table_speed_max numeric,                                   -- r/min of C, hobbers only
    module_max      numeric,                                   -- mm, hobbers only
    -- Conventions and setup (reference §A7): each axis's sense relative to
    -- DIN 66217 (+1 agrees, -1 opposite); the signs of A and of the coupling terms follow them.
    a_direction     smallint NOT NULL DEFAULT 1 CHECK (a_direction IN (-1, 1)),
    b_direction     smallint NOT NULL DEFAULT 1 CHECK (b_direction IN (-1, 1)),
    c_direction     smallint NOT NULL DEFAULT 1 CHECK (c_direction IN (-1, 1)),
    y_direction     smallint NOT NULL DEFAULT 1 CHECK (y_direction IN (-1, 1)),
    z_direction     smallint NOT NULL DEFAULT 1 CHECK (z_direction IN (-1, 1)),
    work_offset     text NOT NULL DEFAULT 'G54' CHECK (work_offset IN ('G54', 'G55', 'G56', 'G57')),
    fixture_diameter numeric NOT NULL DEFAULT 0 CHECK (fixture_diameter >= 0),  -- below the blank; 0 = none
    fixture_gap     numeric NOT NULL DEFAULT 0 CHECK (fixture_gap >= 0),        -- its top below the bottom face
    tailstock_diameter numeric NOT NULL DEFAULT 0 CHECK (tailstock_diameter >= 0),  -- above the blank; 0 = none
    tailstock_gap   numeric NOT NULL DEFAULT 0 CHECK (tailstock_gap >= 0),      -- its lowest point above the top face
    load_x          numeric,                                   -- the load position at the end; NULL = stay
    load_z          numeric,
    rapid_rate      numeric NOT NULL DEFAULT 5000 CHECK (rapid_rate > 0),       -- G0, mm/min
    orient_before_coupling boolean NOT NULL DEFAULT false,                      -- SPOS before EGON
    door_close_m    smallint CHECK (door_close_m BETWEEN 0 AND 999),            -- guard door M functions
    door_open_m     smallint CHECK (door_open_m BETWEEN 0 AND 999),
    -- ISO lathes (issue 27): the G28 reference point (X diameter, Z) in the travel's frame, NULL = not
    -- stated; the G-code system: 'A' X/Z absolute and U/W incremental, G90 a cycle; 'B'/'C' (NULL) G90 absolute.
    reference_x     numeric,
    reference_z     numeric,
    gcode_system    text CHECK (gcode_system IN ('A', 'B', 'C')),
    -- a dimension word without a decimal point (migration 0030): 'increment' X118 = 0.118 mm (refused),
    -- 'calculator' X118 = 118 mm (Fanuc parameter 3401#0 DPI)
    decimal_point_input text NOT NULL DEFAULT 'increment' CHECK (decimal_point_input IN ('increment', 'calculator')),
    -- the modal G codes at power-on and reset (migration 0030), e.g. 'G18 G40 G97 G99'; NULL = not stated;
    -- never G20/G21 (migration 0031: a Fanuc keeps the units the last program set, across reset and M30)
    power_on        text CHECK (power_on ~ '^G(18|40|9[0457-9])( G(18|40|9[0457-9]))*$'),
    -- What a hobbing program does besides cutting, for its floor-to-floor time (NULL: not stated):
    -- degrees per second of the swivel head; seconds of a spindle start (M3/M4), of a coupling's
    -- synchronisation (EGON), of the tailstock's clamp or release (each), of the door's close or
    -- open (each), of a tool call (T), and of loading and unloading one part.
    swivel_speed     numeric CHECK (swivel_speed > 0),
    spindle_runup    numeric CHECK (spindle_runup >= 0),
    coupling_sync    numeric CHECK (coupling_sync >= 0),
    tailstock_time   numeric CHECK (tailstock_time >= 0),
    door_time        numeric CHECK (door_time >= 0),
    tool_change_time numeric CHECK (tool_change_time >= 0),
    load_unload_time numeric CHECK (load_unload_time >= 0),
    -- Fanuc hobbers (migration 0037, fanuc-egb.md §F5): the sign the control applies G81's helical
    -- compensation Z·sin P·360/(π·T·Q) with, in the machine's C and Z senses (+1 the literal
    -- formula, -1 its opposite); NULL = not stated (a helical gear's Fanuc program is refused).
    egb_helix_sign   smallint CHECK (egb_helix_sign IN (-1, 1)),
    -- Fanuc hobbers (migration 0038, fanuc-egb.md §F7): the O number of a gear's program is
    -- program_number_base + the gear's id (a whole number; O1042 for gear 42 at 1000), within
    -- 1…99999 and outside O9000…O9999; NULL = no rule stated (no Fanuc hobbing program).
    program_number_base integer CHECK (program_number_base BETWEEN 0 AND 99998),
    CONSTRAINT machine_reference_point CHECK ((reference_x IS NULL) = (reference_z IS NULL)),
    CHECK (x_min < x_max AND y_min <= y_max AND z_min < z_max),
    CONSTRAINT machine_safe_name CHECK (safe_name('machine', name)),
    CONSTRAINT machine_load_position CHECK ((load_x IS NULL) = (load_z IS NULL))
);

-- Hob library: the tools a hobbing job may use; a hob's id is printed in the program.
CREATE TABLE hob (
    id             text PRIMARY KEY,
    module         numeric NOT NULL CHECK (module > 0),
    pressure_angle numeric NOT NULL DEFAULT 20 CHECK (pressure_angle > 0 AND pressure_angle < 45),
    starts         integer NOT NULL CHECK (starts > 0),
    tip_diameter   numeric NOT NULL CHECK (tip_diameter > 0),
    length         numeric NOT NULL CHECK (length > 0),
    hand           text NOT NULL CHECK (hand IN ('L', 'R')),
    accuracy_class text NOT NULL,
    material       text NOT NULL DEFAULT 'HSS',
    coating        text NOT NULL DEFAULT '',
    -- A worm-wheel hob is made for its worm; it never cuts cylindrical gears, nor the reverse.
    purpose        text NOT NULL DEFAULT 'cylindrical' CHECK (purpose IN ('cylindrical', 'worm_wheel')),
    tool_number    integer NOT NULL DEFAULT 1 CHECK (tool_number BETWEEN 1 AND 32000),  -- T<n> D1
    -- The module the record gives: normal, or (worm-wheel hobs, as catalogued: DIN 3975) the
    -- worm's axial module m_x; the engine converts it on load to m_n = m_x·cos γ0.
    module_kind    text NOT NULL DEFAULT 'normal' CHECK (module_kind IN ('normal', 'axial')),
    -- Gashes (flutes): i = gashes/starts edges share a workpiece revolution's feed, which bounds
    -- it by the chip thickness (Hoffmeister, docs/reference/hobbing.md §C1); 12 = the usual solid
    -- HSS catalogue hob of m1–m4 (DIN 3968).
    gashes         integer NOT NULL DEFAULT 12 CHECK (gashes > 0),
    -- The tooth profile: the basic rack's, a protuberance (undercuts the root ahead of shaving or
    -- grinding), or topping (the hob's root also cuts the gear's tip).
    profile        text NOT NULL DEFAULT 'standard' CHECK (profile IN ('standard', 'protuberance', 'topping')),
    CONSTRAINT hob_safe_id CHECK (safe_name('hob', id)),
    CONSTRAINT hob_axial_module_of_worm_wheel_hobs CHECK (module_kind = 'normal' OR purpose = 'worm_wheel')
);
-- One hob per id whatever its case: H-M2-AA-R1 and h-m2-aa-r1 are one hob.
CREATE UNIQUE INDEX hob_id_ignoring_case ON hob (upper(id));

-- Work-holding library (issue 29): arbors, mandrels, collets and centres a job may be clamped on
-- instead of the machine record's fixture and tailstock; its id is printed in the program.
CREATE TABLE work_holding (
    id                 text PRIMARY KEY,
    kind               text NOT NULL CHECK (kind IN ('arbor', 'mandrel', 'collet', 'centres')),
    -- the part under the gear the hob must clear: its diameter and height (mm), its top face the
    -- machine record's fixture_gap below the gear's bottom face; the machine's fixture below it
    diameter           numeric NOT NULL CHECK (diameter > 0 AND diameter < 'Infinity'),
    height             numeric NOT NULL CHECK (height > 0 AND height < 'Infinity'),
    -- the centre (or tailstock) above the top face, mm; 0 = none
    tailstock_diameter numeric NOT NULL DEFAULT 0 CHECK (tailstock_diameter >= 0 AND tailstock_diameter < 'Infinity'),
    machine            text REFERENCES machine (name),   -- the machine it fits; NULL = any hobber
    CONSTRAINT work_holding_safe_id CHECK (id ~ '^[A-Za-z0-9][A-Za-z0-9_.-]{0,31}$')
);
-- One work-holding per id whatever its case (a setter reading `; FIXTURE …` cannot tell them apart).
CREATE UNIQUE INDEX work_holding_id_ignoring_case ON work_holding (upper(id));

-- Workpiece materials (issue 31): group, hardness range and the cutting speeds of
-- docs/reference/hobbing.md §C by hob material and coating, with their source. A gear whose
-- material is not here is refused at instantiate (engine.gears.materials).
CREATE TABLE material (
    name             text PRIMARY KEY CHECK (name = btrim(name) AND name <> '' AND length(name) <= 40),
    material_group   text NOT NULL CHECK (btrim(material_group) <> ''),
    -- the hardness range the speeds are for, Brinell (HB), as delivered for hobbing
    hardness_min     numeric NOT NULL CHECK (hardness_min > 0 AND hardness_min < 'Infinity'),
    hardness_max     numeric NOT NULL CHECK (hardness_max < 'Infinity'),
    -- cutting speed v [m/min], lowest and highest, by the hob's §C column: uncoated HSS (wet),
    -- TiN/TiAlN coated (PM-)HSS, carbide (dry)
    uncoated_low     numeric NOT NULL CHECK (uncoated_low > 0),
    uncoated_high    numeric NOT NULL CHECK (uncoated_high < 'Infinity'),
    coated_low       numeric NOT NULL CHECK (coated_low > 0),
    coated_high      numeric NOT NULL CHECK (coated_high < 'Infinity'),
    carbide_low      numeric NOT NULL CHECK (carbide_low > 0),
    carbide_high     numeric NOT NULL CHECK (carbide_high < 'Infinity'),
    -- the speed a job with no machining history takes, uncoated and coated hob [m/min]
    default_uncoated numeric NOT NULL,
    default_coated   numeric NOT NULL,
    source           text NOT NULL CHECK (btrim(source) <> ''),
    CONSTRAINT material_hardness_range CHECK (hardness_min <= hardness_max),
    CONSTRAINT material_speed_ranges CHECK (uncoated_low <= uncoated_high AND coated_low <= coated_high
                                            AND carbide_low <= carbide_high),
    CONSTRAINT material_defaults_in_range CHECK (default_uncoated BETWEEN uncoated_low AND uncoated_high
                                                 AND default_coated BETWEEN coated_low AND coated_high)
);
-- One material per name whatever its case (the engine matches a gear's material ignoring case).
CREATE UNIQUE INDEX material_name_ignoring_case ON material (lower(name));

INSERT INTO material (name, material_group, hardness_min, hardness_max, uncoated_low, uncoated_high,
                      coated_low, coated_high, carbide_low, carbide_high, default_uncoated, default_coated, source)
VALUES
    ('45', 'carbon steel', 170, 220, 30, 45, 60, 120, 150, 300, 38, 90, 'hobbing.md §C'),
    ('C45', 'carbon steel', 170, 220, 30, 45, 60, 120, 150, 300, 38, 90, 'hobbing.md §C'),
    ('20CrMnTi', 'case-hardening steel', 160, 210, 30, 40, 60, 110, 150, 280, 35, 85, 'hobbing.md §C'),
    ('40Cr', 'alloy steel, quenched and tempered', 220, 280, 20, 35, 50, 90, 120, 220, 28, 70, 'hobbing.md §C'),
    ('42CrMo4', 'alloy steel, quenched and tempered', 250, 300, 20, 35, 50, 90, 120, 220, 28, 70,
     'hobbing.md §C2, judgement: the row of 40Cr'),
    ('34CrNiMo6', 'alloy steel, quenched and tempered', 260, 320, 18, 30, 45, 80, 100, 200, 24, 62,
     'hobbing.md §C2, judgement: below the row of 40Cr'),
    ('38CrMoAl', 'nitriding steel', 230, 290, 20, 35, 50, 90, 120, 220, 28, 70,
     'hobbing.md §C2, judgement: the row of 40Cr'),
    ('16MnCr5', 'case-hardening steel', 150, 200, 30, 40, 60, 110, 150, 280, 35, 85,
     'hobbing.md §C2, judgement: the row of 20CrMnTi'),
    ('20MnCr5', 'case-hardening steel', 160, 210, 30, 40, 60, 110, 150, 280, 35, 85,
     'hobbing.md §C2, judgement: the row of 20CrMnTi'),
    ('20CrMnMo', 'case-hardening steel', 180, 230, 25, 35, 55, 100, 140, 250, 30, 78,
     'hobbing.md §C2, judgement: below the row of 20CrMnTi'),
    ('18CrNiMo7-6', 'case-hardening steel', 170, 230, 25, 35, 55, 100, 140, 250, 30, 78,
     'hobbing.md §C2, judgement: below the row of 20CrMnTi'),
    ('17CrNiMo6', 'case-hardening steel', 170, 230, 25, 35, 55, 100, 140, 250, 30, 78,
     'hobbing.md §C2, judgement: the row of 18CrNiMo7-6 (its former name)'),
    ('EN-GJL-250', 'grey cast iron', 180, 250, 25, 40, 50, 90, 120, 250, 32, 70,
     'hobbing.md §C2, judgement from the group'),
    ('HT250', 'grey cast iron', 180, 250, 25, 40, 50, 90, 120, 250, 32, 70,
     'hobbing.md §C2, judgement: the row of EN-GJL-250'),
    ('EN-GJS-600-3', 'ductile cast iron', 190, 270, 20, 35, 45, 85, 110, 220, 28, 65,
     'hobbing.md §C2, judgement from the group'),
    ('QT600-3', 'ductile cast iron', 190, 270, 20, 35, 45, 85, 110, 220, 28, 65,
     'hobbing.md §C2, judgement: the row of EN-GJS-600-3'),
    ('CuSn12', 'tin bronze (worm wheels)', 80, 120, 40, 60, 60, 120, 150, 300, 50, 90,
     'hobbing.md §C2, judgement from the group'),
    ('ZCuSn10P1', 'tin bronze (worm wheels)', 80, 120, 40, 60, 60, 120, 150, 300, 50, 90,
     'hobbing.md §C2, judgement: the row of CuSn12');

-- Workpieces (design notes §9 columns).
CREATE TABLE gear (
    id             integer PRIMARY KEY CHECK (id > 0),
    gear_class     text REFERENCES gear_class (name),
    module         numeric NOT NULL CHECK (module > 0),
    teeth          integer NOT NULL CHECK (teeth > 0),
    pressure_angle numeric NOT NULL DEFAULT 20 CHECK (pressure_angle > 0 AND pressure_angle < 45),
    helix_angle    numeric NOT NULL DEFAULT 0 CHECK (helix_angle >= 0 AND helix_angle < 60),
    hand           text CHECK (hand IN ('L', 'R')),
    face_width     numeric NOT NULL CHECK (face_width > 0),
    tip_diameter   numeric CHECK (tip_diameter > 0),
    root_diameter  numeric CHECK (root_diameter > 0),
    cone_angle     numeric,
    crowning       numeric,
    material       text,
    hardness       numeric,
    quality_grade  integer CHECK (quality_grade BETWEEN 1 AND 12),
    quantity       integer CHECK (quantity > 0),
    -- The module stated is normal, or the worm's axial module m_x (worm wheels):
    -- m_n = m_x·cos γ. NULL = not stated: normal for cylindrical gears, refused for worm wheels.
    module_kind    text CHECK (module_kind IN ('normal', 'axial')),
    -- When the gear was stored (`engine gears list --since/--until`): set by the database on
    -- insert; an import that updates a gear keeps the first date. NULL for gears stored before
    -- dates were kept (their date is unknown, and no date is invented for them).
    created_at     timestamptz DEFAULT now(),
    -- The profile shift x (in modules), as the drawing gives it. The gear import checks the tip
    -- and root diameters of cylindrical gears against d = m_n·z/cos β, d_a = d + 2·m_n·(1 + x)
    -- and d_f = d − 2·m_n·(1.25 − x); NULL = not given (the diameters must then fit some plausible x).
    profile_shift  numeric CONSTRAINT gear_profile_shift CHECK (profile_shift > -2 AND profile_shift < 2),
    CHECK (helix_angle = 0 OR hand IS NOT NULL),
    CONSTRAINT gear_cone_angle CHECK (cone_angle > -45 AND cone_angle < 45),
    CONSTRAINT gear_crowning CHECK (crowning >= 0 AND crowning < 1)
);

-- A drawing as `engine import-dxf` read it (issue 26): what the turning proof takes the part, the
-- blank, the tool-change position and the materials from, never from job.params (which a runner
-- may edit in SQL). Written once with its job, never changed or deleted: importing the drawing
-- again (e.g. with another --material) makes a new record and a new job. profile: the segments as
-- job.params.profile holds them ([["line", z0, r0, z1, r1] | ["arc", z0, r0, z1, r1, zc, rc, ccw]],
-- mm); stock_diameter NULL: the blank the importer assumes (docs/design.md §8); workpiece_material
-- and tool_materials ({"n": material} per operation) NULL: the defaults. sha256 of the file's
-- bytes; NULL for the records migration 0027 made from jobs imported before it (imported_by
-- 'migration 0027'). threads: each THREAD operation's pitch and crest and root lines as the job's
-- module_params hold them ({"n": {"thread_pitch": p, "paths": [...]}}, {} for none; migration
-- 0028), NULL when not recorded (records no job names at 0028: the proof reads module_params).
CREATE TABLE drawing (
    id                 bigserial PRIMARY KEY,
    file_name          text NOT NULL,
    sha256             text CHECK (sha256 ~ '^[0-9a-f]{64}$'),
    units              text,
    profile            jsonb NOT NULL CHECK (jsonb_typeof(profile) = 'array'),
    stock_diameter     double precision CHECK (stock_diameter > 0),
    stock_z_front      double precision,
    stock_z_back       double precision,
    tool_change_x      double precision,
    tool_change_z      double precision,
    workpiece_material text,
    tool_materials     jsonb CHECK (tool_materials IS NULL OR jsonb_typeof(tool_materials) = 'object'),
    imported_by        text NOT NULL DEFAULT current_user,
    imported_at        timestamptz NOT NULL DEFAULT now(),
    threads            jsonb CHECK (threads IS NULL OR jsonb_typeof(threads) = 'object')
);
CREATE TRIGGER drawing_is_a_record BEFORE UPDATE OR DELETE ON drawing
FOR EACH ROW EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER drawing_is_not_truncated BEFORE TRUNCATE ON drawing
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- A job: one workpiece on one machine with every parameter its template needs, as computed
-- by the class's model (and possibly edited afterwards in SQL).
-- params: {"name": value}; module_params: {"cutmotion:1": {"name": value}} (scope of module T,N).
CREATE TABLE job (
    id            bigserial PRIMARY KEY,
    gear_id       integer REFERENCES gear (id),
    gear_class    text NOT NULL REFERENCES gear_class (name),
    machine       text NOT NULL REFERENCES machine (name),
    hob_id        text REFERENCES hob (id),
    params        jsonb NOT NULL CHECK (jsonb_typeof(params) = 'object'),
    module_params jsonb NOT NULL DEFAULT '{}' CHECK (jsonb_typeof(module_params) = 'object'),
    created_at    timestamptz NOT NULL DEFAULT now(),
    -- the cutting data chosen for the job and where they came from; confirmed jobs become cases
    cutting       jsonb NOT NULL DEFAULT '{}' CHECK (jsonb_typeof(cutting) = 'object'),
    confirmed_at  timestamptz,
    -- a turning job's drawing record (NULL: a hobbing job, or a class job without a drawing)
    drawing_id    bigint REFERENCES drawing (id),
    -- the work-holding the job is clamped on (NULL: the machine record's fixture and tailstock)
    work_holding_id text REFERENCES work_holding (id),
    CONSTRAINT job_safe_params CHECK (job_params_safe(params, module_params))
);
CREATE INDEX job_gear ON job (gear_id);

-- Further toothed units of a multi-unit (duplex) gear; unit 1 is the gear row itself.
-- One hob cuts all units, so module and pressure angle are the gear's.
CREATE TABLE gear_unit (
    gear_id       integer NOT NULL REFERENCES gear (id) ON DELETE CASCADE,
    unit          integer NOT NULL CHECK (unit >= 2),
    teeth         integer NOT NULL CHECK (teeth > 0),
    face_width    numeric NOT NULL CHECK (face_width > 0),
    tip_diameter  numeric CHECK (tip_diameter > 0),
    root_diameter numeric CHECK (root_diameter > 0),
    z_top         numeric NOT NULL CHECK (z_top < 0),   -- Z of the unit's upper face, mm
    PRIMARY KEY (gear_id, unit)
);

-- The machining history: one case per cut of a proven job (paper §4).
CREATE TABLE cutting_case (
    id               bigserial PRIMARY KEY,
    module           numeric NOT NULL CHECK (module > 0),
    teeth            integer NOT NULL CHECK (teeth > 0),
    material         text NOT NULL,
    hardness         numeric,                                  -- HB
    quality_grade    integer CHECK (quality_grade BETWEEN 1 AND 12),
    hob_material     text NOT NULL,
    hob_coating      text NOT NULL DEFAULT '',
    hob_starts       integer NOT NULL CHECK (hob_starts > 0),
    hob_tip_diameter numeric NOT NULL CHECK (hob_tip_diameter > 0),
    cut              text NOT NULL CHECK (cut IN ('rough', 'finish')),
    hob_speed        numeric NOT NULL CHECK (hob_speed > 0),   -- r/min
    axial_feed       numeric NOT NULL CHECK (axial_feed > 0),  -- mm/min
    radial_feed      numeric NOT NULL CHECK (radial_feed > 0), -- mm/min
    source           text NOT NULL DEFAULT '',
    job_id           bigint REFERENCES job (id) ON DELETE SET NULL,
    created_at       timestamptz NOT NULL DEFAULT now()
);

-- Physically plausible cases, whoever adds them: finite values (numeric takes NaN and infinity),
-- a cutting speed v = π·d_a0·n0/1000 of at most 600 m/min (twice the fastest of reference §C,
-- carbide dry), feeds per workpiece revolution f = v_f/(n0·z0/z2) of at most 10·m_n (2.5 to 10
-- times the typical ranges of §C; the paper's suspicious 8.1 mm at m 2 stays in). Cases stored
-- before the rule are not re-checked (NOT VALID).
ALTER TABLE cutting_case ADD CONSTRAINT cutting_case_plausible CHECK (
    module < 'Infinity' AND hob_tip_diameter < 'Infinity' AND hob_speed < 'Infinity'
    AND axial_feed < 'Infinity' AND radial_feed < 'Infinity'
    AND (hardness IS NULL OR hardness > 0 AND hardness < 'Infinity')
    AND pi() * hob_tip_diameter * hob_speed / 1000 <= 600
    AND axial_feed * teeth <= 10 * module * hob_speed * hob_starts
    AND radial_feed * teeth <= 10 * module * hob_speed * hob_starts) NOT VALID;

-- A number of a job's cutting data, or NULL if it is not a positive finite number.
CREATE FUNCTION cutting_number(value jsonb) RETURNS numeric
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN CASE WHEN jsonb_typeof(value) = 'number' AND value::text::numeric > 0 THEN value::text::numeric END;

-- engine cases confirm: a job the engine made a program for, whose cutting data its machine can
-- run, joins the history, one case per cut kind of its stored cutting data. The case's values
-- are the job's; the hob speed is the one its last program ran (n0). Returns the new case ids.
CREATE FUNCTION confirm_job_cases(confirmed_job bigint) RETURNS bigint[]
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    found_job record;
    speed numeric;
    ran numeric;
    cut text;
    ids bigint[] := '{}';
    case_id bigint;
BEGIN
    SELECT j.cutting, j.confirmed_at, j.machine, g.id AS gear_id, g.module, g.teeth, g.material, g.hardness,
           g.quality_grade, h.material AS hob_material, h.coating, h.starts, h.tip_diameter, m.spindle_max,
           m.table_speed_max
    INTO found_job
    FROM job j LEFT JOIN gear g ON g.id = j.gear_id LEFT JOIN hob h ON h.id = j.hob_id
    JOIN machine m ON m.name = j.machine
    WHERE j.id = confirmed_job FOR UPDATE OF j;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'job % does not exist; nothing confirmed', confirmed_job USING ERRCODE = 'no_data_found';
    END IF;
    IF found_job.confirmed_at IS NOT NULL THEN
        RAISE EXCEPTION 'job % was already confirmed at %; its cases are in the history (engine cases list)',
                        confirmed_job, to_char(found_job.confirmed_at, 'YYYY-MM-DD HH24:MI')
            USING ERRCODE = 'check_violation';
    END IF;
    IF NOT (found_job.cutting ? 'rough' OR found_job.cutting ? 'finish') THEN
        RAISE EXCEPTION 'job % has no cutting data stored (job.cutting is empty); store the chosen cutting data '
                        'with the job before confirming it', confirmed_job USING ERRCODE = 'check_violation';
    END IF;
    IF found_job.gear_id IS NULL OR found_job.tip_diameter IS NULL THEN
        RAISE EXCEPTION 'job % has no gear or no hob; only hobbing jobs become cutting cases', confirmed_job
            USING ERRCODE = 'check_violation';
    END IF;
    IF found_job.material IS NULL THEN
        RAISE EXCEPTION 'gear % of job % has no material; set it before confirming the job', found_job.gear_id,
                        confirmed_job USING ERRCODE = 'check_violation';
    END IF;
    SELECT cutting_number(p.trace->'inputs'->'job'->'n0') INTO ran FROM program p
    WHERE p.job_id = confirmed_job ORDER BY p.id DESC LIMIT 1;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'job % has no stored program: only a job the engine made a program for becomes a case; '
                        'make it first (engine instantiate --job %)', confirmed_job, confirmed_job
            USING ERRCODE = 'check_violation';
    END IF;
    speed := cutting_number(found_job.cutting->'hob_speed');
    FOREACH cut IN ARRAY ARRAY['rough', 'finish'] LOOP
        CONTINUE WHEN NOT found_job.cutting ? cut;
        IF speed IS NULL OR cutting_number(found_job.cutting->cut->'axial_feed') IS NULL
           OR cutting_number(found_job.cutting->cut->'radial_feed') IS NULL THEN
            RAISE EXCEPTION 'job %: cutting data of the % cut need a positive hob_speed, axial_feed and radial_feed '
                            '(mm/min); fix job.cutting', confirmed_job, cut USING ERRCODE = 'check_violation';
        END IF;
    END LOOP;
    IF ran IS NULL THEN
        RAISE EXCEPTION 'job %: its last program does not record the hob speed it ran (no n0 in its trace), so '
                        'nothing vouches for job.cutting; make the program again (engine instantiate --job %)',
                        confirmed_job, confirmed_job USING ERRCODE = 'check_violation';
    END IF;
    IF ran IS DISTINCT FROM speed THEN
        RAISE EXCEPTION 'job %: job.cutting says hob speed % r/min, but its last program ran n0 = % r/min; make the '
                        'program again from the job or fix job.cutting', confirmed_job, speed, ran
            USING ERRCODE = 'check_violation';
    END IF;
    IF speed > found_job.spindle_max THEN
        RAISE EXCEPTION 'job %: hob speed % r/min exceeds %''s hob spindle maximum % r/min; not a case',
                        confirmed_job, speed, found_job.machine, found_job.spindle_max
            USING ERRCODE = 'check_violation';
    END IF;
    IF speed * found_job.starts / found_job.teeth > found_job.table_speed_max THEN
        RAISE EXCEPTION 'job %: table speed % r/min exceeds %''s % r/min; not a case', confirmed_job,
                        round(speed * found_job.starts / found_job.teeth, 1), found_job.machine,
                        found_job.table_speed_max
            USING ERRCODE = 'check_violation';
    END IF;
    FOREACH cut IN ARRAY ARRAY['rough', 'finish'] LOOP
        CONTINUE WHEN NOT found_job.cutting ? cut;
        INSERT INTO cutting_case (module, teeth, material, hardness, quality_grade, hob_material, hob_coating,
                                  hob_starts, hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed, source, job_id)
        VALUES (found_job.module, found_job.teeth, found_job.material, found_job.hardness, found_job.quality_grade,
                found_job.hob_material, found_job.coating, found_job.starts, found_job.tip_diameter, cut, speed,
                cutting_number(found_job.cutting->cut->'axial_feed'),
                cutting_number(found_job.cutting->cut->'radial_feed'), format('job %s', confirmed_job), confirmed_job)
        RETURNING id INTO case_id;
        ids := ids || case_id;
    END LOOP;
    UPDATE job SET confirmed_at = now() WHERE id = confirmed_job;
    RETURN ids;
END
$$;

-- ==============================================================================================
-- programs
-- ==============================================================================================

-- Section programs: programs, the records of what was made (after section records). One row per
-- instantiation: the emitted lines with the template row that emitted each, the template version
-- and hash it came from, who stored it. Stored only through store_program / program_submission,
-- checked on the way in (check_program, check_program_lines, and check_program_release in
-- section release: triggers fire in the order of their names), never changed or deleted. Every program
-- carries one lineage line (row id -1), written by the engine and held to the record here.
CREATE TABLE program (
    id               bigserial PRIMARY KEY,
    job_id           bigint NOT NULL REFERENCES job (id) ON DELETE CASCADE,
    gear_class       text NOT NULL REFERENCES gear_class (name),
    template_version integer NOT NULL,
    template_hash    text NOT NULL,
    name             text NOT NULL,
    lines            text[] NOT NULL,
    row_ids          integer[] NOT NULL,
    created_at       timestamptz NOT NULL DEFAULT now(),
    -- Per row of the template version: ran or skipped, emitted or suppressed, the conditions'
    -- values, the values computed and the inputs read with their origins (engine/templates/trace.py).
    -- NULL for programs stored before traces were kept.
    trace            jsonb,
    -- who stored it: the login person (session_user) and the role (NULL in programs stored before
    -- check_program stamped them)
    stored_by        text,
    stored_role      text,
    -- made from a version not released (an editor's try: the lineage line says DRAFT), and the
    -- hash of the job's parameters the lineage line shows; both set by check_program_release
    draft            boolean NOT NULL DEFAULT false,
    input_hash       text,
    -- stored with --unverified: no verifier read it (a job of an imported class on a machine whose
    -- dialect the verifier does not read, or whose program it refuses); the lineage line says
    -- UNVERIFIED, and the engine never writes such a program to a file for the machine
    unverified       boolean NOT NULL DEFAULT false,
    CHECK (cardinality(lines) = cardinality(row_ids))
);
CREATE INDEX program_job ON program (job_id);
-- A program is found by the 8 hex digits of a hash its lineage line shows (engine/programs/lookup.py).
CREATE INDEX program_input_hash ON program (left(input_hash, 8));
CREATE INDEX program_template_hash ON program (left(template_hash, 8));
-- Programs stored before names and lines were checked keep them (NOT VALID: records are not
-- rewritten); every program stored since has a safe name and lines without line breaks.
ALTER TABLE program ADD CONSTRAINT program_safe_name CHECK (safe_name('program', name)) NOT VALID;
ALTER TABLE program ADD CONSTRAINT program_lines_unbroken CHECK (NOT breaks_lines(array_to_string(lines, ''))) NOT VALID;
-- The version and hash a program records are a stored version of its class (checked for every
-- program stored since versions were stored; programs stored before may name versions never stored).
ALTER TABLE program ADD CONSTRAINT program_template_version
    FOREIGN KEY (gear_class, template_version, template_hash)
    REFERENCES template_version_rows (gear_class, version, hash) NOT VALID;

-- The paper's result table, one row per emitted NC line.
CREATE VIEW result_line AS
SELECT p.id AS program_id, l.line_no::integer AS line_no, p.row_ids[l.line_no] AS template_row_id,
       l.text
FROM program p,
     unnest(p.lines) WITH ORDINALITY AS l (text, line_no);

-- The trace as a table: one row per template row of each program, with the lines it emitted;
-- `read` names the origin of each input (its value: program_input, or the row's `computed`).
CREATE VIEW program_trace AS
SELECT p.id AS program_id, e.position::integer AS position, (e.entry->>'row')::integer AS row_id,
       (e.entry->>'calc')::boolean AS calc, (e.entry->>'emit')::boolean AS emit,
       e.entry->'p_calc' AS p_calc, e.entry->'p_emit' AS p_emit,
       e.entry->'computed' AS computed, e.entry->'read' AS read,
       ARRAY(SELECT l.text FROM unnest(p.lines, p.row_ids) AS l (text, row_id)
             WHERE l.row_id = (e.entry->>'row')::integer) AS lines
FROM program p,
     jsonb_array_elements(p.trace->'rows') WITH ORDINALITY AS e (entry, position);

-- The values a program's rows read from the job and from module parameters, once each.
CREATE VIEW program_input AS
SELECT p.id AS program_id, o.key AS origin, v.key AS name, v.value
FROM program p,
     jsonb_each(p.trace->'inputs') AS o,
     jsonb_each(o.value) AS v;

-- The hash of a job's parameters that a program's lineage line shows (16 hex digits; the line
-- shows 8): sha256 of jsonb's own text of [params, module_params].
CREATE FUNCTION job_input_hash(params jsonb, module_params jsonb) RETURNS text
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN left(encode(sha256(convert_to(jsonb_build_array(coalesce(params, '{}'), coalesce(module_params, '{}'))::text,
                                     'UTF8')), 'hex'), 16);

-- The lineage line's words (the engine writes them as an 840D comment `; …` or an ISO one `(…)`).
CREATE FUNCTION program_lineage(program_id bigint, class_name text, version integer, template_hash text,
                                input_hash text, draft boolean) RETURNS text
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN format('PROGRAM %s TEMPLATE %s v%s %s INPUT %s', program_id, class_name, version, left(template_hash, 8),
              left(input_hash, 8)) || CASE WHEN draft THEN ' DRAFT' ELSE '' END;

-- The same words, with ` UNVERIFIED` after ` DRAFT` for a program no verifier read.
CREATE FUNCTION program_lineage(program_id bigint, class_name text, version integer, template_hash text,
                                input_hash text, draft boolean, unverified boolean) RETURNS text
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN program_lineage(program_id, class_name, version, template_hash, input_hash, draft)
       || CASE WHEN unverified THEN ' UNVERIFIED' ELSE '' END;

-- A program carries one lineage line, the engine's (row id -1). A line a template row wrote must
-- never read as one: a program's printout imported as a template (`engine import-nc`), or a dry
-- run's `; PROGRAM DRY-RUN TEMPLATE …`, would otherwise give every program of the class a second
-- lineage naming another program and version, and the operator who matches the file on the
-- control to its record would find the wrong one. What reads as a lineage line at the control:
-- the comment may follow a block number or a move (`N10 ; PROGRAM 1 TEMPLATE …`), and only a
-- program id or DRY-RUN makes one (`; program from template of spur` is a shop's comment). The
-- spaces are spelled out rather than \s, whose meaning depends on the server's locale, so the
-- database reads exactly the lines engine.programs.lineage.LINEAGE_SHAPE reads.
CREATE FUNCTION lineage_shaped(line text) RETURNS boolean
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN line ~* ('[;(][ \t\v\f\r\n\u0085\u00a0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000\u001c-\u001f]*'
                'PROGRAM[ \t\v\f\r\n\u0085\u00a0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000\u001c-\u001f]+'
                '([0-9]+|DRY-RUN)[ \t\v\f\r\n\u0085\u00a0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000\u001c-\u001f]+'
                'TEMPLATE');

-- What the database can check of a program before it is stored, and who stored it when: its id
-- was drawn from program_id_seq, its job is of its class, its version and hash are a stored
-- version (stored now if it is the class's current one), its lines are one or more texts without
-- line breaks, each from a row of that version or the lineage line (row id -1).
CREATE FUNCTION check_program() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    job_class text;
    stored record;
BEGIN
    NEW.stored_by := session_user;
    NEW.stored_role := template_editor();
    NEW.created_at := now();
    IF NEW.id > (SELECT last_value FROM program_id_seq) THEN
        RAISE EXCEPTION 'program %: its id was not drawn from program_id_seq', NEW.id
            USING ERRCODE = 'check_violation', COLUMN = 'id';
    END IF;
    SELECT j.gear_class INTO job_class FROM job j WHERE j.id = NEW.job_id;
    IF NOT FOUND OR job_class IS DISTINCT FROM NEW.gear_class THEN
        RAISE EXCEPTION 'program % for job %: %', NEW.name, NEW.job_id,
                        CASE WHEN job_class IS NULL THEN 'the job does not exist'
                             ELSE format('the job is of class %s, the program says %s', job_class, NEW.gear_class) END
            USING ERRCODE = 'foreign_key_violation', COLUMN = 'job_id';
    END IF;
    SELECT v.hash, v.row_ids INTO stored FROM template_version_rows v
    WHERE v.gear_class = NEW.gear_class AND v.version = NEW.template_version;
    IF NOT FOUND AND NEW.template_version = (SELECT template_version FROM gear_class WHERE name = NEW.gear_class) THEN
        PERFORM store_current_version(NEW.gear_class);   -- made in this transaction: fixed from now on
        SELECT v.hash, v.row_ids INTO stored FROM template_version_rows v
        WHERE v.gear_class = NEW.gear_class AND v.version = NEW.template_version;
    END IF;
    IF stored.hash IS DISTINCT FROM NEW.template_hash THEN
        RAISE EXCEPTION 'program % for job %: class % version % %; a program records the template it was made '
                        'from: make programs with the engine', NEW.name, NEW.job_id, NEW.gear_class,
                        NEW.template_version,
                        CASE WHEN stored.hash IS NULL THEN 'is not a stored version'
                             ELSE format('has hash %s, not %s', stored.hash, NEW.template_hash) END
            USING ERRCODE = 'foreign_key_violation', COLUMN = 'template_hash';
    END IF;
    IF cardinality(NEW.lines) = 0 OR array_ndims(NEW.lines) <> 1 OR array_lower(NEW.lines, 1) <> 1
       OR array_position(NEW.lines, NULL) IS NOT NULL OR array_position(NEW.row_ids, NULL) IS NOT NULL THEN
        RAISE EXCEPTION 'program % for job %: lines must be a list of one or more texts, each with its row id',
                        NEW.name, NEW.job_id
            USING ERRCODE = 'check_violation', COLUMN = 'lines';
    END IF;
    IF NOT NEW.row_ids <@ (stored.row_ids || -1) THEN
        RAISE EXCEPTION 'program % for job %: row ids % are not rows of class % version %', NEW.name, NEW.job_id,
                        ARRAY(SELECT DISTINCT r FROM unnest(NEW.row_ids) r WHERE r <> ALL (stored.row_ids || -1) ORDER BY r),
                        NEW.gear_class, NEW.template_version
            USING ERRCODE = 'check_violation', COLUMN = 'row_ids';
    END IF;
    IF array_to_string(NEW.lines, '') ~ '[\x01-\x1f\x7f-\x9f\u2028\u2029]' THEN
        RAISE EXCEPTION 'program % for job %: line % holds a control character (CR, LF, TAB, ...); a line is one '
                        'block', NEW.name, NEW.job_id,
                        (SELECT min(l.number) FROM unnest(NEW.lines) WITH ORDINALITY AS l (text, number)
                         WHERE l.text ~ '[\x01-\x1f\x7f-\x9f\u2028\u2029]')
            USING ERRCODE = 'check_violation', COLUMN = 'lines';
    END IF;
    IF NEW.trace IS NOT NULL AND jsonb_typeof(NEW.trace) <> 'object' THEN
        RAISE EXCEPTION 'program % for job %: the trace must be a JSON object', NEW.name, NEW.job_id
            USING ERRCODE = 'check_violation', COLUMN = 'trace';
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER check_program BEFORE INSERT ON program
FOR EACH ROW EXECUTE FUNCTION check_program();
CREATE TRIGGER program_is_a_record BEFORE UPDATE OR DELETE ON program
FOR EACH ROW EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER program_is_not_truncated BEFORE TRUNCATE ON program
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- A line a template row wrote that reads as a lineage line is refused, whatever wrote the rows
-- (SQL editing through template_view included); the engine refuses such files and rows too.
-- Fires between check_program and check_program_release (triggers fire in the order of their names).
CREATE FUNCTION check_program_lines() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
DECLARE
    hit record;
BEGIN
    SELECT l.number, l.text, l.row_id INTO hit
    FROM unnest(NEW.lines, NEW.row_ids) WITH ORDINALITY AS l (text, row_id, number)
    WHERE l.row_id IS DISTINCT FROM -1 AND lineage_shaped(l.text)
    ORDER BY l.number LIMIT 1;
    IF FOUND THEN
        RAISE EXCEPTION 'program % for job %: line % %, written by template row %, reads as a lineage line; only '
                        'the engine writes that line (row id -1): remove the row from class %''s template',
                        NEW.name, NEW.job_id, hit.number, quote_literal(hit.text), hit.row_id, NEW.gear_class
            USING ERRCODE = 'check_violation', COLUMN = 'lines';
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER check_program_lines BEFORE INSERT ON program
FOR EACH ROW EXECUTE FUNCTION check_program_lines();

-- The engine's path for one program: its id.
CREATE FUNCTION store_program(job_id bigint, gear_class text, template_version integer, template_hash text,
                              name text, lines text[], row_ids integer[], trace jsonb) RETURNS bigint
LANGUAGE sql SECURITY DEFINER SET search_path = public, pg_temp
BEGIN ATOMIC
    INSERT INTO program (job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace)
    VALUES (job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace)
    RETURNING id;
END;

-- The engine's path for a batch: COPY into this view (ids drawn from program_id_seq first);
-- each row is checked and stored as store_program stores one; the submission says whether the
-- program is unverified (store_program's programs are verified).
CREATE VIEW program_submission AS
SELECT id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace, unverified FROM program
WHERE false;
ALTER VIEW program_submission ALTER COLUMN unverified SET DEFAULT false;

-- Each row COPYed into program_submission is stored in program, so the same checks run on it.
CREATE FUNCTION submit_program() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    INSERT INTO program (id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace,
                         unverified)
    VALUES (coalesce(NEW.id, nextval('program_id_seq')), NEW.job_id, NEW.gear_class, NEW.template_version,
            NEW.template_hash, NEW.name, NEW.lines, NEW.row_ids, NEW.trace, coalesce(NEW.unverified, false))
    RETURNING id INTO NEW.id;
    RETURN NEW;
END
$$;

CREATE TRIGGER submit_program INSTEAD OF INSERT ON program_submission
FOR EACH ROW EXECUTE FUNCTION submit_program();

-- What each machine asked for and was sent (issue 32: `engine serve`, its FTP server and request
-- folder): one row per request, a program sent or the one-line reason it was refused. A request
-- names the machine that logged in (FTP) or whose folder it came from; a program sent is one of
-- that machine's jobs, stored by the same request (engine/service/delivery.py). Rows are records,
-- never changed: the history of what a control ran.
CREATE TABLE program_request (
    id            bigserial PRIMARY KEY,
    machine       text NOT NULL REFERENCES machine (name),
    via           text NOT NULL CHECK (via IN ('ftp', 'folder', 'web')),
    client        text NOT NULL,   -- ftp: the client's address; folder: the request file; web: the login
    asked_for     text NOT NULL CHECK (length(asked_for) <= 200),   -- the file name or request asked for
    job_id        bigint REFERENCES job (id),   -- NULL: the request named no job of this machine
    program_id    bigint REFERENCES program (id),   -- NULL: refused
    refusal       text CHECK (refusal !~ '[\x01-\x1f]' AND length(refusal) <= 2000),   -- one line; NULL: sent
    requested_at  timestamptz NOT NULL DEFAULT now(),
    requested_by  text NOT NULL DEFAULT session_user,
    CONSTRAINT program_request_sent_or_refused CHECK ((program_id IS NULL) <> (refusal IS NULL)),
    CONSTRAINT program_request_sent_of_a_job CHECK (program_id IS NULL OR job_id IS NOT NULL)
);
CREATE INDEX program_request_machine ON program_request (machine, requested_at DESC);
CREATE INDEX program_request_program ON program_request (program_id);

-- A program sent is a program of the request's job, and that job is the request's machine's: the
-- history never says a machine ran another machine's program.
CREATE FUNCTION check_program_request() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
BEGIN
    IF NEW.job_id IS NOT NULL AND NOT EXISTS (SELECT 1 FROM job WHERE id = NEW.job_id AND machine = NEW.machine) THEN
        RAISE EXCEPTION 'request %: job % is not a job of machine %', NEW.id, NEW.job_id, NEW.machine
            USING ERRCODE = 'check_violation', COLUMN = 'job_id';
    END IF;
    IF NEW.program_id IS NOT NULL
       AND NOT EXISTS (SELECT 1 FROM program WHERE id = NEW.program_id AND job_id = NEW.job_id) THEN
        RAISE EXCEPTION 'request %: program % is not a program of job %', NEW.id, NEW.program_id, NEW.job_id
            USING ERRCODE = 'check_violation', COLUMN = 'program_id';
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER check_program_request BEFORE INSERT ON program_request
FOR EACH ROW EXECUTE FUNCTION check_program_request();
CREATE TRIGGER program_request_is_a_record BEFORE UPDATE OR DELETE ON program_request
FOR EACH ROW EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER program_request_is_not_truncated BEFORE TRUNCATE ON program_request
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- ==============================================================================================
-- release
-- ==============================================================================================

-- Section release: release control (after section programs). Editors change a class's template as
-- a draft version; runners get only the released version, which `engine template release`
-- (the gate: golden tests, impact, lint) makes; every program records whether it was made from a
-- draft. A release is a record, never changed. Also the golden tests the gate runs.

-- One row per release of a class's version, with what the gate found (engine template release).
-- tests: the golden tests the gate ran, [{"class", "name", "passed"}]; impact: the gate's summary
-- ({"jobs", "changed", ...}); checks: what else the gate checked (lint, static analysis). These
-- three are what the caller of release_template states: a screen never shows them as the gate's
-- result without re-running the recorded golden_tests (engine.release.recheck).
CREATE TABLE template_release (
    id          bigserial PRIMARY KEY,
    gear_class  text NOT NULL,
    version     integer NOT NULL,
    hash        text NOT NULL,
    released_at timestamptz NOT NULL DEFAULT now(),
    released_by text NOT NULL DEFAULT session_user,   -- the login person
    role        text NOT NULL,                        -- the role acting (template_editor())
    tests       jsonb NOT NULL DEFAULT '[]',
    impact      jsonb NOT NULL DEFAULT '{}',
    checks      jsonb NOT NULL DEFAULT '{}',
    note        text,
    -- how the releasing login says it released: engine (after the gate), seed, sql (by hand),
    -- unrecorded (before migration 0026); a claim, never a proof (docs/design.md §10)
    released_via text NOT NULL DEFAULT 'sql' CHECK (released_via IN ('engine', 'seed', 'sql', 'unrecorded')),
    -- the golden tests of the class and its descendants at the release, taken by the database
    -- (golden_tests_of); NULL before migration 0026
    golden_tests jsonb CHECK (golden_tests IS NULL OR jsonb_typeof(golden_tests) = 'array'),
    FOREIGN KEY (gear_class, version, hash) REFERENCES template_version_rows (gear_class, version, hash)
        ON DELETE CASCADE,
    UNIQUE (gear_class, version)
);
CREATE INDEX template_release_class ON template_release (gear_class, id);
-- Never changed; deleted only with its class (a cascade, run by a trigger).
CREATE TRIGGER template_release_is_a_record BEFORE UPDATE OR DELETE ON template_release
FOR EACH ROW WHEN (pg_trigger_depth() < 1) EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER template_release_is_not_truncated BEFORE TRUNCATE ON template_release
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- The version runners get: the class's latest release (NULL if it was never released).
CREATE FUNCTION released_version(class_name text) RETURNS integer
LANGUAGE sql STABLE
RETURN (SELECT r.version FROM template_release r WHERE r.gear_class = class_name ORDER BY r.id DESC LIMIT 1);

-- Every stored version with its state: released (the latest release), retired (released before
-- it), draft (the class's current version, not released), superseded (an earlier draft).
CREATE VIEW template_version_state AS
SELECT v.gear_class, v.version, v.hash, v.created_at, v.created_by,
       CASE WHEN r.version IS NOT NULL AND v.version = released_version(v.gear_class) THEN 'released'
            WHEN r.version IS NOT NULL THEN 'retired'
            WHEN v.version = g.template_version THEN 'draft'
            ELSE 'superseded' END AS state,
       r.released_at, r.released_by, r.role AS released_role
FROM template_version_rows v
JOIN gear_class g ON g.name = v.gear_class
LEFT JOIN template_release r ON r.gear_class = v.gear_class AND r.version = v.version;

-- The rows runners get, one per template row, like template_view (read only).
CREATE VIEW released_template_view AS
SELECT v.gear_class, v.version, x.id, x.t, x.n, x.p_calc, x.s, x.o, x.p_emit
FROM template_release r
JOIN template_version_rows v ON v.gear_class = r.gear_class AND v.version = r.version
CROSS JOIN LATERAL jsonb_to_recordset(v.rows) AS x (id integer, t text, n integer, p_calc text, s text, o text,
                                                     p_emit text)
WHERE r.version = released_version(r.gear_class);

-- Release the class's current version (its draft): the gate's findings, as the caller states them,
-- are recorded with it. `expected_hash` is the hash of the rows the gate checked: if the draft
-- changed since, nothing is released. `via` is how the caller says it releases ('engine' after
-- the engine's gate, 'seed' for the shipped templates; 'sql', the default, by hand): a claim of
-- the releasing login, kept as such. The golden tests of the class and its descendants are taken
-- by the database itself (from template_test, each with its class's version now), so a screen can
-- re-run exactly what the gate ran. Returns the release's id.
CREATE FUNCTION release_template(class_name text, expected_version integer, expected_hash text,
                                 tests jsonb DEFAULT '[]', impact jsonb DEFAULT '{}', checks jsonb DEFAULT '{}',
                                 note text DEFAULT NULL, via text DEFAULT 'sql')
RETURNS bigint
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    current integer;
    stored text;
    made bigint;
BEGIN
    SELECT g.template_version INTO current FROM gear_class g WHERE g.name = class_name FOR UPDATE;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'gear class % does not exist; see engine template list', quote_nullable(class_name)
            USING ERRCODE = 'foreign_key_violation';
    END IF;
    IF current IS DISTINCT FROM expected_version THEN
        RAISE EXCEPTION 'class %: its draft is version % now, not the version % that was checked; nothing released, '
                        'run the release again', class_name, current, expected_version
            USING ERRCODE = 'serialization_failure';
    END IF;
    SELECT v.hash INTO stored FROM template_version_rows v WHERE v.gear_class = class_name AND v.version = current;
    IF NOT FOUND THEN
        PERFORM store_current_version(class_name);
        SELECT v.hash INTO stored FROM template_version_rows v WHERE v.gear_class = class_name AND v.version = current;
    END IF;
    IF stored IS DISTINCT FROM expected_hash THEN
        RAISE EXCEPTION 'class % version %: its rows have hash %, not the % that was checked; nothing released',
                        class_name, current, stored, expected_hash
            USING ERRCODE = 'serialization_failure';
    END IF;
    IF EXISTS (SELECT 1 FROM template_release r WHERE r.gear_class = class_name AND r.version = current) THEN
        RAISE EXCEPTION 'class % version % is released already; there is no draft to release', class_name, current
            USING ERRCODE = 'unique_violation';
    END IF;
    INSERT INTO template_release (gear_class, version, hash, role, tests, impact, checks, note, released_via,
                                  golden_tests)
    VALUES (class_name, current, stored, template_editor(), coalesce(tests, '[]'), coalesce(impact, '{}'),
            coalesce(checks, '{}'), note, coalesce(via, 'sql'), golden_tests_of(class_name))
    RETURNING id INTO made;
    UPDATE template_version_rows v SET released = true
    WHERE v.gear_class = class_name AND v.version = current AND NOT v.released;
    RETURN made;
END
$$;

-- A program of a draft is made by an editor only (an editor's try, marked draft); a program of
-- a retired version is refused; a hobbing program is never unverified (the simulation proves it
-- against its gear and hob). Its lineage line (row id -1) must be the one line the database
-- computes from the record (program_lineage), so a program is never marked one way and written
-- the other. Fires after check_program and check_program_lines (trigger names in order).
CREATE FUNCTION check_program_release() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
DECLARE
    released integer := released_version(NEW.gear_class);
    words text;
    lineage_lines text[];
BEGIN
    NEW.draft := NOT EXISTS (SELECT 1 FROM template_release r
                             WHERE r.gear_class = NEW.gear_class AND r.version = NEW.template_version);
    IF NEW.draft AND NOT pg_has_role(template_editor(), 'engine_editor', 'MEMBER') THEN
        RAISE EXCEPTION 'program % for job %: class % version % is a draft (released: %); only an editor '
                        '(engine_editor) tries a draft, runners make programs from the released version',
                        NEW.name, NEW.job_id, NEW.gear_class, NEW.template_version, coalesce(released::text, 'none')
            USING ERRCODE = 'insufficient_privilege', COLUMN = 'template_version';
    END IF;
    IF NOT NEW.draft AND NEW.template_version IS DISTINCT FROM released THEN
        RAISE EXCEPTION 'program % for job %: class % version % was retired by the release of version %; make '
                        'the program again', NEW.name, NEW.job_id, NEW.gear_class, NEW.template_version, released
            USING ERRCODE = 'check_violation', COLUMN = 'template_version';
    END IF;
    IF NEW.unverified AND EXISTS (SELECT 1 FROM job j JOIN machine m ON m.name = j.machine
                                  WHERE j.id = NEW.job_id AND m.kind = 'hobber') THEN
        RAISE EXCEPTION 'program % for job %: a hobbing program is proved by the simulation against its gear and '
                        'hob; it is never stored unverified', NEW.name, NEW.job_id
            USING ERRCODE = 'check_violation', COLUMN = 'unverified';
    END IF;
    SELECT job_input_hash(j.params, j.module_params) INTO NEW.input_hash FROM job j WHERE j.id = NEW.job_id;
    words := program_lineage(NEW.id, NEW.gear_class, NEW.template_version, NEW.template_hash, NEW.input_hash,
                             NEW.draft, NEW.unverified);
    lineage_lines := ARRAY(SELECT l.text FROM unnest(NEW.lines, NEW.row_ids) AS l (text, row_id) WHERE l.row_id = -1);
    IF lineage_lines IS DISTINCT FROM ARRAY['; ' || words] AND lineage_lines IS DISTINCT FROM ARRAY['(' || words || ')']
    THEN
        RAISE EXCEPTION 'program % for job %: its lineage line (row id -1) must be the one line "; %" (or "(%)"), '
                        'found %; make programs with the engine', NEW.name, NEW.job_id, words, words,
                        coalesce(array_to_string(lineage_lines, ' | '), 'none')
            USING ERRCODE = 'check_violation', COLUMN = 'lines';
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER check_program_release BEFORE INSERT ON program
FOR EACH ROW EXECUTE FUNCTION check_program_release();

-- A golden test of a class's template (engine test): the workpiece (a gear, or the job's
-- parameters as JSON), the job choices (engine instantiate's, as JSON), and what the program must
-- show: `expect`, one expectation per element (exact lines, patterns, numeric properties with a
-- tolerance; the language is engine.templates.golden's).
CREATE TABLE template_test (
    id          bigserial PRIMARY KEY,
    gear_class  text NOT NULL REFERENCES gear_class (name) ON DELETE CASCADE,
    name        text NOT NULL CHECK (name ~ '^[A-Za-z0-9][A-Za-z0-9_.-]{0,79}$'),
    gear_id     integer REFERENCES gear (id),
    params      jsonb CHECK (params IS NULL OR jsonb_typeof(params) = 'object'),
    choices     jsonb NOT NULL DEFAULT '{}' CHECK (jsonb_typeof(choices) = 'object'),
    expect      text[] NOT NULL CHECK (cardinality(expect) > 0),
    description text NOT NULL DEFAULT '',
    created_at  timestamptz NOT NULL DEFAULT now(),
    created_by  text NOT NULL DEFAULT session_user,
    UNIQUE (gear_class, name),
    CHECK ((gear_id IS NULL) <> (params IS NULL))
);

-- The golden tests of a class and its descendants as stored now, each with its class's current
-- version: what the gate ran, recorded with a release by the database (not by its caller).
CREATE FUNCTION golden_tests_of(class_name text) RETURNS jsonb
LANGUAGE sql STABLE
RETURN (SELECT coalesce(jsonb_agg(jsonb_build_object('id', t.id, 'class', t.gear_class, 'name', t.name,
                                                     'gear_id', t.gear_id, 'params', t.params, 'choices', t.choices,
                                                     'expect', to_jsonb(t.expect), 'description', t.description,
                                                     'version', g.template_version)
                                  ORDER BY t.gear_class, t.name), '[]')
        FROM classes_and_below(ARRAY[class_name]) b
        JOIN gear_class g ON g.name = b.name
        JOIN template_test t ON t.gear_class = g.name);

-- ==============================================================================================
-- plants
-- ==============================================================================================

-- Section plants: several plants, one template authority (issue 33, after section release;
-- docs/design.md §12). The head office publishes the released versions and the records they run
-- on; a plant subscribes to them and publishes its history back. Every trigger here is an ordinary
-- one (ENABLE, origin only): it checks what is written in this database and never fires for a row
-- the replication applies (session_replication_role = replica), so a program a plant made is
-- taken at the head office as the plant proved it, whatever the head office has released since.

-- plant_identity: which plant this database is (one row, written by `engine plant subscribe`);
-- no row: the head office, or a shop of one database (plant 0).
CREATE TABLE plant_identity (
    one        boolean PRIMARY KEY DEFAULT true CHECK (one),
    number     integer NOT NULL CHECK (number BETWEEN 1 AND 9999),
    set_at     timestamptz NOT NULL DEFAULT now(),
    set_by     text NOT NULL DEFAULT session_user
);

-- This database's plant number: 0 at the head office.
CREATE FUNCTION plant_number() RETURNS integer
LANGUAGE sql STABLE
RETURN coalesce((SELECT p.number FROM plant_identity p), 0);

-- The ids a plant makes: [number * 10^10, (number + 1) * 10^10), the head office's from 1.
CREATE FUNCTION plant_first_id(number integer) RETURNS bigint
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN greatest(number::bigint * 10000000000, 1);

CREATE FUNCTION plant_last_id(number integer) RETURNS bigint
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN (number::bigint + 1) * 10000000000 - 1;

-- check_plant_id: a row made here has an id of this plant's range.
CREATE FUNCTION check_plant_id() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
DECLARE
    here integer := plant_number();
BEGIN
    IF NEW.id NOT BETWEEN plant_first_id(here) AND plant_last_id(here) THEN
        RAISE EXCEPTION '% %: plant % makes ids % to % only, so no two plants make one id; its sequence %_id_seq '
                        'was moved, run engine plant status', TG_TABLE_NAME, NEW.id, here, plant_first_id(here),
                        plant_last_id(here), TG_TABLE_NAME
            USING ERRCODE = 'check_violation', COLUMN = 'id', TABLE = TG_TABLE_NAME, CONSTRAINT = 'a_plant_id';
    END IF;
    RETURN NEW;
END
$$;

CREATE TRIGGER a_plant_id BEFORE INSERT ON job FOR EACH ROW EXECUTE FUNCTION check_plant_id();
CREATE TRIGGER a_plant_id BEFORE INSERT ON program FOR EACH ROW EXECUTE FUNCTION check_plant_id();
CREATE TRIGGER a_plant_id BEFORE INSERT ON program_request FOR EACH ROW EXECUTE FUNCTION check_plant_id();
CREATE TRIGGER a_plant_id BEFORE INSERT ON drawing FOR EACH ROW EXECUTE FUNCTION check_plant_id();

-- refuse_at_a_plant: the head office's tables are read-only at a plant.
CREATE FUNCTION refuse_at_a_plant() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
BEGIN
    IF plant_number() > 0 THEN
        RAISE EXCEPTION 'this database is plant %: % is the head office''s (templates are edited, released and '
                        'kept there, and replicated here); make the change at the head office', plant_number(),
                        TG_TABLE_NAME
            USING ERRCODE = 'read_only_sql_transaction', CONSTRAINT = 'head_office_writes_it';
    END IF;
    RETURN NULL;
END
$$;

CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON gear_class
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON component
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON assembly
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON template_version_rows
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON template_release
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON template_test
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON machine
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON hob
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();
CREATE TRIGGER head_office_writes_it BEFORE INSERT OR UPDATE OR DELETE OR TRUNCATE ON work_holding
FOR EACH STATEMENT EXECUTE FUNCTION refuse_at_a_plant();

-- replace_kept_row: at a plant, a row the head office made again replaces the one kept. Deletions
-- are not published (a plant's history refers to what it ran), so a hob, machine, work-holding,
-- golden test or unreleased class deleted at the head office stays at the plant; the head office's
-- new row of the same key (`engine hobs delete`, then `engine hobs add` of that id) then broke a
-- unique index there and stopped the plant's subscription, and with it every later release.
-- Enabled for replica only: it runs for the rows the replication applies, never for a person's write.
CREATE FUNCTION replace_kept_row() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
BEGIN
    CASE TG_TABLE_NAME
        WHEN 'hob' THEN DELETE FROM hob WHERE upper(id) = upper(NEW.id);
        WHEN 'work_holding' THEN DELETE FROM work_holding WHERE upper(id) = upper(NEW.id);
        WHEN 'machine' THEN DELETE FROM machine WHERE name = NEW.name;
        WHEN 'gear_class' THEN DELETE FROM gear_class WHERE name = NEW.name;
        WHEN 'template_test' THEN
            DELETE FROM template_test WHERE id = NEW.id OR (gear_class, name) = (NEW.gear_class, NEW.name);
    END CASE;
    RETURN NEW;
END
$$;

CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON hob FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON work_holding
FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON machine
FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON template_test
FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
ALTER TABLE hob ENABLE REPLICA TRIGGER made_again_at_the_head_office;
ALTER TABLE work_holding ENABLE REPLICA TRIGGER made_again_at_the_head_office;
ALTER TABLE machine ENABLE REPLICA TRIGGER made_again_at_the_head_office;
ALTER TABLE template_test ENABLE REPLICA TRIGGER made_again_at_the_head_office;

-- A class the head office made again under a deleted one's name (never released: see below).
CREATE TRIGGER made_again_at_the_head_office BEFORE INSERT ON gear_class
FOR EACH ROW EXECUTE FUNCTION replace_kept_row();
ALTER TABLE gear_class ENABLE REPLICA TRIGGER made_again_at_the_head_office;

-- refuse_deleting_a_released_class: at a head office (it publishes engine_templates), a class with a
-- release is not deleted. Its plants keep it and its released versions (deletions are not sent, a
-- plant's programs refer to them); a class made again under its name restarts at version 1, whose
-- release collided with the version 1 a plant kept and stopped that plant's subscription for good.
CREATE FUNCTION refuse_deleting_a_released_class() RETURNS trigger
LANGUAGE plpgsql SET search_path = public, pg_temp
AS $$
BEGIN
    IF EXISTS (SELECT 1 FROM template_release r WHERE r.gear_class = OLD.name)
       AND EXISTS (SELECT 1 FROM pg_publication p WHERE p.pubname = 'engine_templates') THEN
        RAISE EXCEPTION 'class %: its released versions are kept at every plant, so a head office keeps the class; '
                        'make a class of another name instead', OLD.name
            USING ERRCODE = 'dependent_objects_still_exist';
    END IF;
    RETURN OLD;
END
$$;

CREATE TRIGGER released_classes_are_kept BEFORE DELETE ON gear_class
FOR EACH ROW EXECUTE FUNCTION refuse_deleting_a_released_class();

-- ==============================================================================================
-- roles
-- ==============================================================================================

-- Section roles: who may do what (loaded last: it grants on the objects of every other section).
-- Five NOLOGIN groups, granted to login roles: engine_reader reads; engine_runner makes jobs,
-- programs and cases; engine_editor changes templates; engine_releaser releases them;
-- engine_planner keeps the shop's data (gears, units, hobs, cases, work-holdings, machines,
-- materials). Writes of templates and programs go through the engine's functions and views
-- (SECURITY DEFINER: checked, versioned, audited), not the tables; the library's records the
-- planner writes directly; the owner (the role running `engine db migrate`) is the only other
-- writer.

-- Roles belong to the cluster, not to this database: create them once, whichever database
-- migrates first, even concurrently.
DO $$
DECLARE
    role_name text;
BEGIN
    FOREACH role_name IN ARRAY ARRAY['engine_reader', 'engine_runner', 'engine_editor', 'engine_releaser',
                                         'engine_planner'] LOOP
        IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = role_name) THEN
            BEGIN
                EXECUTE format('CREATE ROLE %I NOLOGIN', role_name);
            EXCEPTION WHEN duplicate_object OR unique_violation THEN
                NULL;   -- created meanwhile by a migration of another database
            END;
        END IF;
    END LOOP;
END
$$;

-- Everybody reads every table and view, also those a later migration adds (default privileges
-- of the role running the migrations), except the per-transaction change markers, which only
-- engine_releaser may read (it was granted every table after they were made; nothing to hide).
-- Sequences are no tables to default privileges: the first ones are readable, later ones only by
-- whoever draws ids from them.
GRANT USAGE ON SCHEMA public TO engine_reader, engine_runner, engine_editor;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO engine_reader, engine_runner, engine_editor;
GRANT SELECT ON SEQUENCE component_id_seq, cutting_case_id_seq, job_id_seq, program_id_seq, template_audit_id_seq
    TO engine_reader, engine_runner, engine_editor, engine_releaser;
ALTER DEFAULT PRIVILEGES IN SCHEMA public GRANT SELECT ON TABLES TO engine_reader, engine_runner, engine_editor;
-- Functions that write run only inside the engine's own functions, or are granted below.
REVOKE EXECUTE ON FUNCTION audit_class_change(text, jsonb, integer[]), bump_template_versions(text),
    component_for(text, text, text, text, text), delete_component_if_unused(bigint), note_template_change(text[]),
    store_current_version(text), replace_class_template(text, jsonb),
    store_program(bigint, text, integer, text, text, text[], integer[], jsonb), confirm_job_cases(bigint)
    FROM PUBLIC;
-- template_change and template_check_due are written by the versioning functions only.
REVOKE ALL ON template_change, template_check_due FROM engine_reader, engine_runner, engine_editor;
GRANT USAGE ON SCHEMA public TO engine_releaser;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO engine_releaser;
ALTER DEFAULT PRIVILEGES IN SCHEMA public GRANT SELECT ON TABLES TO engine_releaser;

-- Runners instantiate: jobs (and their parameters, edited to make a program again) and programs
-- through store_program / program_submission; confirming a job adds its cuts to the machining
-- history through confirm_job_cases. The nightly refactor (an unattended job, run as
-- engine_runner) writes the near-duplicate pairs it reported.
GRANT INSERT ON job TO engine_runner;
GRANT UPDATE (params, module_params, cutting) ON job TO engine_runner;
GRANT USAGE ON SEQUENCE job_id_seq, program_id_seq TO engine_runner;
GRANT EXECUTE ON FUNCTION store_program(bigint, text, integer, text, text, text[], integer[], jsonb),
    confirm_job_cases(bigint) TO engine_runner;
GRANT INSERT ON program_submission TO engine_runner;
-- Runners (and `engine serve`, which connects as one) record what each machine asked for and was sent.
GRANT INSERT ON program_request TO engine_runner;
GRANT USAGE ON SEQUENCE program_request_id_seq TO engine_runner;
-- Runners import drawings (engine import-dxf): they insert drawing records, never change them.
GRANT INSERT ON drawing TO engine_runner;
GRANT USAGE ON SEQUENCE drawing_id_seq TO engine_runner;
GRANT INSERT, UPDATE (last_seen) ON near_duplicate_seen TO engine_runner;

-- Editors change templates through template_view (audited, versioned) and the engine's imports
-- (replace_class_template); they create, describe and re-parent classes (re-parenting is
-- versioned and audited), set an imported class's import_params and line layout, write golden
-- tests, and mark near-duplicate pairs intended (and withdraw marks). Not the library tables,
-- programs, jobs, cases or the audit trail.
GRANT INSERT, UPDATE, DELETE ON template_view TO engine_editor;
GRANT INSERT (name, parent, description), UPDATE (parent, description, import_params) ON gear_class TO engine_editor;
GRANT UPDATE (line_ending, final_newline) ON gear_class TO engine_editor;
GRANT EXECUTE ON FUNCTION replace_class_template(text, jsonb) TO engine_editor;
GRANT INSERT, UPDATE, DELETE ON template_test TO engine_editor;
GRANT USAGE ON SEQUENCE template_test_id_seq TO engine_editor;
GRANT INSERT (pair_key, t, a, b, why), UPDATE (withdrawn_at) ON near_duplicate_intended TO engine_editor;
GRANT USAGE ON SEQUENCE near_duplicate_intended_id_seq TO engine_editor;

-- Releasers release: release_template records the gate's findings, as its caller states them, with
-- the release (and how the caller says it released; screens re-check it, docs/design.md §10).
REVOKE EXECUTE ON FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text, text) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION release_template(text, integer, text, jsonb, jsonb, jsonb, text, text) TO engine_releaser;

-- Planners keep the shop's data (issue 31, docs/design.md §10): they read what the other roles
-- read, add and replace the library's records (the engine's imports, or by hand) and delete gears
-- and hobs no job was made from (job's foreign keys refuse the others). In the machining history
-- they add and replace a case's values, never which job it came from nor when (the database's own
-- record). No template, release, program, job or audit row.
GRANT USAGE ON SCHEMA public TO engine_planner;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO engine_planner;
REVOKE ALL ON template_change, template_check_due FROM engine_planner;
GRANT SELECT ON SEQUENCE component_id_seq, cutting_case_id_seq, job_id_seq, program_id_seq, template_audit_id_seq
    TO engine_planner;
ALTER DEFAULT PRIVILEGES IN SCHEMA public GRANT SELECT ON TABLES TO engine_planner;
GRANT INSERT, UPDATE, DELETE ON gear, gear_unit, hob TO engine_planner;
GRANT INSERT, UPDATE ON work_holding, machine, material TO engine_planner;
GRANT INSERT (id, module, teeth, material, hardness, quality_grade, hob_material, hob_coating, hob_starts,
              hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed, source),
      UPDATE (module, teeth, material, hardness, quality_grade, hob_material, hob_coating, hob_starts,
              hob_tip_diameter, cut, hob_speed, axial_feed, radial_feed, source)
    ON cutting_case TO engine_planner;
GRANT USAGE, UPDATE ON SEQUENCE cutting_case_id_seq TO engine_planner;
