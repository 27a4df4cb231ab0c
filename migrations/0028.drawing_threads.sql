-- Issue 26: a THREAD operation's pitch and drawn crest and root lines are the drawing's too. They
-- were read from job.module_params (cutmotion:n.thread_pitch and .paths), which a runner may edit in
-- SQL: a pitch of 2.0 on a drawn M20x1.5 passed with G32 ... F2.0, and a moved root line let a
-- thread be cut below its root diameter. drawing.threads holds them as the import put them in the
-- job: {"n": {"thread_pitch": p, "paths": [...]}} per THREAD operation n, {} for a drawing without
-- one, NULL when not recorded (the proof then reads the job's module_params, as before).
ALTER TABLE drawing ADD COLUMN threads jsonb CHECK (threads IS NULL OR jsonb_typeof(threads) = 'object');

-- Existing records, from the module_params of the job stored with them (the first job naming the
-- record, as import-dxf and migration 0027 made one record per job), as they are now: an edit made
-- before this migration is not known to be one. A record no job names stays NULL (not recorded).
-- The records are never changed (trigger drawing_is_a_record): this migration, the tables' owner,
-- fills the new column with the trigger off for the one statement.
ALTER TABLE drawing DISABLE TRIGGER drawing_is_a_record;
UPDATE drawing d
SET threads = coalesce((SELECT jsonb_object_agg(split_part(m.key, ':', 2),
                                                jsonb_build_object('thread_pitch', m.value->'thread_pitch',
                                                                   'paths', m.value->'paths'))
                        FROM jsonb_each(j.module_params) m
                        WHERE m.key LIKE 'cutmotion:%' AND jsonb_typeof(m.value) = 'object'
                          AND m.value->>'kind' = 'THREAD'), '{}')
FROM job j
WHERE j.id = (SELECT min(k.id) FROM job k WHERE k.drawing_id = d.id);
ALTER TABLE drawing ENABLE TRIGGER drawing_is_a_record;
