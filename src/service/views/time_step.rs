//! A sweep over `discretization.cfl` as the API shows it: per group of the other swept values,
//! the time-step analysis of its finished runs (`crate::study::step`), the cheapest step within
//! 2 % of the best estimate of the mean load (least wall time), and the step from which on the books close within
//! the verdict's 2 %. Loads in N, time in s.

use super::formats::{json, key_without};
use crate::service::store::{JobRecord, Status};
use crate::solver::analysis::verdict::BALANCE_CAUTION;
use crate::study::step::{StepAnalysis, StepPoint, STEP_FIELD};
use schemars::JsonSchema;
use serde::Serialize;
use serde_json::Value;

/// The mean-load error the view reads the cheapest step off for, as `crush study step` does.
pub const STEP_TOLERANCE: f64 = 0.02;

/// One group of a time-step sweep: the runs that differ only in `discretization.cfl`.
#[derive(Debug, Serialize, JsonSchema)]
pub struct StepGroupView {
    /// The other swept values, `field=value, …` (empty when only the step varies).
    pub group: String,
    /// Null until a run of the group has succeeded.
    pub analysis: Option<StepAnalysis>,
    /// The step of least wall time whose mean load, and every smaller step's, is within 2 % of
    /// the Richardson value (when trusted) or of the smallest step's; null when none is.
    pub cfl_within_2_percent: Option<f64>,
    /// The largest step from which on the energy books close within 2 %; null when none does.
    pub cfl_books_within_2_percent: Option<f64>,
}

/// The groups of a time-step sweep, in order of first appearance.
pub(super) fn time_steps(fields: &[String], jobs: &[JobRecord]) -> Vec<StepGroupView> {
    let mut groups: Vec<(String, Vec<StepPoint>)> = Vec::new();
    for j in jobs {
        let values = json(j.sweep_values_json.as_deref()).unwrap_or(Value::Null);
        let key = key_without(fields, &values, STEP_FIELD);
        let index = match groups.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                groups.push((key, Vec::new()));
                groups.len() - 1
            }
        };
        let point = (j.status == Status::Succeeded)
            .then_some(())
            .and(j.summary.as_ref())
            .zip(values.get(STEP_FIELD).and_then(Value::as_f64))
            .map(|(s, cfl)| StepPoint::of(cfl, &s.figures()));
        groups[index].1.extend(point);
    }
    groups
        .into_iter()
        .map(|(group, points)| {
            let analysis = StepAnalysis::of(&points);
            let read = |f: &dyn Fn(&StepAnalysis) -> Option<f64>| analysis.as_ref().and_then(f);
            StepGroupView {
                cfl_within_2_percent: read(&|a| {
                    a.cheapest_within(STEP_TOLERANCE).map(|r| r.run.cfl)
                }),
                cfl_books_within_2_percent: read(&|a| {
                    a.books_within(BALANCE_CAUTION).map(|r| r.run.cfl)
                }),
                group,
                analysis,
            }
        })
        .collect()
}
