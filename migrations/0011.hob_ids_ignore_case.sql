-- Hob ids that differ only in case name one hob (issue 13 review): `engine hobs import` kept
-- h-m2-aa-r1 beside H-M2-AA-R1, and a job or a program's `; HOB …` comment could then name
-- either, while an operator reading the program (or a control, which does not tell case)
-- cannot. One id per hob, whatever its case; engine/gears/hob_library.py says which id is
-- there already before the database refuses it.

-- Rows written before it: the migration stops and names them, so that one of each pair is
-- renamed (or deleted) rather than silently kept.
DO $$
DECLARE
    twins text;
BEGIN
    SELECT string_agg(found.ids, '; ') INTO twins
    FROM (SELECT string_agg(to_json(id)::text, ' and ' ORDER BY id) AS ids
          FROM hob GROUP BY upper(id) HAVING count(*) > 1 LIMIT 20) AS found;
    IF twins IS NOT NULL THEN
        RAISE EXCEPTION 'hob ids that differ only in case: %; rename or delete one of each (UPDATE job SET '
                        'hob_id = … WHERE hob_id = …; DELETE FROM hob WHERE id = …) and migrate again', twins;
    END IF;
END
$$;

CREATE UNIQUE INDEX hob_id_ignoring_case ON hob (upper(id));
