-- See migrations/sqlite/0009_ladder.sql.
ALTER TABLE checkpoints ADD COLUMN ladder_json TEXT;
