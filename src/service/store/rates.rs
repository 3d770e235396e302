//! The solver's throughput as this server measured it: per succeeded job, its model, shape
//! functions and particle-steps per second, newest first, for the planner's and the
//! estimate's wall-time guesses (`solver::analysis::rates`).

use super::{Result, Store};
use crate::solver::analysis::rates::RateSample;
use crate::solver::model::case::{Model, ShapeKind};
use serde_json::Value;

/// Succeeded jobs read for a calibration: the latest this many to finish. Bounds what one
/// estimate or plan reads (two short JSON documents a job).
pub const RATE_JOBS_READ: i64 = 200;

impl Store {
    /// The throughput of the latest [`RATE_JOBS_READ`] succeeded jobs, newest first. A job whose
    /// summary does not say its shape functions (stored before it did) or whose wall time is
    /// not positive is left out.
    pub async fn rate_samples(&self) -> Result<Vec<RateSample>> {
        let rows: Vec<(String, String, i64, i64, f64)> = sqlx::query_as(
            "SELECT j.case_json, s.summary_json, s.particles, s.steps, s.wall_time_s \
             FROM summaries s JOIN jobs j ON j.id = s.job_id \
             WHERE j.status = 'succeeded' AND s.wall_time_s > 0 \
             ORDER BY j.finished_at DESC, j.seq DESC LIMIT $1",
        )
        .bind(RATE_JOBS_READ)
        .fetch_all(&self.pool)
        .await?;
        Ok(rows
            .into_iter()
            .filter_map(|(case, summary, particles, steps, wall)| {
                let case: Value = serde_json::from_str(&case).ok()?;
                let summary: Value = serde_json::from_str(&summary).ok()?;
                let model = match case.pointer("/discretization/model") {
                    None => Model::default(),
                    Some(m) => serde_json::from_value(m.clone()).ok()?,
                };
                let shape: ShapeKind =
                    serde_json::from_value(summary.pointer("/shape/kind")?.clone()).ok()?;
                let threads = summary.pointer("/cost/threads")?.as_u64()?;
                Some(RateSample {
                    model,
                    shape,
                    particle_steps_per_s: particles as f64 * steps as f64 / wall,
                    threads: u32::try_from(threads).ok()?,
                })
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::store::{sample_summary, NewJob, Status, Succeeded};
    use crate::solver::analysis::rates::{RateBasis, Rates};
    use uuid::Uuid;

    /// Stores a succeeded job of `case_json` that ran `particles` × `steps` in `wall_time_s`
    /// on `threads` threads with `shape`.
    async fn finished(
        store: &Store,
        case_json: &str,
        shape: ShapeKind,
        threads: u32,
        wall_time_s: f64,
    ) {
        let id = Uuid::new_v4();
        let job = NewJob {
            id,
            case_json: case_json.into(),
            label: None,
            particles: 10,
            idempotency_key: None,
        };
        store.submit(job, 100).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        let mut summary = sample_summary();
        summary.cost.particles = 1000;
        summary.cost.steps = 1000;
        summary.cost.wall_time_s = wall_time_s;
        summary.cost.threads = threads;
        summary.shape.as_mut().unwrap().kind = shape;
        let result = Succeeded {
            history: &[],
            summary: &summary,
            final_state: None,
            progress_json: None,
            frames: 0,
            particles: 0,
        };
        let stored = store.finish_succeeded(id, claim.lease, result).await;
        assert_eq!(stored.unwrap(), Some(Status::Succeeded));
    }

    #[tokio::test]
    async fn rates_are_calibrated_from_the_stored_jobs_of_the_same_model_and_shape() {
        let (_dir, store) = crate::service::store::temp_store().await;
        assert!(store.rate_samples().await.unwrap().is_empty());
        // 1e6 particle-steps each: 3D uGIMP at 2, 4 and 8 M/s on two threads (1, 2 and 4 M on
        // one), a linear 3D run and an axisymmetric one.
        for wall in [0.5, 0.25, 0.125] {
            finished(&store, "{}", ShapeKind::Gimp, 2, wall).await;
        }
        finished(&store, "{}", ShapeKind::Linear, 1, 0.1).await;
        let axisymmetric = r#"{"discretization": {"model": "axisymmetric"}}"#;
        finished(&store, axisymmetric, ShapeKind::Gimp, 1, 1.0).await;

        let samples = store.rate_samples().await.unwrap();
        assert_eq!(samples.len(), 5);
        assert_eq!(samples[0].model, Model::Axisymmetric, "newest first");
        let rates = Rates::calibrated(&samples);
        assert_eq!(
            rates.rate(Model::ThreeD, ShapeKind::Gimp, 1),
            (2e6, RateBasis::Measured { runs: 3 })
        );
        assert_eq!(
            rates.rate(Model::ThreeD, ShapeKind::Linear, 3),
            (30e6, RateBasis::Measured { runs: 1 })
        );
        assert_eq!(
            rates.rate(Model::Axisymmetric, ShapeKind::Gimp, 1),
            (1e6, RateBasis::Measured { runs: 1 })
        );
        assert_eq!(
            rates.rate(Model::PlaneStrain, ShapeKind::Gimp, 1).1,
            RateBasis::Assumed
        );
    }
}
