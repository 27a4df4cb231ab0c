-- schema/versions.sql: template versions (after templates.sql). The assembled template of every
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
    PRIMARY KEY (gear_class, version),
    CONSTRAINT template_version_rows_hash UNIQUE (gear_class, version, hash)
);

-- The class's assembled rows as template_version_rows stores them.
CREATE FUNCTION class_rows_array(class_name text)
RETURNS jsonb LANGUAGE sql STABLE
RETURN (SELECT coalesce(jsonb_agg(template_row_json(r.id, c.t, r.n, c.p_calc, c.s, c.o, c.p_emit) ORDER BY r.id),
                        '[]')
        FROM class_template(class_name) r JOIN component c ON c.id = r.component_id);

-- Never changed; deleted only with its class (a cascade, run by a trigger).
CREATE TRIGGER template_version_rows_is_a_record BEFORE UPDATE OR DELETE ON template_version_rows
FOR EACH ROW WHEN (pg_trigger_depth() < 1) EXECUTE FUNCTION refuse_changing_a_record();
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
