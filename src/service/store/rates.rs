//! The solver's throughput as this server measured it: per succeeded job, its model, shape
//! functions, material law, particles, steps and wall time (s), newest first, for the
//! planner's and the estimate's wall-time guesses (`solver::analysis::rates`, which decides
//! which runs are large enough to count).

use super::database::{Result, Store};
use crate::solver::analysis::rates::{LawKind, RateSample};
use crate::solver::model::case::{Material, Model, ShapeKind};
use serde_json::Value;

/// Succeeded jobs read for a calibration: the latest this many to finish. Bounds what one
/// estimate or plan reads (two short JSON documents a job).
pub const RATE_JOBS_READ: i64 = 200;

impl Store {
    /// The costs of the latest [`RATE_JOBS_READ`] succeeded jobs, newest first. A job whose
    /// summary does not say its shape functions (stored before it did), whose case's material
    /// section no longer reads, or whose wall time is not positive is left out.
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
                let material: Material = match case.get("material") {
                    None => Material::default(),
                    Some(m) => serde_json::from_value(m.clone()).ok()?,
                };
                let shape: ShapeKind =
                    serde_json::from_value(summary.pointer("/shape/kind")?.clone()).ok()?;
                let threads = summary.pointer("/cost/threads")?.as_u64()?;
                Some(RateSample {
                    model,
                    shape,
                    law: LawKind::of(&material),
                    particles: u64::try_from(particles).ok()?,
                    steps: u64::try_from(steps).ok()?,
                    wall_time_s: wall,
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
    use crate::solver::analysis::rates::{law_factor, RateBasis, Rates};
    use crate::solver::model::case::{HardeningKind, RateKind};
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
        summary.cost.particles = 10_000;
        summary.cost.steps = 1000;
        summary.cost.wall_time_s = wall_time_s;
        summary.cost.threads = threads;
        summary.shape.kind = shape;
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
        // 1e7 particle-steps each: 3D uGIMP at 2, 4 and 8 M/s on two threads (1, 2 and 4 M on
        // one), a linear 3D run and an axisymmetric one of the paper's PVC, and a linear 3D
        // run of a metal with a rate law, the newest.
        for wall in [5.0, 2.5, 1.25] {
            finished(&store, "{}", ShapeKind::Gimp, 2, wall).await;
        }
        finished(&store, "{}", ShapeKind::Linear, 1, 1.0).await;
        let axisymmetric = r#"{"discretization": {"model": "axisymmetric"}}"#;
        finished(&store, axisymmetric, ShapeKind::Gimp, 1, 10.0).await;
        let steel = r#"{"material": {"preset": "mild_steel"}}"#;
        finished(&store, steel, ShapeKind::Linear, 1, 1.0).await;

        let samples = store.rate_samples().await.unwrap();
        assert_eq!(samples.len(), 6);
        let steel = LawKind::Metal {
            hardening: HardeningKind::None,
            rate: RateKind::CowperSymonds,
        };
        assert_eq!(samples[0].law, steel, "newest first");
        assert_eq!(samples[1].model, Model::Axisymmetric);
        assert_eq!(samples[1].law, LawKind::PerfectlyPlastic);
        assert_eq!((samples[1].particles, samples[1].steps), (10_000, 1000));
        let rates = Rates::calibrated(&samples);
        let pvc = LawKind::PerfectlyPlastic;
        let close = |(r, basis): (f64, RateBasis), want: f64, runs: u32| {
            assert!((r / want - 1.0).abs() < 1e-9, "{r} against {want}");
            assert_eq!(basis, RateBasis::Measured { runs });
        };
        close(rates.rate(Model::ThreeD, ShapeKind::Gimp, pvc, 1), 2e6, 3);
        close(
            rates.rate(Model::Axisymmetric, ShapeKind::Gimp, pvc, 1),
            1e6,
            1,
        );
        // The linear runs: 10 M of PVC on one thread and 10 M of steel, which is 10 M over the
        // metal's factor at the paper's law: their median, and the metal at its factor of it.
        let steel_as_pvc = 10e6 / law_factor(Model::ThreeD, steel);
        let linear = 0.5 * (10e6 + steel_as_pvc);
        close(
            rates.rate(Model::ThreeD, ShapeKind::Linear, pvc, 3),
            3.0 * linear,
            2,
        );
        close(
            rates.rate(Model::ThreeD, ShapeKind::Linear, steel, 1),
            linear * law_factor(Model::ThreeD, steel),
            2,
        );
        assert_eq!(
            rates.rate(Model::PlaneStrain, ShapeKind::Gimp, pvc, 1).1,
            RateBasis::Assumed
        );
    }
}
