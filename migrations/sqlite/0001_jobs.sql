-- Jobs, sweeps, summaries and histories. Times are unix milliseconds (UTC).

CREATE TABLE sweeps (
    id              TEXT PRIMARY KEY,
    created_at      INTEGER NOT NULL,
    label           TEXT,
    base_json       TEXT NOT NULL,
    -- [[field, [value, ...]], ...] in table-column order
    parameters_json TEXT NOT NULL
);

CREATE TABLE jobs (
    seq               INTEGER PRIMARY KEY AUTOINCREMENT,
    id                TEXT NOT NULL UNIQUE,
    status            TEXT NOT NULL
                      CHECK (status IN ('queued', 'running', 'succeeded', 'failed', 'cancelled')),
    label             TEXT,
    case_json         TEXT NOT NULL,
    particles         INTEGER NOT NULL,
    idempotency_key   TEXT UNIQUE,
    sweep_id          TEXT REFERENCES sweeps (id),
    sweep_index       INTEGER,
    sweep_values_json TEXT,
    created_at        INTEGER NOT NULL,
    started_at        INTEGER,
    finished_at       INTEGER,
    -- times a worker claimed the job
    attempts          INTEGER NOT NULL DEFAULT 0,
    -- times its worker died (stale heartbeat) while running it
    lost              INTEGER NOT NULL DEFAULT 0,
    -- the current claim; a worker may write results only while it holds it
    lease             TEXT,
    worker            TEXT,
    heartbeat_at      INTEGER,
    cancel_requested  INTEGER NOT NULL DEFAULT 0,
    progress_json     TEXT,
    progress_fraction REAL,
    error             TEXT
);

CREATE INDEX jobs_status_seq ON jobs (status, seq);
CREATE INDEX jobs_label_seq ON jobs (label, seq);
CREATE INDEX jobs_sweep ON jobs (sweep_id, sweep_index);

-- One row per succeeded job: the numbers a dashboard queries, and the whole summary as JSON.
CREATE TABLE summaries (
    job_id               TEXT PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    mean_load_n          REAL NOT NULL,
    peak_load_n          REAL NOT NULL,
    energy_absorbed_mj   REAL NOT NULL,
    crush_distance_mm    REAL NOT NULL,
    folds                INTEGER NOT NULL,
    mode                 TEXT NOT NULL,
    energy_balance_error REAL NOT NULL,
    particles            INTEGER NOT NULL,
    steps                INTEGER NOT NULL,
    wall_time_s          REAL NOT NULL,
    summary_json         TEXT NOT NULL
);

-- The load-displacement and energy history of a succeeded job, one row per history point.
CREATE TABLE history (
    job_id          TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    row             INTEGER NOT NULL,
    time_ms         REAL NOT NULL,
    displacement_mm REAL NOT NULL,
    load_top_n      REAL NOT NULL,
    load_bottom_n   REAL NOT NULL,
    kinetic_mj      REAL NOT NULL,
    internal_mj     REAL NOT NULL,
    plastic_mj      REAL NOT NULL,
    external_mj     REAL NOT NULL,
    friction_mj     REAL NOT NULL,
    PRIMARY KEY (job_id, row)
) WITHOUT ROWID;
