-- Every term of the energy balance on its own (issue 11): the elastic energy, the work of each
-- plate, the energy the contact projection dissipated (nodes caught by a plate) and the
-- residual (the balance's numerical error). Rows stored before this migration read 0.
ALTER TABLE history ADD COLUMN elastic_mj     REAL NOT NULL DEFAULT 0;
ALTER TABLE history ADD COLUMN work_top_mj    REAL NOT NULL DEFAULT 0;
ALTER TABLE history ADD COLUMN work_bottom_mj REAL NOT NULL DEFAULT 0;
ALTER TABLE history ADD COLUMN contact_mj     REAL NOT NULL DEFAULT 0;
ALTER TABLE history ADD COLUMN residual_mj    REAL NOT NULL DEFAULT 0;
