-- Programs are records, and a template changes only with a version and an audit (issue 13,
-- design notes §10).
--
-- * A program is written only by the engine's own path: store_program (one) and the view
--   program_submission (a batch, through COPY), SECURITY DEFINER both. Before it is stored the
--   database checks what it can: the job exists and is of the program's class, the template
--   version and hash are a stored version of that class (the hash computed here, as
--   engine.templates.rows.rows_hash computes it), every line's row is a row of that version,
--   no line holds a control character. It records who stored it (the login person and the
--   role) and when. No role, the owner included, updates or deletes a program.
-- * The version and hash a program records always equal the rows it was made from: every
--   change of component, assembly or gear_class notes the classes it touches (and those below
--   them), and at commit each touched class's assembled rows must equal the rows stored for its
--   version, or a new version is stored; anything else is refused. Edits through the view bump
--   a class's version once per transaction (each engine import makes a version of its own); what
--   was bumped is marked in a table only the engine's functions write (no user-settable setting).
-- * Editors change templates through template_view, re-parenting (versioned and audited here)
--   and replace_class_template (engine template import, restore, import-nc); they lose direct
--   writes to component, assembly and gear_class.template_version.
-- * template_audit names the login person (session_user) and the role, stamped by a trigger:
--   nobody writes who or when by hand, and no role changes or deletes an audit row.
-- * The machining history: runners add cases only through confirm_job_cases (a job the engine
--   made a program for, values within the machine's limits); every case is physically plausible.

-- --- who ------------------------------------------------------------------------------------

-- The login person behind a change: session_user, which neither SET ROLE nor a SECURITY
-- DEFINER function changes. The role: template_editor() (migration 0005).
ALTER TABLE template_audit ADD COLUMN login text;   -- NULL: written before this migration

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

-- Records are appended, never changed: programs, the audit trail, stored template versions.
CREATE FUNCTION refuse_changing_a_record() RETURNS trigger
LANGUAGE plpgsql
AS $$
BEGIN
    RAISE EXCEPTION '% of %: its rows are records, never changed or deleted (%)', TG_OP, TG_TABLE_NAME,
                    CASE TG_TABLE_NAME
                        WHEN 'program' THEN 'make a new program with engine instantiate'
                        WHEN 'template_audit' THEN 'the audit trail is append-only'
                        ELSE 'a new version is stored when a template changes' END
        USING ERRCODE = 'insufficient_privilege';
END
$$;

CREATE TRIGGER template_audit_is_a_record BEFORE UPDATE OR DELETE ON template_audit
FOR EACH ROW EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER template_audit_is_not_truncated BEFORE TRUNCATE ON template_audit
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- --- template hashes --------------------------------------------------------------------------

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

-- Computed from the rows, so a stored version's hash cannot say anything else.
ALTER TABLE template_version_rows
    ADD COLUMN hash text GENERATED ALWAYS AS (template_rows_hash(rows)) STORED,
    ADD COLUMN row_ids integer[] GENERATED ALWAYS AS (template_row_ids(rows)) STORED,
    ADD CONSTRAINT template_version_rows_hash UNIQUE (gear_class, version, hash);

-- Never changed; deleted only with its class (a cascade, run by a trigger).
CREATE TRIGGER template_version_rows_is_a_record BEFORE UPDATE OR DELETE ON template_version_rows
FOR EACH ROW WHEN (pg_trigger_depth() < 1) EXECUTE FUNCTION refuse_changing_a_record();
CREATE TRIGGER template_version_rows_is_not_truncated BEFORE TRUNCATE ON template_version_rows
FOR EACH STATEMENT EXECUTE FUNCTION refuse_changing_a_record();

-- --- changes noted, versions bumped, checked at commit ------------------------------------------

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
REVOKE ALL ON template_change, template_check_due FROM engine_reader, engine_runner, engine_editor;

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
CREATE OR REPLACE FUNCTION bump_template_versions(class_name text) RETURNS integer
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
-- included): its current version and its assembled rows then.
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

-- The commit check stores versions now.
DROP TRIGGER store_template_version ON gear_class;
DROP FUNCTION store_template_version();

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

-- --- the engine's imports -----------------------------------------------------------------------

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
    PERFORM template_row_check(class_name, x.id, x.t, x.n, x.p_calc, x.s, x.o)
    FROM jsonb_to_recordset(own) AS x (id integer, t text, n integer, p_calc text, s text, o text);
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

-- --- programs -----------------------------------------------------------------------------------

-- Who stored each program: the login person and the role (NULL before this migration).
ALTER TABLE program ADD COLUMN stored_by text, ADD COLUMN stored_role text;

-- The version and hash a program records are a stored version of its class (checked for every
-- program stored from now on; programs stored before may name versions never stored).
ALTER TABLE program ADD CONSTRAINT program_template_version
    FOREIGN KEY (gear_class, template_version, template_hash)
    REFERENCES template_version_rows (gear_class, version, hash) NOT VALID;

-- What the database can check of a program before it is stored, and who stored it when.
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
    IF NOT NEW.row_ids <@ stored.row_ids THEN
        RAISE EXCEPTION 'program % for job %: row ids % are not rows of class % version %', NEW.name, NEW.job_id,
                        ARRAY(SELECT DISTINCT r FROM unnest(NEW.row_ids) r WHERE r <> ALL (stored.row_ids) ORDER BY r),
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
-- each row is checked and stored as store_program stores one.
CREATE VIEW program_submission AS
SELECT id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace FROM program
WHERE false;

CREATE FUNCTION submit_program() RETURNS trigger
LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp
AS $$
BEGIN
    INSERT INTO program (id, job_id, gear_class, template_version, template_hash, name, lines, row_ids, trace)
    VALUES (coalesce(NEW.id, nextval('program_id_seq')), NEW.job_id, NEW.gear_class, NEW.template_version,
            NEW.template_hash, NEW.name, NEW.lines, NEW.row_ids, NEW.trace)
    RETURNING id INTO NEW.id;
    RETURN NEW;
END
$$;

CREATE TRIGGER submit_program INSTEAD OF INSERT ON program_submission
FOR EACH ROW EXECUTE FUNCTION submit_program();

-- --- the machining history -------------------------------------------------------------------------

-- Physically plausible cases, whoever adds them: finite values (numeric takes NaN and infinity),
-- a cutting speed v = π·d_a0·n0/1000 of at most 600 m/min (twice the fastest of reference §C,
-- carbide dry), feeds per workpiece revolution f = v_f/(n0·z0/z2) of at most 10·m_n (2.5 to 10
-- times the typical ranges of §C; the paper's suspicious 8.1 mm at m 2 stays in). Cases stored
-- before this migration are not re-checked.
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
    IF ran IS DISTINCT FROM speed AND ran IS NOT NULL THEN
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

-- --- privileges -----------------------------------------------------------------------------------

-- Functions that write run only inside the engine's own functions, or are granted below.
REVOKE EXECUTE ON FUNCTION bump_template_versions(text), component_for(text, text, text, text, text),
    delete_component_if_unused(bigint), note_template_change(text[]), store_current_version(text),
    replace_class_template(text, jsonb), store_program(bigint, text, integer, text, text, text[], integer[], jsonb),
    confirm_job_cases(bigint)
    FROM PUBLIC;
REVOKE EXECUTE ON FUNCTION audit_class_change(text, jsonb, integer[]) FROM engine_editor;

-- Runners store programs only through store_program and program_submission, add cases only by
-- confirming a job, and edit a job's parameters (to make its program again), nothing else of it.
REVOKE INSERT, UPDATE ON program FROM engine_runner;
REVOKE INSERT ON cutting_case FROM engine_runner;
REVOKE USAGE ON SEQUENCE cutting_case_id_seq FROM engine_runner;
REVOKE UPDATE ON job FROM engine_runner;
GRANT UPDATE (params, module_params, cutting) ON job TO engine_runner;
GRANT EXECUTE ON FUNCTION store_program(bigint, text, integer, text, text, text[], integer[], jsonb),
    confirm_job_cases(bigint) TO engine_runner;
GRANT INSERT ON program_submission TO engine_runner;

-- Editors change templates through template_view and the engine's imports; they create,
-- describe and re-parent classes (re-parenting is versioned and audited), nothing else.
REVOKE INSERT, UPDATE, DELETE ON component, assembly FROM engine_editor;
REVOKE INSERT, UPDATE ON gear_class FROM engine_editor;
REVOKE USAGE ON SEQUENCE component_id_seq FROM engine_editor;
GRANT INSERT (name, parent, description), UPDATE (parent, description, import_params) ON gear_class TO engine_editor;
GRANT EXECUTE ON FUNCTION replace_class_template(text, jsonb) TO engine_editor;
