//! The files `crush run` leaves behind, the same the server gives for a job: `history.csv`
//! (one row per history point, columns [`HistoryRow::COLUMNS`]), `load.svg` (the load curve),
//! `energy.svg` (the plates' work and the energy dissipated against the travel; the CLI only),
//! `summary.json` (the summary plus the mode's diagnostics), and, when the case keeps the final
//! state (`output.final_state`), `particles.csv`, `state.vtu` (for ParaView) and `shape.png`.
//! A time series (`output.frames`) is written as the run goes (`cli/series.rs`).

use crate::export::{self, FinalState};
use crate::solver::analysis::mode::ModeDetail;
use crate::solver::Snapshot;
use crate::solver::{Case, HistoryRow, RunOutput, Summary};
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

/// What `summary.json` holds: every [`Summary`] field at the top level, the case's label and
/// the numbers behind the collapse mode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryFile {
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub label: Option<String>,
    #[serde(flatten)]
    pub summary: Summary,
    pub mode_detail: ModeDetail,
}

/// Writes the history as CSV with a header row ([`export::csv::history`]).
pub fn write_history_csv(path: &Path, rows: &[HistoryRow]) -> anyhow::Result<()> {
    let file = create(path)?;
    export::csv::history(file, rows.iter().map(HistoryRow::values))
        .and_then(|mut w| Ok(w.flush()?))
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes the final particle state as CSV ([`export::csv::particles`]).
pub fn write_particles_csv(path: &Path, snapshot: &Snapshot) -> anyhow::Result<()> {
    let rows = snapshot
        .initial_mm
        .iter()
        .zip(&snapshot.position_mm)
        .zip(&snapshot.plastic_strain)
        .map(|((a, b), e)| (*a, *b, *e));
    export::csv::particles(create(path)?, rows)
        .and_then(|mut w| Ok(w.flush()?))
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes the final particle state as a VTK file for ParaView ([`export::vtu::write_vtu`]), the
/// file the server's `state.vtu` gives.
pub fn write_state_vtu(path: &Path, case: &Case, snapshot: &Snapshot) -> anyhow::Result<()> {
    let geometry = case.geometry();
    let mut out = create(path)?;
    let state = FinalState::of(snapshot);
    export::vtu::write_vtu(
        &mut out,
        &snapshot.initial_mm,
        &state,
        geometry.symmetry_note(),
    )
    .and_then(|()| out.flush())
    .with_context(|| format!("writing {}", path.display()))
}

/// The load on the moving plate against its travel with the mean load, as SVG: the picture
/// the server's `plot.svg` gives.
pub fn write_load_svg(path: &Path, case: &Case, out: &RunOutput) -> anyhow::Result<()> {
    let title = case
        .spec()
        .label
        .as_deref()
        .unwrap_or("load against plate travel");
    let points = out
        .history
        .iter()
        .map(|r| (r.displacement_mm, r.load_top_n));
    let svg = crate::plot::load_curve_svg(title, points, Some(out.summary.mean_load_n))?;
    std::fs::write(path, svg).with_context(|| format!("writing {}", path.display()))
}

/// The energy against the plate's travel, as SVG: the plates' work and what the wall
/// dissipated of it (plastic work plus friction), J.
pub fn write_energy_svg(path: &Path, case: &Case, rows: &[HistoryRow]) -> anyhow::Result<()> {
    let curve = |name: &str, f: fn(&HistoryRow) -> f64| crate::plot::Series {
        name: name.into(),
        points: rows
            .iter()
            .map(|r| (r.displacement_mm, f(r) / 1000.0))
            .collect(),
    };
    let series = [
        curve("work of the plates", |r| r.external_mj),
        curve("dissipated: plastic + friction", |r| {
            r.plastic_mj + r.friction_mj
        }),
    ];
    let title = case
        .spec()
        .label
        .as_deref()
        .unwrap_or("energy against plate travel");
    let svg = crate::plot::lines_svg(
        (title, "plate travel, mm", "energy, J"),
        &series,
        &[],
        false,
    )?;
    std::fs::write(path, svg).with_context(|| format!("writing {}", path.display()))
}

/// A file for writing, buffered.
fn create(path: &Path) -> anyhow::Result<std::io::BufWriter<std::fs::File>> {
    let file =
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
    Ok(std::io::BufWriter::new(file))
}

/// Writes the summary as pretty JSON.
pub fn write_summary_json(path: &Path, file: &SummaryFile) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(file)?;
    std::fs::write(path, text + "\n").with_context(|| format!("writing {}", path.display()))
}

/// The deformed tube, coloured by plastic strain (see [`crate::plot::tube_png`]).
pub fn write_shape_png(path: &Path, case: &Case, snapshot: &Snapshot) -> anyhow::Result<()> {
    let state = FinalState::of(snapshot);
    let title = case.spec().label.as_deref().unwrap_or("final shape");
    let png = crate::plot::tube_png(
        case.geometry(),
        case.crush_distance_mm(),
        title,
        &state.position_mm,
        &state.plastic_strain,
    )?;
    std::fs::write(path, png).with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::CollapseMode;

    #[test]
    fn history_csv_has_the_header_and_every_row() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("history.csv");
        let rows = [
            HistoryRow {
                time_ms: 0.1,
                displacement_mm: 1.0,
                load_top_n: 1234.5,
                ..Default::default()
            },
            HistoryRow {
                time_ms: 0.2,
                displacement_mm: 2.0,
                load_top_n: 1e-7,
                ..Default::default()
            },
        ];
        write_history_csv(&path, &rows).unwrap();
        let mut r = csv::Reader::from_path(&path).unwrap();
        assert_eq!(
            r.headers().unwrap().iter().collect::<Vec<_>>(),
            HistoryRow::COLUMNS
        );
        let back: Vec<Vec<f64>> = r
            .records()
            .map(|rec| rec.unwrap().iter().map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(
            back,
            rows.iter().map(|r| r.values().to_vec()).collect::<Vec<_>>()
        );
    }

    #[test]
    fn summary_json_keeps_summary_fields_at_the_top() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.json");
        let file = SummaryFile {
            label: Some("t".into()),
            summary: Summary {
                mean_load_n: 1.0,
                mode: CollapseMode::Diamond { lobes: 3 },
                ..crate::service::store::sample_summary()
            },
            mode_detail: ModeDetail::default(),
        };
        write_summary_json(&path, &file).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(value["mean_load_n"], 1.0);
        assert_eq!(value["mode"]["lobes"], 3);
        // The plain Summary reads summary.json too (extra keys are ignored).
        let plain: Summary = serde_json::from_str(&text).unwrap();
        assert_eq!(plain, file.summary);
        assert_eq!(serde_json::from_str::<SummaryFile>(&text).unwrap(), file);
    }
}
