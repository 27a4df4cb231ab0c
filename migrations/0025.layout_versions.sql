-- Issue 17: a class's line layout (line ending, final newline: migration 0023) is part of its
-- template, so it travels with the template's versions. A stored version records the layout the
-- class had when it was stored; runners get the released version's layout, an editor's change of
-- it is a new draft version until `engine template release` releases it; a stored program is
-- written with its version's layout, which never changes (template_version_rows is a record).
ALTER TABLE template_version_rows ADD COLUMN line_ending text NOT NULL DEFAULT E'\n'
    CHECK (line_ending IN (E'\n', E'\r\n'));
ALTER TABLE template_version_rows ADD COLUMN final_newline boolean NOT NULL DEFAULT true;

-- Before this migration every program of a class was written with the class's one layout, set
-- when its file was imported: the versions stored so far get it.
ALTER TABLE template_version_rows DISABLE TRIGGER template_version_rows_is_a_record;
UPDATE template_version_rows v SET line_ending = g.line_ending, final_newline = g.final_newline
FROM gear_class g WHERE g.name = v.gear_class AND (g.line_ending, g.final_newline) <> (E'\n', true);
ALTER TABLE template_version_rows ENABLE TRIGGER template_version_rows_is_a_record;

-- check_version_rows as in migration 0010, and the stored version takes the class's layout as it is.
CREATE OR REPLACE FUNCTION check_version_rows() RETURNS trigger
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
