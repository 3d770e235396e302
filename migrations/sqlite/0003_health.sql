-- One row the health check writes (`/healthz`): a probe that commits proves the database can
-- be written now (not only read), so a full or read-only disk shows as unhealthy.
CREATE TABLE health (
    id         INTEGER PRIMARY KEY CHECK (id = 1),
    checked_at INTEGER NOT NULL
);
INSERT INTO health (id, checked_at) VALUES (1, 0);
