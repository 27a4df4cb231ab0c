-- Issue 31: the workpiece materials were four names in the engine's code (45, C45, 20CrMnTi,
-- 40Cr); any other material (42CrMo4, 16MnCr5, …) silently took a cautious default cutting
-- speed. The materials are now data: each with its group, hardness range and the cutting speeds
-- of docs/reference/hobbing.md §C by hob material and coating, and the source of those numbers.
-- A gear whose material is not here is refused at instantiate (engine.gears.materials);
-- `engine materials import` adds one.
CREATE TABLE material (
    name             text PRIMARY KEY CHECK (name = btrim(name) AND name <> '' AND length(name) <= 40),
    material_group   text NOT NULL CHECK (btrim(material_group) <> ''),
    -- the hardness range the speeds are for, Brinell (HB), as delivered for hobbing
    hardness_min     numeric NOT NULL CHECK (hardness_min > 0 AND hardness_min < 'Infinity'),
    hardness_max     numeric NOT NULL CHECK (hardness_max < 'Infinity'),
    -- cutting speed v [m/min], lowest and highest, by the hob's §C column: uncoated HSS (wet),
    -- TiN/TiAlN coated (PM-)HSS, carbide (dry)
    uncoated_low     numeric NOT NULL CHECK (uncoated_low > 0),
    uncoated_high    numeric NOT NULL CHECK (uncoated_high < 'Infinity'),
    coated_low       numeric NOT NULL CHECK (coated_low > 0),
    coated_high      numeric NOT NULL CHECK (coated_high < 'Infinity'),
    carbide_low      numeric NOT NULL CHECK (carbide_low > 0),
    carbide_high     numeric NOT NULL CHECK (carbide_high < 'Infinity'),
    -- the speed a job with no machining history takes, uncoated and coated hob [m/min]
    default_uncoated numeric NOT NULL,
    default_coated   numeric NOT NULL,
    source           text NOT NULL CHECK (btrim(source) <> ''),
    CONSTRAINT material_hardness_range CHECK (hardness_min <= hardness_max),
    CONSTRAINT material_speed_ranges CHECK (uncoated_low <= uncoated_high AND coated_low <= coated_high
                                            AND carbide_low <= carbide_high),
    CONSTRAINT material_defaults_in_range CHECK (default_uncoated BETWEEN uncoated_low AND uncoated_high
                                                 AND default_coated BETWEEN coated_low AND coated_high)
);
-- One material per name whatever its case (the engine matches a gear's material ignoring case).
CREATE UNIQUE INDEX material_name_ignoring_case ON material (lower(name));

INSERT INTO material (name, material_group, hardness_min, hardness_max, uncoated_low, uncoated_high,
                      coated_low, coated_high, carbide_low, carbide_high, default_uncoated, default_coated, source)
VALUES
    ('45', 'carbon steel', 170, 220, 30, 45, 60, 120, 150, 300, 38, 90, 'hobbing.md §C'),
    ('C45', 'carbon steel', 170, 220, 30, 45, 60, 120, 150, 300, 38, 90, 'hobbing.md §C'),
    ('20CrMnTi', 'case-hardening steel', 160, 210, 30, 40, 60, 110, 150, 280, 35, 85, 'hobbing.md §C'),
    ('40Cr', 'alloy steel, quenched and tempered', 220, 280, 20, 35, 50, 90, 120, 220, 28, 70, 'hobbing.md §C'),
    ('42CrMo4', 'alloy steel, quenched and tempered', 250, 300, 20, 35, 50, 90, 120, 220, 28, 70,
     'hobbing.md §C2, judgement: the row of 40Cr'),
    ('34CrNiMo6', 'alloy steel, quenched and tempered', 260, 320, 18, 30, 45, 80, 100, 200, 24, 62,
     'hobbing.md §C2, judgement: below the row of 40Cr'),
    ('38CrMoAl', 'nitriding steel', 230, 290, 20, 35, 50, 90, 120, 220, 28, 70,
     'hobbing.md §C2, judgement: the row of 40Cr'),
    ('16MnCr5', 'case-hardening steel', 150, 200, 30, 40, 60, 110, 150, 280, 35, 85,
     'hobbing.md §C2, judgement: the row of 20CrMnTi'),
    ('20MnCr5', 'case-hardening steel', 160, 210, 30, 40, 60, 110, 150, 280, 35, 85,
     'hobbing.md §C2, judgement: the row of 20CrMnTi'),
    ('20CrMnMo', 'case-hardening steel', 180, 230, 25, 35, 55, 100, 140, 250, 30, 78,
     'hobbing.md §C2, judgement: below the row of 20CrMnTi'),
    ('18CrNiMo7-6', 'case-hardening steel', 170, 230, 25, 35, 55, 100, 140, 250, 30, 78,
     'hobbing.md §C2, judgement: below the row of 20CrMnTi'),
    ('17CrNiMo6', 'case-hardening steel', 170, 230, 25, 35, 55, 100, 140, 250, 30, 78,
     'hobbing.md §C2, judgement: the row of 18CrNiMo7-6 (its former name)'),
    ('EN-GJL-250', 'grey cast iron', 180, 250, 25, 40, 50, 90, 120, 250, 32, 70,
     'hobbing.md §C2, judgement from the group'),
    ('HT250', 'grey cast iron', 180, 250, 25, 40, 50, 90, 120, 250, 32, 70,
     'hobbing.md §C2, judgement: the row of EN-GJL-250'),
    ('EN-GJS-600-3', 'ductile cast iron', 190, 270, 20, 35, 45, 85, 110, 220, 28, 65,
     'hobbing.md §C2, judgement from the group'),
    ('QT600-3', 'ductile cast iron', 190, 270, 20, 35, 45, 85, 110, 220, 28, 65,
     'hobbing.md §C2, judgement: the row of EN-GJS-600-3'),
    ('CuSn12', 'tin bronze (worm wheels)', 80, 120, 40, 60, 60, 120, 150, 300, 50, 90,
     'hobbing.md §C2, judgement from the group'),
    ('ZCuSn10P1', 'tin bronze (worm wheels)', 80, 120, 40, 60, 60, 120, 150, 300, 50, 90,
     'hobbing.md §C2, judgement: the row of CuSn12');
