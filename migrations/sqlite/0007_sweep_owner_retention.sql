-- The name of the token that submitted each sweep (its jobs carry it too), so that a submitter
-- may delete its own sweeps; sweeps stored before read their jobs' owner.
ALTER TABLE sweeps ADD COLUMN owner TEXT;
UPDATE sweeps SET owner = (SELECT owner FROM jobs WHERE jobs.sweep_id = sweeps.id LIMIT 1);
-- The sweep list pages newest first by (created_at, id); retention finds finished jobs by when
-- they finished.
CREATE INDEX sweeps_created ON sweeps (created_at, id);
CREATE INDEX jobs_finished ON jobs (finished_at) WHERE finished_at IS NOT NULL;
