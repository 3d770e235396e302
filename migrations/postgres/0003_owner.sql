-- The name of the token that submitted each job (`--token-file`), as in
-- migrations/sqlite/0006_owner.sql: NULL for a job submitted to a server without tokens.
ALTER TABLE jobs ADD COLUMN owner TEXT;
