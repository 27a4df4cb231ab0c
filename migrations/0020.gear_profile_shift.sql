-- Issue 16: a gear's profile shift x (in modules), as the drawing gives it. The gear import checks the
-- tip and root diameters of cylindrical gears against d = m_n·z/cos β, d_a = d + 2·m_n·(1 + x) and
-- d_f = d − 2·m_n·(1.25 − x); NULL = not given (the diameters must then fit some plausible x).
ALTER TABLE gear ADD COLUMN profile_shift numeric CONSTRAINT gear_profile_shift CHECK (profile_shift > -2 AND profile_shift < 2);
