//! The sweep as the API shows it: its parameters, one table row per job with the key numbers
//! of its typed summary (N, mJ, s), and for a resolution sweep the convergence analysis.

use super::formats::{json, key_without, rfc3339};
use super::time_step::{time_steps, StepGroupView};
use crate::service::store::{JobRecord, Status, StoredSummary, SweepListed, SweepRecord};
use crate::study::convergence::{analyse, GroupAnalysis, RunPoint};
use crate::study::ensemble::{Distribution, SEED_FIELD};
use crate::study::step::STEP_FIELD;
use crate::study::Figures;
use schemars::JsonSchema;
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
    Verdict,
    VerdictReasons,
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
    pub const ALL: [TableNumber; 17] = [
        TableNumber::MeanLoad,
        TableNumber::PeakLoad,
        TableNumber::EnergyAbsorbed,
        TableNumber::Folds,
        TableNumber::Mode,
        TableNumber::EnergyBalanceError,
        TableNumber::Verdict,
        TableNumber::VerdictReasons,
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
            TableNumber::Verdict => "verdict",
            TableNumber::VerdictReasons => "verdict_reasons",
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
    pub fn of(self, s: &StoredSummary) -> Value {
        match self {
            TableNumber::MeanLoad => s.mean_load_n.into(),
            TableNumber::PeakLoad => s.peak_load_n.into(),
            TableNumber::EnergyAbsorbed => s.energy_absorbed_mj.into(),
            TableNumber::Folds => s.folds.into(),
            TableNumber::Mode => s.mode.kind().into(),
            TableNumber::EnergyBalanceError => s.energy_balance_error.into(),
            // Null for a summary stored before there were verdicts.
            TableNumber::Verdict => s.verdict.as_ref().map(|v| v.level.name()).into(),
            TableNumber::VerdictReasons => s
                .verdict
                .as_ref()
                .map(|v| {
                    v.reasons
                        .iter()
                        .map(|r| r.rule.name())
                        .collect::<Vec<_>>()
                        .join(" ")
                })
                .into(),
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

/// A sweep of the list: what it varies and how far its jobs are, without the table.
/// A sweep's `parameters` as shown: `[field, values]` pairs in column order.
fn parameters_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
    schemars::json_schema!({
        "type": "array",
        "items": {
            "type": "array",
            "description": "The field, then the list of its values",
            "minItems": 2,
            "maxItems": 2,
            "items": {
                "anyOf": [
                    { "type": "string" },
                    { "type": "array", "items": { "type": ["number", "string", "boolean", "null"] } }
                ]
            }
        }
    })
}

/// A page of the sweep list.
#[derive(Debug, Serialize, JsonSchema)]
pub struct SweepPage {
    pub sweeps: Vec<SweepListItem>,
    /// Pass as `cursor` for the next page; null on the last.
    pub next_cursor: Option<String>,
}

#[derive(Debug, Serialize, JsonSchema)]
pub struct SweepListItem {
    pub id: Uuid,
    pub label: Option<String>,
    #[schemars(extend("format" = "date-time"))]
    pub created_at: String,
    pub owner: Option<String>,
    /// `[field, values]` pairs in column order.
    #[schemars(schema_with = "parameters_schema")]
    pub parameters: Value,
    /// Jobs of the sweep, all states.
    pub jobs: i64,
    pub counts: serde_json::Map<String, Value>,
    pub links: SweepLinks,
}

#[derive(Debug, Serialize, JsonSchema)]
pub struct SweepLinks {
    #[serde(rename = "self")]
    pub this: String,
}

fn counts(of: impl Fn(Status) -> i64) -> serde_json::Map<String, Value> {
    Status::ALL
        .iter()
        .map(|s| (s.as_str().to_string(), of(*s).into()))
        .collect()
}

impl SweepListItem {
    pub fn new(l: &SweepListed) -> SweepListItem {
        let of = |status| {
            l.counts
                .iter()
                .filter(|(s, _)| *s == status)
                .map(|(_, n)| n)
                .sum()
        };
        SweepListItem {
            id: l.record.id,
            label: l.record.label.clone(),
            created_at: rfc3339(l.record.created_at),
            owner: l.record.owner.clone(),
            parameters: json(Some(&l.record.parameters_json)).unwrap_or(Value::Null),
            jobs: l.counts.iter().map(|(_, n)| n).sum(),
            counts: counts(of),
            links: SweepLinks {
                this: format!("/v1/sweeps/{}", l.record.id),
            },
        }
    }
}

/// A sweep as the API shows it: its parameters, and one table row per job.
#[derive(Debug, Serialize, JsonSchema)]
#[schemars(rename = "Sweep")]
pub struct SweepView {
    pub id: Uuid,
    pub label: Option<String>,
    #[schemars(extend("format" = "date-time"))]
    pub created_at: String,
    /// The name of the token that submitted it; null on a server without tokens.
    pub owner: Option<String>,
    /// `[field, values]` pairs in column order.
    #[schemars(schema_with = "parameters_schema")]
    pub parameters: Value,
    /// The sweep's base case, as submitted.
    #[schemars(with = "serde_json::Map<String, Value>")]
    pub base: Value,
    pub counts: serde_json::Map<String, Value>,
    pub columns: Vec<String>,
    pub rows: Vec<serde_json::Map<String, Value>>,
    /// When the sweep varies `discretization.particles_through_thickness`: per group of the
    /// other swept values, the runs with their errors and the Richardson extrapolations.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub convergence: Option<Vec<GroupView>>,
    /// When the sweep varies `trigger.seed` (an ensemble): per group of the other swept
    /// values, the distribution of its finished runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ensemble: Option<Vec<EnsembleGroup>>,
    /// When the sweep varies `discretization.cfl`: per group of the other swept values, the
    /// time step's share of the error and the books at each step (`crush study step`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_step: Option<Vec<StepGroupView>>,
}

/// One group of an ensemble: the runs that differ only in their seed.
#[derive(Debug, Serialize, JsonSchema)]
pub struct EnsembleGroup {
    /// The other swept values, `field=value, …` (empty when only the seed varies).
    pub group: String,
    /// Runs of the group, finished or not.
    pub jobs: usize,
    /// The distribution of its succeeded runs; null until one has succeeded.
    pub distribution: Option<Distribution>,
}

/// Columns added when the sweep varies the seed: the row's group's distribution.
pub const ENSEMBLE_COLUMNS: [&str; 7] = [
    "ensemble_runs",
    "ensemble_modes",
    "ensemble_mean_load_n",
    "ensemble_sd_load_n",
    "ensemble_min_load_n",
    "ensemble_max_load_n",
    "ensemble_not_trusted_runs",
];

/// The ensemble's groups, in order of first appearance.
fn ensembles(fields: &[String], jobs: &[JobRecord]) -> Vec<EnsembleGroup> {
    let mut groups: Vec<(String, Vec<&JobRecord>)> = Vec::new();
    for j in jobs {
        let key = values_key(fields, j, SEED_FIELD);
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, members)) => members.push(j),
            None => groups.push((key, vec![j])),
        }
    }
    groups
        .into_iter()
        .map(|(group, members)| {
            let done: Vec<Figures> = members
                .iter()
                .filter(|j| j.status == Status::Succeeded)
                .filter_map(|j| j.summary.as_ref().map(StoredSummary::figures))
                .collect();
            EnsembleGroup {
                group,
                jobs: members.len(),
                distribution: Distribution::of(&done),
            }
        })
        .collect()
}

/// The job's swept values other than `left_out`, as one string.
fn values_key(fields: &[String], job: &JobRecord, left_out: &str) -> String {
    let values = json(job.sweep_values_json.as_deref()).unwrap_or(Value::Null);
    key_without(fields, &values, left_out)
}

impl EnsembleGroup {
    fn fill(&self, row: &mut serde_json::Map<String, Value>) {
        let d = self.distribution.as_ref();
        let mut put = |k: &str, v: Option<Value>| {
            row.insert(k.into(), v.unwrap_or(Value::Null));
        };
        put("ensemble_runs", d.map(|d| d.runs.into()));
        put("ensemble_modes", d.map(|d| d.modes_line().into()));
        put("ensemble_mean_load_n", d.map(|d| d.mean_load_n.mean.into()));
        put("ensemble_sd_load_n", d.map(|d| d.mean_load_n.sd.into()));
        put("ensemble_min_load_n", d.map(|d| d.mean_load_n.min.into()));
        put("ensemble_max_load_n", d.map(|d| d.mean_load_n.max.into()));
        put(
            "ensemble_not_trusted_runs",
            d.map(|d| d.not_trusted_runs.into()),
        );
    }
}

/// The tolerance the sweep view reads off for the user, as `crush study convergence` does.
pub const READ_OFF_TOLERANCE: f64 = 0.05;

/// One group of a resolution sweep: the analysis, and the cheapest run within
/// [`READ_OFF_TOLERANCE`] of the best estimate.
#[derive(Debug, Serialize, JsonSchema)]
pub struct GroupView {
    #[serde(flatten)]
    pub analysis: GroupAnalysis,
    pub within_5_percent: Option<Cheapest>,
}

/// The cheapest run within the tolerance, and what its error was measured against.
#[derive(Debug, Serialize, JsonSchema)]
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
                    &s.figures(),
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
            put("mean_vs_reference", r.mean_vs_reference);
        }
    }
}

/// The other swept values of a job, as one string: the runs that differ only in resolution.
fn group_key(fields: &[String], values: &Value) -> String {
    key_without(fields, values, RESOLUTION_FIELD)
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
        let counts = counts(|status| jobs.iter().filter(|j| j.status == status).count() as i64);
        let convergence = fields
            .iter()
            .any(|f| f == RESOLUTION_FIELD)
            .then(|| Convergence::of(&fields, jobs));
        if convergence.is_some() {
            columns.extend(ERROR_COLUMNS.iter().map(|s| s.to_string()));
        }
        let ensemble = fields
            .iter()
            .any(|f| f == SEED_FIELD)
            .then(|| ensembles(&fields, jobs));
        if ensemble.is_some() {
            columns.extend(ENSEMBLE_COLUMNS.iter().map(|s| s.to_string()));
        }
        let time_step = fields
            .iter()
            .any(|f| f == STEP_FIELD)
            .then(|| time_steps(&fields, jobs));
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
                if let Some(groups) = &ensemble {
                    let key = values_key(&fields, j, SEED_FIELD);
                    if let Some(g) = groups.iter().find(|g| g.group == key) {
                        g.fill(&mut row);
                    }
                }
                row
            })
            .collect();
        SweepView {
            convergence: convergence.map(|c| c.groups.into_iter().map(GroupView::new).collect()),
            ensemble,
            time_step,
            id: s.id,
            label: s.label.clone(),
            created_at: rfc3339(s.created_at),
            owner: s.owner.clone(),
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
    /// of `cost`, an object's `kind` (the mode) or `level` (the verdict), or the verdict's rules
    /// in one line.
    fn json_field(summary: &Value, name: &str) -> Option<Value> {
        if name == "verdict_reasons" {
            let rules: Vec<&str> = summary["verdict"]["reasons"]
                .as_array()?
                .iter()
                .map(|r| r["rule"].as_str().unwrap())
                .collect();
            return Some(rules.join(" ").into());
        }
        match summary.get(name) {
            Some(Value::Object(o)) => o.get("kind").or_else(|| o.get("level")).cloned(),
            Some(v) => Some(v.clone()),
            None => summary.get("cost")?.get(name).cloned(),
        }
    }

    #[test]
    fn every_sweep_table_number_is_the_summary_field_of_its_name() {
        // Distinct values everywhere, so that a column reading the wrong field shows.
        let mut s = StoredSummary::from(crate::service::store::sample_summary());
        s.cost.particle_steps_per_s = 8.25e6;
        s.cost.threads = 7;
        s.verdict = Some(crate::solver::analysis::verdict::Verdict::unstable(
            "a blow-up",
        ));
        let json = serde_json::to_value(&s).unwrap();
        let mut names = std::collections::HashSet::new();
        for n in TableNumber::ALL {
            assert!(names.insert(n.name()), "{} twice", n.name());
            let field = json_field(&json, n.name())
                .unwrap_or_else(|| panic!("the summary has no field {}", n.name()));
            assert_eq!(n.of(&s), field, "{}", n.name());
        }
    }

    #[test]
    fn the_sweep_table_has_every_number_and_nulls_before_the_summary() {
        let mut done = StoredSummary::from(crate::service::store::sample_summary());
        done.cost.particle_steps_per_s = 8.25e6;
        let mut older = done.clone();
        older.verdict = None;
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
            owner: None,
        };
        let jobs = [
            record(Status::Succeeded, Some(done.clone())),
            record(Status::Queued, None),
            record(Status::Succeeded, Some(older)),
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
        // A row stored before verdicts: its numbers, and null for its verdict.
        assert!(view.rows[0]["verdict"].is_string());
        assert_eq!(view.rows[2]["verdict"], Value::Null);
        assert_eq!(view.rows[2]["verdict_reasons"], Value::Null);
        assert_eq!(view.rows[2]["mean_load_n"], done.mean_load_n);
    }
}
