-- Checkpoints of running jobs: the solver's whole state at a step boundary (its own binary
-- format, checked by a CRC-32), one row per job, replaced by each newer one and deleted when the
-- job ends. A requeued job resumes from it on any node.
CREATE TABLE checkpoints (
    job_id     TEXT PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    -- the claim that wrote it, the solver step and share of the crush it stands at
    attempt    INTEGER NOT NULL,
    step       INTEGER NOT NULL,
    fraction   REAL NOT NULL,
    written_at INTEGER NOT NULL,
    data       BLOB NOT NULL
);

-- Claims of the job that stored a checkpoint: they moved the job on, so they do not count
-- against --max-attempts; and the last claim that stored one.
ALTER TABLE jobs ADD COLUMN advanced INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN checkpoint_attempt INTEGER;
-- Where the job's checkpoint stands (NULL: none), for the job's view.
ALTER TABLE jobs ADD COLUMN checkpoint_step INTEGER;
ALTER TABLE jobs ADD COLUMN checkpoint_fraction REAL;
ALTER TABLE jobs ADD COLUMN checkpoint_at INTEGER;
