-- The time series of a job whose case asks for one (output.frames): each frame in parts of at
-- most 65 536 particles (3.5 MB), so that a download reads one part at a time, stored by the
-- worker as the run reaches the frame. `data` is little-endian f32, per particle in the case's
-- own particle order: position x, y, z (mm), equivalent plastic strain, Cauchy stress xx, yy,
-- zz, yz, xz, xy (MPa), velocity x, y, z (m/s), volume (mm³); `particles` is the frame's count.
-- A run that starts over writes its frames again; a job that fails or is cancelled keeps none.
CREATE TABLE frames (
    job_id    TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    k         INTEGER NOT NULL,
    part      INTEGER NOT NULL,
    travel_mm REAL NOT NULL,
    time_ms   REAL NOT NULL,
    particles INTEGER NOT NULL,
    data      BLOB NOT NULL,
    PRIMARY KEY (job_id, k, part)
);
