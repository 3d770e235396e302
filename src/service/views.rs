//! What clients see of stored records: the job JSON and the final SSE event here, the sweep and
//! its table in [`sweep`]. Times are RFC 3339 (UTC).

mod formats;
mod sweep;
mod time_step;

pub use formats::rfc3339;
pub use sweep::{SweepListItem, SweepPage, SweepView};

use formats::json;

use super::hub::{final_id, Event};
use super::store::{JobRecord, Status, StoredSummary};
use crate::solver::analysis::verdict::{self, Verdict};
use crate::solver::{RunOutput, Summary};
use schemars::JsonSchema;
use serde::Serialize;
use serde_json::Value;
use uuid::Uuid;

#[derive(Debug, Serialize, JsonSchema)]
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
    pub particles: String,
}

/// Where a job's checkpoint stands.
#[derive(Debug, Serialize, JsonSchema)]
pub struct CheckpointView {
    /// Solver steps done.
    pub step: i64,
    /// Share of the crush distance done, 0..1.
    pub fraction: f64,
    #[schemars(extend("format" = "date-time"))]
    pub written_at: String,
}

/// A job as the API shows it.
#[derive(Debug, Serialize, JsonSchema)]
#[schemars(rename = "Job")]
pub struct JobView {
    pub id: Uuid,
    pub status: Status,
    pub label: Option<String>,
    #[schemars(extend("format" = "date-time"))]
    pub created_at: String,
    #[schemars(extend("format" = "date-time"))]
    pub started_at: Option<String>,
    #[schemars(extend("format" = "date-time"))]
    pub finished_at: Option<String>,
    /// Times a worker claimed the job. `--max-attempts` counts only the claims that stored no
    /// checkpoint: a claim that moved the job on does not use up an attempt.
    pub attempts: i64,
    /// The node that runs the job, or that ran its last claim; null before the first claim.
    pub node: Option<String>,
    /// The name of the token that submitted the job; null on a server without tokens.
    pub owner: Option<String>,
    pub cancel_requested: bool,
    pub particles: i64,
    /// Latest stored progress (stored about once a second while running).
    #[schemars(with = "Option<crate::solver::Progress>")]
    pub progress: Option<Value>,
    /// Where the job's checkpoint stands while it has one (queued or running): a job put back
    /// in the queue resumes there instead of starting over.
    pub checkpoint: Option<CheckpointView>,
    pub error: Option<String>,
    pub sweep_id: Option<Uuid>,
    /// The values this job takes from its sweep, field → value.
    #[schemars(with = "Option<serde_json::Map<String, Value>>")]
    pub sweep_values: Option<Value>,
    /// The case as submitted (single-job reads only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(with = "crate::solver::CaseSpec")]
    pub case: Option<Value>,
    pub summary: Option<StoredSummary>,
    /// How far to trust the result: the summary's verdict, or not trusted for a run that failed
    /// on a blow-up; null while it runs and for a result stored before there were verdicts.
    pub verdict: Option<Verdict>,
    pub links: JobLinks,
}

/// A page of the job list.
#[derive(Debug, Serialize, JsonSchema)]
pub struct JobPage {
    pub jobs: Vec<JobView>,
    /// Pass as `cursor` for the next page; null on the last.
    pub next_cursor: Option<String>,
    /// Every job in the store by status, whatever the filters.
    pub counts: std::collections::BTreeMap<String, i64>,
}

/// A job's load history as JSON.
#[derive(Debug, Serialize, JsonSchema)]
#[schemars(rename = "History")]
pub struct HistoryView<'a> {
    pub job_id: Uuid,
    /// The name of each column, with its unit.
    pub columns: &'static [&'static str],
    /// One array of numbers per history point, in `columns` order.
    pub rows: &'a [Vec<f64>],
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
            node: r.node.clone(),
            owner: r.owner.clone(),
            cancel_requested: r.cancel_requested,
            particles: r.particles,
            progress: json(r.progress_json.as_deref()),
            checkpoint: r.checkpoint.map(|c| CheckpointView {
                step: c.step,
                fraction: c.fraction,
                written_at: rfc3339(c.written_at),
            }),
            error: r.error.clone(),
            sweep_id: r.sweep_id,
            sweep_values: json(r.sweep_values_json.as_deref()),
            case: if with_case {
                json(Some(&r.case_json))
            } else {
                None
            },
            summary: r.summary.clone(),
            verdict: match r.status {
                Status::Succeeded => r.summary.as_ref().and_then(|s| s.verdict.clone()),
                Status::Failed => r.error.as_deref().and_then(verdict::of_failure),
                _ => None,
            },
            links: JobLinks {
                events: format!("{base}/events"),
                history: format!("{base}/history"),
                cancel: format!("{base}/cancel"),
                summary: format!("{base}/summary"),
                plot: format!("{base}/plot.svg"),
                shape: format!("{base}/shape.png"),
                state: format!("{base}/state.vtu"),
                particles: format!("{base}/particles.csv"),
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
    if let Some((n, _)) = key.iter().find(|(_, v)| !v.is_finite()) {
        return Some(format!("a non-finite {n} in the summary"));
    }
    // Any other number: JSON writes a non-finite one as `null`, which would not read back as a
    // summary, and the store refuses a summary that does not read.
    let text = serde_json::to_string(s).ok()?;
    let back = serde_path_to_error::deserialize::<_, Summary>(
        &mut serde_json::Deserializer::from_str(&text),
    )
    .err()?;
    Some(format!("a non-finite {} in the summary", back.path()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_are_rfc3339_utc() {
        assert_eq!(rfc3339(0), "1970-01-01T00:00:00Z");
        assert_eq!(rfc3339(1_500), "1970-01-01T00:00:01.5Z");
    }

    /// The keys of a JSON object and, one level down, of its objects (`cost.steps`).
    fn record(status: Status, error: Option<&str>) -> JobRecord {
        JobRecord {
            seq: 1,
            id: Uuid::new_v4(),
            status,
            label: None,
            case_json: "{}".into(),
            particles: 1,
            sweep_id: None,
            sweep_values_json: None,
            created_at: 0,
            started_at: None,
            finished_at: None,
            attempts: 1,
            cancel_requested: false,
            progress_json: None,
            error: error.map(str::to_string),
            node: None,
            checkpoint: None,
            owner: None,
            summary: None,
        }
    }

    #[test]
    fn the_contract_describes_the_jobs_and_summaries_the_views_serialize() {
        use crate::service::contract::tests::assert_valid;
        // Every variant of the summary's tagged parts: a diamond mode, both error bars.
        let mut s = crate::service::store::sample_summary();
        s.mode = crate::solver::CollapseMode::Diamond { lobes: 3 };
        assert_valid("Summary", &serde_json::to_value(&s).unwrap());
        // And a summary as a row stored before verdicts, shape choices and expected errors.
        s.error_bar = None;
        s.mode = crate::solver::CollapseMode::TippedOver;
        let mut older = StoredSummary::from(s);
        (older.verdict, older.shape, older.expected_error) = (None, None, None);
        assert_valid("Summary", &serde_json::to_value(&older).unwrap());

        let mut done = record(Status::Succeeded, None);
        done.summary = Some(crate::service::store::sample_summary().into());
        done.progress_json = Some(
            r#"{"step":3,"time_ms":0.1,"displacement_mm":1.0,"load_n":2.0,"fraction":0.5,"elapsed_s":1.0,"eta_s":1.0}"#
                .into(),
        );
        done.started_at = Some(1);
        done.finished_at = Some(2);
        for (r, with_case) in [(done, true), (record(Status::Queued, None), false)] {
            assert_valid(
                "Job",
                &serde_json::to_value(JobView::new(&r, with_case)).unwrap(),
            );
        }
        // A schema that describes nothing would pass everything: this one refuses a job
        // without its id.
        let mut broken =
            serde_json::to_value(JobView::new(&record(Status::Queued, None), false)).unwrap();
        broken.as_object_mut().unwrap().remove("id");
        assert!(crate::service::contract::tests::errors("Job", &broken).is_some());
    }

    #[test]
    fn a_job_that_failed_on_a_blow_up_is_not_trusted_and_other_failures_say_nothing() {
        let blow_up = "unstable at step 40 (t = 0.010000 ms): a non-finite stress at particle 7";
        let v = JobView::new(&record(Status::Failed, Some(blow_up)), false)
            .verdict
            .unwrap();
        assert_eq!(v.level, verdict::Level::NotTrusted);
        assert_eq!(v.reasons[0].rule, verdict::Rule::Unstable);
        let other = record(Status::Failed, Some("gave up after 3 attempts"));
        assert_eq!(JobView::new(&other, false).verdict, None);
        assert_eq!(
            JobView::new(&record(Status::Running, None), false).verdict,
            None
        );
    }

    #[test]
    fn a_result_stored_before_verdicts_shows_its_summary_and_a_null_verdict() {
        let mut done = record(Status::Succeeded, None);
        let mut older = StoredSummary::from(crate::service::store::sample_summary());
        older.verdict = None;
        done.summary = Some(older);
        let json = serde_json::to_value(JobView::new(&done, false)).unwrap();
        assert_eq!(json["verdict"], Value::Null);
        assert!(
            json["summary"].get("verdict").is_none(),
            "{}",
            json["summary"]
        );
        assert_eq!(json["summary"]["folds"], 3);
        done.summary = Some(crate::service::store::sample_summary().into());
        let json = serde_json::to_value(JobView::new(&done, false)).unwrap();
        assert_eq!(json["verdict"], json["summary"]["verdict"]);
        assert!(json["verdict"]["level"].is_string());
    }

    #[test]
    fn a_non_finite_number_anywhere_in_the_summary_fails_the_run() {
        let mut summary = crate::service::store::sample_summary();
        let out = |summary: Summary| RunOutput {
            history: vec![],
            summary,
            mode_detail: Default::default(),
            snapshot: Default::default(),
        };
        assert_eq!(non_finite(&out(summary.clone())), None);
        // Not one of the key numbers: JSON would store it as null, and the summary would not
        // read back (regression: the store reads summaries typed now).
        summary.kinetic_to_internal = f64::NAN;
        let why = non_finite(&out(summary)).expect("a non-finite number is caught");
        assert_eq!(why, "a non-finite kinetic_to_internal in the summary");
    }
}
