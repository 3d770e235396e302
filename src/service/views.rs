//! What clients see of stored records: the job and sweep JSON, the sweep table, the final SSE
//! event. Times are RFC 3339 (UTC).

use super::hub::{final_id, Event};
use super::store::{JobRecord, Status, SweepRecord};
use crate::solver::RunOutput;
use crate::study::convergence::{analyse, GroupAnalysis, RunPoint};
use serde::Serialize;
use serde_json::Value;
use uuid::Uuid;

/// Unix ms → RFC 3339.
pub fn rfc3339(ms: i64) -> String {
    time::OffsetDateTime::from_unix_timestamp_nanos(ms as i128 * 1_000_000)
        .ok()
        .and_then(|t| {
            t.format(&time::format_description::well_known::Rfc3339)
                .ok()
        })
        .unwrap_or_default()
}

fn json(text: Option<&str>) -> Option<Value> {
    text.and_then(|t| serde_json::from_str(t).ok())
}

#[derive(Debug, Serialize)]
pub struct JobLinks {
    #[serde(rename = "self")]
    pub this: String,
    pub events: String,
    pub history: String,
    pub cancel: String,
    pub summary: String,
    pub plot: String,
    pub shape: String,
    pub state: String,
}

/// A job as the API shows it.
#[derive(Debug, Serialize)]
pub struct JobView {
    pub id: Uuid,
    pub status: Status,
    pub label: Option<String>,
    pub created_at: String,
    pub started_at: Option<String>,
    pub finished_at: Option<String>,
    pub attempts: i64,
    pub cancel_requested: bool,
    pub particles: i64,
    pub progress: Option<Value>,
    pub error: Option<String>,
    pub sweep_id: Option<Uuid>,
    /// The values this job takes from its sweep, field → value.
    pub sweep_values: Option<Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub case: Option<Value>,
    pub summary: Option<Value>,
    pub links: JobLinks,
}

impl JobView {
    /// `with_case`: include the case as submitted (single-job reads, not lists).
    pub fn new(r: &JobRecord, with_case: bool) -> JobView {
        let base = format!("/v1/jobs/{}", r.id);
        JobView {
            id: r.id,
            status: r.status,
            label: r.label.clone(),
            created_at: rfc3339(r.created_at),
            started_at: r.started_at.map(rfc3339),
            finished_at: r.finished_at.map(rfc3339),
            attempts: r.attempts,
            cancel_requested: r.cancel_requested,
            particles: r.particles,
            progress: json(r.progress_json.as_deref()),
            error: r.error.clone(),
            sweep_id: r.sweep_id,
            sweep_values: json(r.sweep_values_json.as_deref()),
            case: if with_case {
                json(Some(&r.case_json))
            } else {
                None
            },
            summary: json(r.summary_json.as_deref()),
            links: JobLinks {
                events: format!("{base}/events"),
                history: format!("{base}/history"),
                cancel: format!("{base}/cancel"),
                summary: format!("{base}/summary"),
                plot: format!("{base}/plot.svg"),
                shape: format!("{base}/shape.png"),
                state: format!("{base}/state.vtu"),
                this: base,
            },
        }
    }
}

/// The SSE event that ends a finished job's stream; `None` while it is not finished.
pub fn final_event(r: &JobRecord) -> Option<Event> {
    let name = match r.status {
        Status::Succeeded => "done",
        Status::Failed => "failed",
        Status::Cancelled => "cancelled",
        Status::Queued | Status::Running => return None,
    };
    let data = serde_json::to_string(&JobView::new(r, false)).unwrap_or_default();
    Some(Event {
        id: final_id(r.attempts),
        name,
        data,
    })
}

/// The first non-finite number of a run's output, named; `None` when all are finite.
pub fn non_finite(out: &RunOutput) -> Option<String> {
    for (i, row) in out.history.iter().enumerate() {
        let cols = crate::solver::HistoryRow::COLUMNS;
        if let Some((c, _)) = cols.iter().zip(row.values()).find(|(_, v)| !v.is_finite()) {
            return Some(format!("a non-finite {c} in history row {i}"));
        }
    }
    let snap = &out.snapshot;
    if let Some(i) = snap
        .position_mm
        .iter()
        .position(|x| !x.iter().all(|v| v.is_finite()))
    {
        return Some(format!("a non-finite final position of particle {i}"));
    }
    if let Some(i) = snap.plastic_strain.iter().position(|e| !e.is_finite()) {
        return Some(format!("a non-finite final plastic strain of particle {i}"));
    }
    let s = &out.summary;
    let key = [
        ("mean_load_n", s.mean_load_n),
        ("peak_load_n", s.peak_load_n),
        ("energy_absorbed_mj", s.energy_absorbed_mj),
        ("energy_balance_error", s.energy_balance_error),
        ("wall_time_s", s.cost.wall_time_s),
    ];
    key.iter()
        .find(|(_, v)| !v.is_finite())
        .map(|(n, _)| format!("a non-finite {n} in the summary"))
}

/// Key summary numbers of a sweep table, in column order.
pub const TABLE_NUMBERS: [&str; 9] = [
    "mean_load_n",
    "peak_load_n",
    "energy_absorbed_mj",
    "folds",
    "mode",
    "energy_balance_error",
    "particles",
    "steps",
    "wall_time_s",
];

fn table_number(summary: &Value, name: &str) -> Value {
    let ptr = match name {
        "mode" => "/mode/kind",
        "particles" | "steps" | "wall_time_s" => {
            return summary
                .pointer(&format!("/cost/{name}"))
                .cloned()
                .unwrap_or(Value::Null)
        }
        _ => return summary.get(name).cloned().unwrap_or(Value::Null),
    };
    summary.pointer(ptr).cloned().unwrap_or(Value::Null)
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
                let summary = json(j.summary_json.as_deref())?;
                let num = |p: &str| summary.pointer(p).and_then(Value::as_f64);
                Some(RunPoint {
                    group: group_key(fields, &values),
                    n: values.get(RESOLUTION_FIELD)?.as_u64()? as u32,
                    particles: num("/cost/particles")? as u64,
                    steps: num("/cost/steps")? as u64,
                    wall_time_s: num("/cost/wall_time_s")?,
                    mean_load_n: num("/mean_load_n")?,
                    peak_load_n: num("/peak_load_n")?,
                    reference_n: num("/references/primary_n")?,
                })
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
        columns.extend(TABLE_NUMBERS.iter().map(|s| s.to_string()));
        let mut counts = serde_json::Map::new();
        for status in Status::ALL {
            let n = jobs.iter().filter(|j| j.status == status).count();
            counts.insert(status.as_str().into(), n.into());
        }
        let convergence = fields
            .iter()
            .any(|f| f == RESOLUTION_FIELD)
            .then(|| Convergence::of(&fields, jobs));
        columns.push("particle_steps_per_s".into());
        if convergence.is_some() {
            columns.extend(ERROR_COLUMNS.iter().map(|s| s.to_string()));
        }
        let rows = jobs
            .iter()
            .map(|j| {
                let values = json(j.sweep_values_json.as_deref()).unwrap_or(Value::Null);
                let summary = json(j.summary_json.as_deref()).unwrap_or(Value::Null);
                let mut row = serde_json::Map::new();
                row.insert("job_id".into(), j.id.to_string().into());
                for f in &fields {
                    row.insert(f.clone(), values.get(f).cloned().unwrap_or(Value::Null));
                }
                row.insert("status".into(), j.status.as_str().into());
                for n in TABLE_NUMBERS {
                    row.insert(n.into(), table_number(&summary, n));
                }
                row.insert(
                    "particle_steps_per_s".into(),
                    summary
                        .pointer("/cost/particle_steps_per_s")
                        .cloned()
                        .unwrap_or(Value::Null),
                );
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

    #[test]
    fn times_are_rfc3339_utc() {
        assert_eq!(rfc3339(0), "1970-01-01T00:00:00Z");
        assert_eq!(rfc3339(1_500), "1970-01-01T00:00:01.5Z");
    }
}
