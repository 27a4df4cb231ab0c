
-- How an imported NC file ended its lines (issue 17): LF or CRLF, and whether its last line
-- ended with one. The rows hold the lines without them, so `M17` of a CRLF file and of an LF
-- file is one component; writing the class's program back uses these to give the file byte for byte.
ALTER TABLE gear_class ADD COLUMN line_ending text NOT NULL DEFAULT E'\n'
    CHECK (line_ending IN (E'\n', E'\r\n'));
ALTER TABLE gear_class ADD COLUMN final_newline boolean NOT NULL DEFAULT true;
-- Editors import NC programs (engine import-nc): they set the layout with the rows, as they set
-- import_params (migration 0010); nobody else writes it.
GRANT UPDATE (line_ending, final_newline) ON gear_class TO engine_editor;
