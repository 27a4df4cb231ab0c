-- Lineage and cases (issue 13 review, attacks on migration 0010).
--
-- * A class's lineage is at most 50 classes above it: every recursion over gear_class
--   (class_template, assembled_rows_of, classes_and_below, bump_template_versions) stops at depth
--   50, so a deeper class silently lost its far ancestors' rows and a re-parent past that depth
--   closed a cycle the check did not see. A class that would be deeper is refused, whether it is
--   created there or moved there.
-- * Two re-parents in parallel (ra under rb, rb under ra) each checked a snapshot without the
--   other and both committed a cycle. The check now walks the new parent's ancestors one by one,
--   each row locked FOR SHARE: a concurrent re-parent of any of them waits for this transaction
--   (or this one waits for it and then reads what it committed; under REPEATABLE READ it fails with
--   a serialization error), so two changes that together close a cycle never both commit.
-- * confirm_job_cases failed open when the job's last program recorded no hob speed (n0): the
--   case took job.cutting's speed, which no program ran. Now such a job is not a case.

-- Stop here if the classes already break the limit (or form a cycle): name them, to fix by hand.
DO $$
DECLARE
    too_deep text;
BEGIN
    WITH RECURSIVE lineage(name, ancestor, depth) AS (
        SELECT g.name, g.parent, 1 FROM gear_class g WHERE g.parent IS NOT NULL
        UNION ALL
        SELECT l.name, g.parent, l.depth + 1 FROM lineage l JOIN gear_class g ON g.name = l.ancestor
        WHERE g.parent IS NOT NULL AND l.depth <= 50)
    SELECT string_agg(DISTINCT quote_literal(name), ', ') INTO too_deep FROM lineage WHERE depth > 50;
    IF too_deep IS NOT NULL THEN
        RAISE EXCEPTION 'gear classes more than 50 levels deep or in a cycle: %; re-parent them (UPDATE gear_class '
                        'SET parent = ... WHERE name = ...) and migrate again', too_deep;
    END IF;
END
$$;

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

-- confirm_job_cases as in 0010, but a job whose last program records no n0 is refused.
CREATE OR REPLACE FUNCTION confirm_job_cases(confirmed_job bigint) RETURNS bigint[]
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
