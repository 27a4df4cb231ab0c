-- Issue 16: a program carries one lineage line, the engine's (row id -1, migration 0015). A line a
-- template row wrote must never read as one: a program's printout imported as a template
-- (`engine import-nc`), or a dry run's `; PROGRAM DRY-RUN TEMPLATE …`, would otherwise give every
-- program of the class a second lineage naming another program and version, and the operator who
-- matches the file on the control to its record would find the wrong one. The engine refuses such
-- files and rows (engine.programs.lineage.LINEAGE_SHAPE is the same shape); the database refuses the
-- program, whatever wrote the rows (SQL editing through template_view included).
CREATE FUNCTION lineage_shaped(line text) RETURNS boolean
LANGUAGE sql IMMUTABLE PARALLEL SAFE
RETURN line ~* '^\s*[;(]\s*PROGRAM\s+\S+\s+TEMPLATE(\s|\)|$)';

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
