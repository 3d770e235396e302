//! The measured tubes `crush validate` compares with: axial crush tests from the literature,
//! transcribed in `validation/measured_tests.json` (compiled into the binary), each row with its
//! source, table and units, the measured columns apart from the theory columns printed beside
//! them. Units: mm, MPa, GPa, kN. Imports nothing of the validate folder.
//!
//! A row is refused when it does not name its source and table, or when its measured mean load
//! equals one of its theory columns (a theory transcribed as a measurement).

use serde::Deserialize;
use serde_json::{json, Value};
use std::collections::BTreeMap;

/// The data file, as compiled in.
const FILE: &str = include_str!("../../../validation/measured_tests.json");

/// The data file's shape.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[allow(dead_code)]
    about: String,
    /// Papers whose tables are to be transcribed, named for whoever can read them in full.
    candidates_not_yet_transcribed: Vec<String>,
    tubes: Vec<MeasuredTube>,
}

/// One tube crushed in a testing machine.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasuredTube {
    /// A short name, unique in the file.
    pub id: String,
    /// Authors, year, title, journal, volume, pages.
    pub source: String,
    /// Where in the source: "Table 3".
    pub table: String,
    pub section: Section,
    pub material: String,
    pub props: Props,
    /// Outer diameter (round) or outer width (square), mm.
    pub outer_mm: f64,
    pub thickness_mm: f64,
    pub length_mm: f64,
    /// Plate travel of the test, mm.
    pub crush_mm: f64,
    pub measured: Measured,
    /// Theory or FE values printed beside the measurement, kN, by the name the source gives.
    #[serde(default)]
    pub theory_columns: BTreeMap<String, f64>,
    /// How the source's units were converted.
    pub units_note: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Section {
    Round,
    Square,
}

/// The material as the source measured it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Props {
    pub youngs_modulus_gpa: f64,
    pub poisson_ratio: f64,
    pub yield_mpa: f64,
    pub ultimate_mpa: f64,
    pub density_kg_m3: f64,
}

/// What the test measured.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Measured {
    pub mean_kn: Option<f64>,
    pub peak_kn: Option<f64>,
    /// As `CollapseMode::kind` spells it: ring, diamond, global_buckling, symmetric, …
    pub mode: String,
    pub lobes: Option<u32>,
}

impl MeasuredTube {
    pub fn title(&self) -> String {
        let what = match self.section {
            Section::Round => "round, D",
            Section::Square => "square, b",
        };
        format!(
            "{} {what} {} t {} l {} mm",
            self.material, self.outer_mm, self.thickness_mm, self.length_mm
        )
    }
}

/// Why a row cannot stand, or `None`.
fn refusal(tube: &MeasuredTube) -> Option<String> {
    if tube.source.trim().len() < 20 {
        return Some("names no source (authors, year, title, journal)".into());
    }
    if tube.table.trim().is_empty() {
        return Some("names no table or figure of its source".into());
    }
    let mean = tube.measured.mean_kn?;
    let theory = tube
        .theory_columns
        .iter()
        .find(|(_, v)| (**v - mean).abs() <= 1e-9 * mean.abs().max(1.0));
    theory.map(|(name, _)| format!("its measured mean equals its theory column {name}"))
}

/// The rows of `text`, every one checked; an error names the row and why.
fn parse(text: &str) -> Result<(Vec<MeasuredTube>, Vec<String>), String> {
    let file: File = serde_json::from_str(text).map_err(|e| e.to_string())?;
    for t in &file.tubes {
        if let Some(why) = refusal(t) {
            return Err(format!("measured tube {}: {why}", t.id));
        }
    }
    Ok((file.tubes, file.candidates_not_yet_transcribed))
}

/// The measured tubes of the data file.
pub fn tubes() -> Vec<MeasuredTube> {
    parse(FILE)
        .unwrap_or_else(|e| panic!("validation/measured_tests.json: {e}"))
        .0
}

/// The papers named in the data file whose tables are not transcribed yet.
pub fn candidates() -> Vec<String> {
    parse(FILE)
        .unwrap_or_else(|e| panic!("validation/measured_tests.json: {e}"))
        .1
}

/// The case that stands for `tube` (at the full profile's resolution when `full`), and how it models the test in a phrase. A
/// round tube crushed in rings runs in its axisymmetric section; any other in 3D with a 0.3 %
/// trigger on a platen's μ 0.3. The wall is perfectly plastic at the flow stress (σy + σu)/2.
pub fn case(tube: &MeasuredTube, full: bool) -> (Value, String) {
    let t = tube.thickness_mm;
    let ring = tube.section == Section::Round && tube.measured.mode == "ring";
    let n = match (full, ring) {
        (true, true) => 8,
        (true, false) => 4,
        (false, true) => 4,
        (false, false) => 2,
    };
    let tube_json = match tube.section {
        Section::Round => json!({
            "thickness_mm": t, "mean_diameter_mm": tube.outer_mm - t, "length_mm": tube.length_mm
        }),
        Section::Square => json!({
            "section": "rectangular", "thickness_mm": t, "side_a_mm": tube.outer_mm - t,
            "length_mm": tube.length_mm
        }),
    };
    let p = &tube.props;
    let flow = 0.5 * (p.yield_mpa + p.ultimate_mpa);
    let case = json!({
        "label": format!("{} ({})", tube.title(), tube.id),
        "tube": tube_json,
        "material": {
            "model": "j2",
            "youngs_modulus_mpa": p.youngs_modulus_gpa * 1e3,
            "poisson_ratio": p.poisson_ratio,
            "yield_stress_mpa": flow,
            "density_kg_m3": p.density_kg_m3,
        },
        "loading": {"mode": "axial", "plate_speed_m_s": 10.0, "crush_distance_mm": tube.crush_mm},
        "contact": {"friction": 0.3},
        "discretization": {
            "particles_through_thickness": n,
            "model": if ring { "axisymmetric" } else { "3d" },
        },
        "trigger": {"weak_fraction": if ring { 0.0 } else { 0.003 }},
        "output": {"final_state": !ring},
    });
    let how = if ring {
        format!("axisymmetric section, n {n}")
    } else {
        format!("3D, n {n}, 0.3 % trigger")
    };
    (
        case,
        format!("{how}; perfectly plastic at σ0 {flow:.0} MPa"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(mean: f64, theory: &[(&str, f64)]) -> String {
        json!({
            "about": "", "candidates_not_yet_transcribed": [],
            "tubes": [{
                "id": "x", "source": "A. Author and B. Author, A paper, Some Journal 1 (2000) 1-10",
                "table": "Table 2", "section": "round", "material": "AA6060-T5",
                "props": {"youngs_modulus_gpa": 68.0, "poisson_ratio": 0.3, "yield_mpa": 180.0,
                          "ultimate_mpa": 200.0, "density_kg_m3": 2700.0},
                "outer_mm": 50.0, "thickness_mm": 2.0, "length_mm": 100.0, "crush_mm": 60.0,
                "measured": {"mean_kn": mean, "peak_kn": 40.0, "mode": "ring", "lobes": null},
                "theory_columns": theory.iter().cloned().collect::<BTreeMap<_, _>>(),
                "units_note": "N / 1000"
            }]
        })
        .to_string()
    }

    #[test]
    fn the_data_file_parses_and_every_row_names_its_source_and_keeps_theory_apart() {
        let (tubes, candidates) = parse(FILE).unwrap();
        for t in &tubes {
            assert!(refusal(t).is_none());
            assert!(t.measured.mean_kn.is_some() || t.measured.peak_kn.is_some());
        }
        assert!(!tubes.is_empty() || !candidates.is_empty());
    }

    #[test]
    fn a_theory_column_transcribed_as_the_measurement_is_refused() {
        assert!(parse(&row(25.0, &[("Alexander", 22.0)])).is_ok());
        let err = parse(&row(22.0, &[("Alexander", 22.0)])).unwrap_err();
        assert!(err.contains("theory column Alexander"), "{err}");
    }

    #[test]
    fn a_row_without_its_source_is_refused() {
        let text = row(25.0, &[]).replace(
            "A. Author and B. Author, A paper, Some Journal 1 (2000) 1-10",
            "",
        );
        assert!(parse(&text).unwrap_err().contains("names no source"));
        let text = row(25.0, &[]).replace("Table 2", " ");
        assert!(parse(&text).unwrap_err().contains("names no table"));
    }

    #[test]
    fn a_ring_tube_runs_in_its_section_at_the_flow_stress() {
        let (tubes, _) = parse(&row(25.0, &[])).unwrap();
        let (case, how) = case(&tubes[0], false);
        assert_eq!(case["discretization"]["model"], "axisymmetric");
        assert_eq!(case["tube"]["mean_diameter_mm"], 48.0);
        assert_eq!(case["material"]["yield_stress_mpa"], 190.0);
        assert!(how.contains("σ0 190 MPa"), "{how}");
        let text = case.to_string();
        crate::solver::Case::from_json(&text, &crate::solver::Limits::unbounded()).unwrap();
    }
}
