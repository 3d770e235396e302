-- See migrations/sqlite/0007_sweep_owner_retention.sql.
ALTER TABLE sweeps ADD COLUMN owner TEXT;
UPDATE sweeps SET owner = (SELECT owner FROM jobs WHERE jobs.sweep_id = sweeps.id LIMIT 1);
CREATE INDEX sweeps_created ON sweeps (created_at, id);
CREATE INDEX jobs_finished ON jobs (finished_at) WHERE finished_at IS NOT NULL;
