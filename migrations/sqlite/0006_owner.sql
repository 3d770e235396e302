-- The name of the token that submitted each job (`--token-file`); NULL for a job submitted to a
-- server without tokens, and for every job stored before tokens existed. A token with the submit
-- role may cancel only the jobs that carry its name.
ALTER TABLE jobs ADD COLUMN owner TEXT;
