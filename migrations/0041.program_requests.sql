-- Issue 32: `engine serve` delivers programs to the controls (FTP, a request folder); every request
-- is recorded, sent or refused, as a record nobody changes.

CREATE OR REPLACE FUNCTION refuse_changing_a_record() RETURNS trigger
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

GRANT INSERT ON program_request TO engine_runner;
GRANT USAGE ON SEQUENCE program_request_id_seq TO engine_runner;
