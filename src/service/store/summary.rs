//! A run's summary as the store reads it back, whichever version of the summary stored it.
//! The solver's [`Summary`] is what the store writes; rows stored by older versions lack some
//! of its fields, and [`StoredSummary`] reads them all and serves each as the API always has.
//! A leaf of the store: imports nothing of it.

use crate::solver::analysis::error_bar::ErrorBar;
use crate::solver::analysis::expected::ExpectedError;
use crate::solver::analysis::measures::Measures;
use crate::solver::analysis::verdict::Verdict;
use crate::solver::model::case::ShapeChoice;
use crate::solver::{CollapseMode, EnergyBooks, References, RunCost, Summary};
use crate::study::figures::{not_trusted, Figures};
use schemars::{JsonSchema, Schema, SchemaGenerator};
use serde::{Deserialize, Serialize};
use serde_json::{json, Map, Value};
use std::borrow::Cow;

/// A stored summary: field for field the solver's [`Summary`] (which says what each means),
/// but for the three that rows stored by older versions may lack ([`OLDER_ROWS_LACK`]).
/// Serializes as it reads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StoredSummary {
    pub mean_load_n: f64,
    pub peak_load_n: f64,
    pub energy_absorbed_mj: f64,
    pub crush_distance_mm: f64,
    pub folds: u32,
    pub load_drops: u32,
    pub energy_balance_error: f64,
    pub energy: EnergyBooks,
    #[serde(flatten)]
    pub measures: Measures,
    pub kinetic_to_internal: f64,
    pub longest_unloaded_mm: f64,
    pub mode: CollapseMode,
    pub references: References,
    pub cost: RunCost,
    /// See [`OLDER_ROWS_LACK`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeChoice>,
    /// See [`OLDER_ROWS_LACK`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verdict: Option<Verdict>,
    /// Absent where the run did not price its error bar, as in the solver's summary.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_bar: Option<ErrorBar>,
    /// See [`OLDER_ROWS_LACK`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expected_error: Option<ExpectedError>,
}

/// The fields of the solver's summary that results stored by older versions lack, and which
/// versions: the API serves such a summary without them, and its contract says so.
pub const OLDER_ROWS_LACK: [(&str, &str); 3] = [
    (
        "shape",
        "Absent from results stored before the default depended on the wall.",
    ),
    (
        "verdict",
        "Absent from results stored before there were verdicts.",
    ),
    (
        "expected_error",
        "Absent from results stored before there were expected errors.",
    ),
];

impl StoredSummary {
    /// Reads a stored summary's JSON of any version; the error says where it does not read.
    pub fn read(text: &str) -> Result<StoredSummary, String> {
        let mut value: Value =
            serde_json::from_str(text).map_err(|e| format!("is not JSON: {e}"))?;
        if let Value::Object(fields) = &mut value {
            fill_older(fields);
        }
        serde_path_to_error::deserialize(value)
            .map_err(|e| format!("does not read at {}: {}", e.path(), e.inner()))
    }

    /// What the studies read of the run, as [`Figures::of`] reads the solver's summary.
    pub fn figures(&self) -> Figures {
        Figures {
            cost: self.cost,
            mean_load_n: self.mean_load_n,
            peak_load_n: self.peak_load_n,
            energy_absorbed_mj: self.energy_absorbed_mj,
            first_peak_load_n: self.measures.first_peak_load_n,
            energy_balance_error: self.energy_balance_error,
            mode: self.mode,
            folds: self.folds,
            reference_n: self.references.primary_n(),
            not_trusted: not_trusted(self.verdict.as_ref()),
        }
    }
}

/// What rows stored by older versions lack, each filled with what such a row has always been
/// read as: the figure's zero (the crash measures lie at the summary's top level).
fn fill_older(summary: &mut Map<String, Value>) {
    let zeros = [
        // Stored before load drops were counted.
        ("load_drops", json!(0)),
        // Stored before the summary kept the energy books.
        (
            "energy",
            json!({
                "kinetic_mj": 0.0, "elastic_mj": 0.0, "plastic_mj": 0.0, "friction_mj": 0.0,
                "contact_mj": 0.0, "work_top_mj": 0.0, "work_bottom_mj": 0.0, "residual_mj": 0.0
            }),
        ),
        // Stored before the unloaded stretch was measured.
        ("longest_unloaded_mm", json!(0.0)),
        // Stored before the crash measures (the first peak's figures read as null).
        ("tube_mass_g", json!(0.0)),
        ("specific_energy_absorption_j_per_g", json!(0.0)),
        ("energy_dissipated_mj", json!(0.0)),
    ];
    for (key, zero) in zeros {
        summary.entry(key).or_insert(zero);
    }
    // A round tube's references (the only ones with Alexander's ring load): stored before
    // the metal tube's closed forms, or before those named σy and σu.
    let round = summary
        .get_mut("references")
        .and_then(Value::as_object_mut)
        .filter(|r| r.contains_key("alexander_ring_n"));
    if let Some(references) = round {
        let metal = references.entry("metal").or_insert_with(|| {
            json!({
                "flow_stress_mpa": 0.0, "abramowicz_jones_n": 0.0,
                "abramowicz_jones_dynamic_n": null, "guillow_n": 0.0, "guillow_dynamic_n": null,
                "guillow_in_range": false, "fold_wavelength_mm": 0.0, "strain_rate_per_s": 0.0,
                "rate_factor": 0.0
            })
        });
        if let Value::Object(metal) = metal {
            for key in ["yield_stress_mpa", "ultimate_stress_mpa"] {
                metal.entry(key).or_insert(json!(0.0));
            }
        }
    }
}

impl From<Summary> for StoredSummary {
    fn from(s: Summary) -> StoredSummary {
        StoredSummary {
            mean_load_n: s.mean_load_n,
            peak_load_n: s.peak_load_n,
            energy_absorbed_mj: s.energy_absorbed_mj,
            crush_distance_mm: s.crush_distance_mm,
            folds: s.folds,
            load_drops: s.load_drops,
            energy_balance_error: s.energy_balance_error,
            energy: s.energy,
            measures: s.measures,
            kinetic_to_internal: s.kinetic_to_internal,
            longest_unloaded_mm: s.longest_unloaded_mm,
            mode: s.mode,
            references: s.references,
            cost: s.cost,
            shape: Some(s.shape),
            verdict: Some(s.verdict),
            error_bar: s.error_bar,
            expected_error: Some(s.expected_error),
        }
    }
}

/// The contract's `Summary`: the solver's, with the fields older rows lack not required and
/// their descriptions saying which results lack them.
impl JsonSchema for StoredSummary {
    fn schema_name() -> Cow<'static, str> {
        Summary::schema_name()
    }

    fn json_schema(generator: &mut SchemaGenerator) -> Schema {
        let mut schema = Summary::json_schema(generator);
        for (field, lacked) in OLDER_ROWS_LACK {
            if let Some(Value::Array(required)) = schema.get_mut("required") {
                required.retain(|k| k != field);
            }
            let property = schema
                .get_mut("properties")
                .and_then(|p| p.get_mut(field))
                .and_then(Value::as_object_mut);
            if let Some(property) = property {
                let text = match property.get("description").and_then(Value::as_str) {
                    Some(doc) => format!("{doc} {lacked}"),
                    None => lacked.to_string(),
                };
                property.insert("description".into(), text.into());
            }
        }
        schema
    }
}

#[cfg(test)]
mod tests;
