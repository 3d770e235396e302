-- The rungs of a run's error-bar ladder finished so far, as JSON (a list of rungs), beside the
-- checkpoint of the finished run they follow: a job interrupted while it prices its error bar
-- resumes with the next rung. NULL while the run itself is not finished.
ALTER TABLE checkpoints ADD COLUMN ladder_json TEXT;
