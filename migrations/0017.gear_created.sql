-- When a gear was stored (issue 16: `engine gears list --since/--until`): set by the database
-- on insert; an import that updates a gear keeps the first date. NULL for gears stored before
-- this migration (their date is unknown, and no date is invented for them).
ALTER TABLE gear ADD COLUMN created_at timestamptz;
ALTER TABLE gear ALTER COLUMN created_at SET DEFAULT now();
