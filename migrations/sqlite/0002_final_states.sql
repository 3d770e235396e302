-- The final particle state of a succeeded job, for the deformed-tube picture and the VTU file.
-- `data` is little-endian f32: per particle, in the case's own particle order, the final
-- position x, y, z (mm) and the equivalent plastic strain. The start positions are not stored:
-- the lattice is rebuilt from the case. A case with output.final_state = false stores no row.
CREATE TABLE final_states (
    job_id    TEXT PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    particles INTEGER NOT NULL,
    data      BLOB NOT NULL
);
