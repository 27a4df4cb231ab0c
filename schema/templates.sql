-- schema/templates.sql: the template library (after core.sql). Gear classes form a tree; a
-- class's template is its assembly of components (row bodies stored once), inherited down the
-- tree; template_view shows it as the paper's table. Also the library's companions: kept SQL
-- condition translations and the near-duplicate pairs of the nightly refactor.
-- Editing (editing.sql) and versions (versions.sql) build on these.

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
-- newline) is part of its template and versioned with it (version_layout_change, versions.sql).
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
-- (template_view_edit, editing.sql).
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
