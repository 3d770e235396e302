-- The PostgreSQL schema: the same tables, columns and meanings as migrations/sqlite/0001–0004
-- (one file here, as there was no earlier PostgreSQL store to upgrade). Times are unix
-- milliseconds (UTC); ids are hyphenated UUIDs as text, as in SQLite, so that one set of
-- statements serves both backends. Types: INTEGER → BIGINT, REAL → DOUBLE PRECISION,
-- BLOB → BYTEA.

CREATE TABLE sweeps (
    id              TEXT PRIMARY KEY,
    created_at      BIGINT NOT NULL,
    label           TEXT,
    base_json       TEXT NOT NULL,
    -- [[field, [value, ...]], ...] in table-column order
    parameters_json TEXT NOT NULL
);

CREATE TABLE jobs (
    seq               BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    id                TEXT NOT NULL UNIQUE,
    status            TEXT NOT NULL
                      CHECK (status IN ('queued', 'running', 'succeeded', 'failed', 'cancelled')),
    label             TEXT,
    case_json         TEXT NOT NULL,
    particles         BIGINT NOT NULL,
    idempotency_key   TEXT UNIQUE,
    sweep_id          TEXT REFERENCES sweeps (id),
    sweep_index       BIGINT,
    sweep_values_json TEXT,
    created_at        BIGINT NOT NULL,
    started_at        BIGINT,
    finished_at       BIGINT,
    -- times a worker claimed the job
    attempts          BIGINT NOT NULL DEFAULT 0,
    -- times its worker died (stale heartbeat) while running it
    lost              BIGINT NOT NULL DEFAULT 0,
    -- the current claim; a worker may write results only while it holds it
    lease             TEXT,
    -- the node that holds the claim, or that held the last one
    worker            TEXT,
    heartbeat_at      BIGINT,
    cancel_requested  BIGINT NOT NULL DEFAULT 0,
    progress_json     TEXT,
    progress_fraction DOUBLE PRECISION,
    error             TEXT
);

CREATE INDEX jobs_status_seq ON jobs (status, seq);
CREATE INDEX jobs_label_seq ON jobs (label, seq);
CREATE INDEX jobs_sweep ON jobs (sweep_id, sweep_index);
-- The reaper's scan: running jobs by heartbeat.
CREATE INDEX jobs_running_heartbeat ON jobs (heartbeat_at) WHERE status = 'running';

CREATE TABLE summaries (
    job_id               TEXT PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    mean_load_n          DOUBLE PRECISION NOT NULL,
    peak_load_n          DOUBLE PRECISION NOT NULL,
    energy_absorbed_mj   DOUBLE PRECISION NOT NULL,
    crush_distance_mm    DOUBLE PRECISION NOT NULL,
    folds                BIGINT NOT NULL,
    mode                 TEXT NOT NULL,
    energy_balance_error DOUBLE PRECISION NOT NULL,
    particles            BIGINT NOT NULL,
    steps                BIGINT NOT NULL,
    wall_time_s          DOUBLE PRECISION NOT NULL,
    summary_json         TEXT NOT NULL
);

CREATE TABLE history (
    job_id          TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    row             BIGINT NOT NULL,
    time_ms         DOUBLE PRECISION NOT NULL,
    displacement_mm DOUBLE PRECISION NOT NULL,
    load_top_n      DOUBLE PRECISION NOT NULL,
    load_bottom_n   DOUBLE PRECISION NOT NULL,
    kinetic_mj      DOUBLE PRECISION NOT NULL,
    internal_mj     DOUBLE PRECISION NOT NULL,
    plastic_mj      DOUBLE PRECISION NOT NULL,
    external_mj     DOUBLE PRECISION NOT NULL,
    friction_mj     DOUBLE PRECISION NOT NULL,
    elastic_mj      DOUBLE PRECISION NOT NULL DEFAULT 0,
    work_top_mj     DOUBLE PRECISION NOT NULL DEFAULT 0,
    work_bottom_mj  DOUBLE PRECISION NOT NULL DEFAULT 0,
    contact_mj      DOUBLE PRECISION NOT NULL DEFAULT 0,
    residual_mj     DOUBLE PRECISION NOT NULL DEFAULT 0,
    PRIMARY KEY (job_id, row)
);

-- See migrations/sqlite/0002_final_states.sql: little-endian f32 x, y, z (mm), plastic strain.
CREATE TABLE final_states (
    job_id    TEXT PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    particles BIGINT NOT NULL,
    data      BYTEA NOT NULL
);

-- The row `/healthz` writes to prove the database takes writes now.
CREATE TABLE health (
    id         BIGINT PRIMARY KEY CHECK (id = 1),
    checked_at BIGINT NOT NULL
);
INSERT INTO health (id, checked_at) VALUES (1, 0);
