-- See migrations/sqlite/0005_checkpoints.sql.
CREATE TABLE checkpoints (
    job_id     TEXT PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    attempt    BIGINT NOT NULL,
    step       BIGINT NOT NULL,
    fraction   DOUBLE PRECISION NOT NULL,
    written_at BIGINT NOT NULL,
    data       BYTEA NOT NULL
);

ALTER TABLE jobs ADD COLUMN advanced BIGINT NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN checkpoint_attempt BIGINT;
ALTER TABLE jobs ADD COLUMN checkpoint_step BIGINT;
ALTER TABLE jobs ADD COLUMN checkpoint_fraction DOUBLE PRECISION;
ALTER TABLE jobs ADD COLUMN checkpoint_at BIGINT;
