-- Every program explains itself (design notes §4): per row of its template version, whether
-- `s` ran or `p_calc` skipped the row, whether `o` was emitted or `p_emit` suppressed it, the
-- value of each condition, the values computed, and the inputs each expression read with
-- where each value came from (the job, a module's parameters, the row that computed it).
-- One JSON object per program: the input values by origin, and one entry per row in id order
-- (engine/templates/trace.py).
-- Programs stored before this migration have none (NULL).
ALTER TABLE program ADD COLUMN trace jsonb;

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

GRANT SELECT ON program_trace, program_input TO engine_reader, engine_runner, engine_editor;
