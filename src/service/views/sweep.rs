//! The sweep as the API shows it: its parameters, one table row per job with the key numbers
//! of its typed summary (N, mJ, s), and for a resolution sweep the convergence analysis.

use super::{json, rfc3339};
use crate::service::store::{JobRecord, Status, SweepRecord};
use crate::solver::Summary;
use crate::study::convergence::{analyse, GroupAnalysis, RunPoint};
use serde::Serialize;
use serde_json::Value;
use uuid::Uuid;

/// A number of the sweep table, read from the typed summary. Each column is named as its field
/// in the summary's JSON (`mode` is the mode's `kind`, the cost's numbers are `cost.*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableNumber {
    MeanLoad,
    PeakLoad,
    EnergyAbsorbed,
    Folds,
    Mode,
    EnergyBalanceError,
    Particles,
    Steps,
    WallTime,
    ParticleStepsPerS,
    FirstPeak,
    MeanAfterFirstPeak,
    CrushForceEfficiency,
    SpecificEnergyAbsorption,
    TubeMass,
}

impl TableNumber {
    /// Every number, in column order.
    pub const ALL: [TableNumber; 15] = [
        TableNumber::MeanLoad,
        TableNumber::PeakLoad,
        TableNumber::EnergyAbsorbed,
        TableNumber::Folds,
        TableNumber::Mode,
        TableNumber::EnergyBalanceError,
        TableNumber::Particles,
        TableNumber::Steps,
        TableNumber::WallTime,
        TableNumber::ParticleStepsPerS,
        TableNumber::FirstPeak,
        TableNumber::MeanAfterFirstPeak,
        TableNumber::CrushForceEfficiency,
        TableNumber::SpecificEnergyAbsorption,
        TableNumber::TubeMass,
    ];

    /// The column's name.
    pub fn name(self) -> &'static str {
        match self {
            TableNumber::MeanLoad => "mean_load_n",
            TableNumber::PeakLoad => "peak_load_n",
            TableNumber::EnergyAbsorbed => "energy_absorbed_mj",
            TableNumber::Folds => "folds",
            TableNumber::Mode => "mode",
            TableNumber::EnergyBalanceError => "energy_balance_error",
            TableNumber::Particles => "particles",
            TableNumber::Steps => "steps",
            TableNumber::WallTime => "wall_time_s",
            TableNumber::ParticleStepsPerS => "particle_steps_per_s",
            TableNumber::FirstPeak => "first_peak_load_n",
            TableNumber::MeanAfterFirstPeak => "mean_load_after_first_peak_n",
            TableNumber::CrushForceEfficiency => "crush_force_efficiency",
            TableNumber::SpecificEnergyAbsorption => "specific_energy_absorption_j_per_g",
            TableNumber::TubeMass => "tube_mass_g",
        }
    }

    /// The column's value for a run with this summary.
    pub fn of(self, s: &Summary) -> Value {
        match self {
            TableNumber::MeanLoad => s.mean_load_n.into(),
            TableNumber::PeakLoad => s.peak_load_n.into(),
            TableNumber::EnergyAbsorbed => s.energy_absorbed_mj.into(),
            TableNumber::Folds => s.folds.into(),
            TableNumber::Mode => s.mode.kind().into(),
            TableNumber::EnergyBalanceError => s.energy_balance_error.into(),
            TableNumber::Particles => s.cost.particles.into(),
            TableNumber::Steps => s.cost.steps.into(),
            TableNumber::WallTime => s.cost.wall_time_s.into(),
            TableNumber::ParticleStepsPerS => s.cost.particle_steps_per_s.into(),
            TableNumber::FirstPeak => s.measures.first_peak_load_n.into(),
            TableNumber::MeanAfterFirstPeak => s.measures.mean_load_after_first_peak_n.into(),
            TableNumber::CrushForceEfficiency => s.measures.crush_force_efficiency.into(),
            TableNumber::SpecificEnergyAbsorption => {
                s.measures.specific_energy_absorption_j_per_g.into()
            }
            TableNumber::TubeMass => s.measures.tube_mass_g.into(),
        }
    }
}

/// A sweep as the API shows it: its parameters, and one table row per job.
#[derive(Debug, Serialize)]
pub struct SweepView {
    pub id: Uuid,
    pub label: Option<String>,
    pub created_at: String,
    pub parameters: Value,
    pub base: Value,
    pub counts: serde_json::Map<String, Value>,
    pub columns: Vec<String>,
    pub rows: Vec<serde_json::Map<String, Value>>,
    /// When the sweep varies `discretization.particles_through_thickness`: per group of the
    /// other swept values, the runs with their errors and the Richardson extrapolations.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub convergence: Option<Vec<GroupView>>,
}

/// The tolerance the sweep view reads off for the user, as `crush study convergence` does.
pub const READ_OFF_TOLERANCE: f64 = 0.05;

/// One group of a resolution sweep: the analysis, and the cheapest run within
/// [`READ_OFF_TOLERANCE`] of the best estimate.
#[derive(Debug, Serialize)]
pub struct GroupView {
    #[serde(flatten)]
    pub analysis: GroupAnalysis,
    pub within_5_percent: Option<Cheapest>,
}

/// The cheapest run within the tolerance, and what its error was measured against.
#[derive(Debug, Serialize)]
pub struct Cheapest {
    pub n: u32,
    pub wall_time_s: f64,
    /// `richardson` when the extrapolation is trusted, else `finest`.
    pub against: &'static str,
}

impl GroupView {
    fn new(analysis: GroupAnalysis) -> GroupView {
        let trusted = analysis.mean_extrapolation.is_some_and(|e| e.trustworthy);
        let within_5_percent = analysis
            .cheapest_within(READ_OFF_TOLERANCE)
            .map(|r| Cheapest {
                n: r.run.n,
                wall_time_s: r.run.wall_time_s,
                against: if trusted { "richardson" } else { "finest" },
            });
        GroupView {
            analysis,
            within_5_percent,
        }
    }
}

/// The swept field that sets the resolution.
pub const RESOLUTION_FIELD: &str = "discretization.particles_through_thickness";

/// Columns added when the sweep varies the resolution (relative errors, see
/// `crate::study::convergence`).
pub const ERROR_COLUMNS: [&str; 5] = [
    "mean_error_vs_finest",
    "peak_error_vs_finest",
    "mean_error_vs_richardson",
    "peak_error_vs_richardson",
    "mean_vs_reference",
];

/// Convergence analysis of a sweep's succeeded jobs, grouped by the other swept values.
struct Convergence {
    groups: Vec<GroupAnalysis>,
}

impl Convergence {
    fn of(fields: &[String], jobs: &[JobRecord]) -> Convergence {
        let points: Vec<RunPoint> = jobs
            .iter()
            .filter(|j| j.status == Status::Succeeded)
            .filter_map(|j| {
                let values = json(j.sweep_values_json.as_deref())?;
                let s = j.summary.as_ref()?;
                Some(RunPoint::of(
                    group_key(fields, &values),
                    values.get(RESOLUTION_FIELD)?.as_u64()? as u32,
                    s,
                ))
            })
            .collect();
        Convergence {
            groups: analyse(&points),
        }
    }

    fn fill(&self, job: &JobRecord, row: &mut serde_json::Map<String, Value>) {
        for c in ERROR_COLUMNS {
            row.insert(c.into(), Value::Null);
        }
        let Some(values) = json(job.sweep_values_json.as_deref()) else {
            return;
        };
        let fields: Vec<String> = values
            .as_object()
            .map(|o| o.keys().cloned().collect())
            .unwrap_or_default();
        let key = group_key(&fields, &values);
        let n = values.get(RESOLUTION_FIELD).and_then(Value::as_u64);
        let found = self
            .groups
            .iter()
            .filter(|g| g.group == key)
            .flat_map(|g| &g.rows)
            .find(|r| Some(r.run.n as u64) == n);
        if let Some(r) = found {
            let mut put = |k: &str, v: Option<f64>| {
                row.insert(k.into(), v.map_or(Value::Null, Value::from));
            };
            put("mean_error_vs_finest", Some(r.mean_error_vs_finest));
            put("peak_error_vs_finest", Some(r.peak_error_vs_finest));
            put("mean_error_vs_richardson", r.mean_error_vs_richardson);
            put("peak_error_vs_richardson", r.peak_error_vs_richardson);
            put("mean_vs_reference", Some(r.mean_vs_reference));
        }
    }
}

/// The other swept values of a job, as one string: the runs that differ only in resolution.
fn group_key(fields: &[String], values: &Value) -> String {
    let mut parts: Vec<String> = fields
        .iter()
        .filter(|f| *f != RESOLUTION_FIELD)
        .map(|f| format!("{f}={}", values.get(f).unwrap_or(&Value::Null)))
        .collect();
    parts.sort();
    parts.join(", ")
}

impl SweepView {
    pub fn new(s: &SweepRecord, jobs: &[JobRecord]) -> SweepView {
        let parameters = json(Some(&s.parameters_json)).unwrap_or(Value::Null);
        let fields: Vec<String> = parameters
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|p| p.get(0)?.as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default();
        let mut columns = vec!["job_id".to_string()];
        columns.extend(fields.iter().cloned());
        columns.push("status".into());
        columns.extend(TableNumber::ALL.iter().map(|n| n.name().to_string()));
        let mut counts = serde_json::Map::new();
        for status in Status::ALL {
            let n = jobs.iter().filter(|j| j.status == status).count();
            counts.insert(status.as_str().into(), n.into());
        }
        let convergence = fields
            .iter()
            .any(|f| f == RESOLUTION_FIELD)
            .then(|| Convergence::of(&fields, jobs));
        if convergence.is_some() {
            columns.extend(ERROR_COLUMNS.iter().map(|s| s.to_string()));
        }
        let rows = jobs
            .iter()
            .map(|j| {
                let values = json(j.sweep_values_json.as_deref()).unwrap_or(Value::Null);
                let mut row = serde_json::Map::new();
                row.insert("job_id".into(), j.id.to_string().into());
                for f in &fields {
                    row.insert(f.clone(), values.get(f).cloned().unwrap_or(Value::Null));
                }
                row.insert("status".into(), j.status.as_str().into());
                for n in TableNumber::ALL {
                    let v = j.summary.as_ref().map_or(Value::Null, |s| n.of(s));
                    row.insert(n.name().into(), v);
                }
                if let Some(c) = &convergence {
                    c.fill(j, &mut row);
                }
                row
            })
            .collect();
        SweepView {
            convergence: convergence.map(|c| c.groups.into_iter().map(GroupView::new).collect()),
            id: s.id,
            label: s.label.clone(),
            created_at: rfc3339(s.created_at),
            parameters,
            base: json(Some(&s.base_json)).unwrap_or(Value::Null),
            counts,
            columns,
            rows,
        }
    }

    /// The table as CSV, header first; empty cells for numbers not yet known.
    pub fn csv(&self) -> Result<String, csv::Error> {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(&self.columns)?;
        for row in &self.rows {
            w.write_record(self.columns.iter().map(|c| match row.get(c) {
                None | Some(Value::Null) => String::new(),
                Some(Value::String(s)) => s.clone(),
                Some(v) => v.to_string(),
            }))?;
        }
        String::from_utf8(w.into_inner().map_err(|e| e.into_error())?)
            .map_err(|e| csv::Error::from(std::io::Error::other(e)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where a sweep-table column's name is in the summary's JSON: a top-level number, a number
    /// of `cost`, or an object's `kind` (the mode).
    fn json_field<'a>(summary: &'a Value, name: &str) -> Option<&'a Value> {
        match summary.get(name) {
            Some(Value::Object(o)) => o.get("kind"),
            Some(v) => Some(v),
            None => summary.get("cost")?.get(name),
        }
    }

    #[test]
    fn every_sweep_table_number_is_the_summary_field_of_its_name() {
        // Distinct values everywhere, so that a column reading the wrong field shows.
        let mut s = crate::service::store::sample_summary();
        s.cost.particle_steps_per_s = 8.25e6;
        s.cost.threads = 7;
        let json = serde_json::to_value(&s).unwrap();
        let mut names = std::collections::HashSet::new();
        for n in TableNumber::ALL {
            assert!(names.insert(n.name()), "{} twice", n.name());
            let field = json_field(&json, n.name())
                .unwrap_or_else(|| panic!("the summary has no field {}", n.name()));
            assert_eq!(&n.of(&s), field, "{}", n.name());
        }
    }

    #[test]
    fn the_sweep_table_has_every_number_and_nulls_before_the_summary() {
        let mut done = crate::service::store::sample_summary();
        done.cost.particle_steps_per_s = 8.25e6;
        let record = |status, summary| JobRecord {
            seq: 1,
            id: Uuid::new_v4(),
            status,
            label: None,
            case_json: "{}".into(),
            particles: 1,
            sweep_id: None,
            sweep_values_json: Some(r#"{"tube.thickness_mm": 1.5}"#.into()),
            created_at: 0,
            started_at: None,
            finished_at: None,
            attempts: 0,
            cancel_requested: false,
            progress_json: None,
            error: None,
            node: None,
            checkpoint: None,
            owner: None,
            summary,
        };
        let sweep = SweepRecord {
            id: Uuid::new_v4(),
            label: None,
            created_at: 0,
            parameters_json: r#"[["tube.thickness_mm", [1.5]]]"#.into(),
            base_json: "{}".into(),
        };
        let jobs = [
            record(Status::Succeeded, Some(done.clone())),
            record(Status::Queued, None),
        ];
        let view = SweepView::new(&sweep, &jobs);
        for n in TableNumber::ALL {
            assert!(view.columns.iter().any(|c| c == n.name()), "{}", n.name());
            assert_eq!(view.rows[0][n.name()], n.of(&done), "{}", n.name());
            assert_eq!(view.rows[1][n.name()], Value::Null, "{}", n.name());
        }
        assert_eq!(view.rows[0]["mean_load_n"], done.mean_load_n);
        assert_eq!(view.rows[0]["mode"], done.mode.kind());
        assert_eq!(view.rows[0]["particle_steps_per_s"], 8.25e6);
    }
}
