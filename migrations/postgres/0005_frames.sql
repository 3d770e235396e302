-- See migrations/sqlite/0008_frames.sql.
CREATE TABLE frames (
    job_id    TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    k         BIGINT NOT NULL,
    part      BIGINT NOT NULL,
    travel_mm DOUBLE PRECISION NOT NULL,
    time_ms   DOUBLE PRECISION NOT NULL,
    particles BIGINT NOT NULL,
    data      BYTEA NOT NULL,
    PRIMARY KEY (job_id, k, part)
);
