-- Issue 33: a plant's refusal of a write to the head office's tables names itself (the constraint
-- head_office_writes_it), so the command line tells it in one line, exit 1, while any other
-- read-only refusal (a READ ONLY transaction, a standby) stays what it was: an unexpected write, exit 2
-- (tests/test_read_only_database.py: the suite's read-only copy catches a test that writes).

CREATE OR REPLACE FUNCTION refuse_at_a_plant() RETURNS trigger
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
