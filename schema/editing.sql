-- schema/editing.sql: how a template changes (after versions.sql). Editing templates in SQL
-- (design notes §10) through template_view's INSTEAD OF trigger, the engine's imports
-- (replace_class_template) and re-parenting a class: each change bumps the versions
-- (bump_template_versions, versions.sql) and writes the audit trail, whoever makes it.
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
