//! CSV exports: the history (one row per history point, columns [`HistoryRow::COLUMNS`]) and
//! the particles (start and final position in mm, equivalent plastic strain; one particle per
//! row, in the case's particle order). Numbers are written as the shortest text that reads back
//! as the same f64.

use crate::solver::HistoryRow;
use std::io::Write;

/// Columns of the particles' CSV.
pub const PARTICLE_COLUMNS: [&str; 7] = [
    "x0_mm",
    "y0_mm",
    "z0_mm",
    "x_mm",
    "y_mm",
    "z_mm",
    "plastic_strain",
];

/// Writes the history: a header row, then each row's values in [`HistoryRow::COLUMNS`] order.
pub fn history<W: Write>(out: W, rows: impl IntoIterator<Item = [f64; 14]>) -> csv::Result<W> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(HistoryRow::COLUMNS)?;
    for row in rows {
        w.write_record(row.iter().map(|v| v.to_string()))?;
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

/// Writes the particles: a header row, then per particle its start position, final position
/// (mm) and equivalent plastic strain.
pub fn particles<W: Write>(
    out: W,
    rows: impl IntoIterator<Item = ([f64; 3], [f64; 3], f64)>,
) -> csv::Result<W> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(PARTICLE_COLUMNS)?;
    for (a, b, e) in rows {
        w.write_record(
            [a[0], a[1], a[2], b[0], b[1], b[2], e]
                .iter()
                .map(|v| v.to_string()),
        )?;
    }
    w.into_inner().map_err(|e| e.into_error().into())
}
