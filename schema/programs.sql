-- schema/programs.sql: programs, the records of what was made (after records.sql). One row per
-- instantiation: the emitted lines with the template row that emitted each, the template version
-- and hash it came from, who stored it. Stored only through store_program / program_submission,
-- checked on the way in (check_program, check_program_lines, and check_program_release in
-- release.sql: triggers fire in the order of their names), never changed or deleted. Every program
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
