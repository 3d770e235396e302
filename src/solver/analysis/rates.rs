//! Solver throughput for wall-time guesses, particle-steps per second: the assumed defaults by
//! model and shape function, and the rates calibrated from runs measured on this machine (the
//! median of the latest runs of the same model and shape). Pure arithmetic on what the caller
//! measured: the service reads its finished jobs, `crush bench-plan` its own runs.

use crate::solver::model::case::{Model, ShapeKind};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Runs of one model and shape function that a calibrated rate is the median of: the latest
/// ones, so that a faster solver or a busier machine shows within that many jobs.
pub const CALIBRATION_RUNS: usize = 20;

/// One finished run's throughput, as the solver measured it (`RunCost`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateSample {
    pub model: Model,
    pub shape: ShapeKind,
    /// Particles × steps over the run's wall time.
    pub particle_steps_per_s: f64,
    pub threads: u32,
}

/// What a wall-time guess was based on.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "source", rename_all = "snake_case")]
pub enum RateBasis {
    /// The median rate of this many finished runs of the same model and shape function.
    Measured { runs: u32 },
    /// No run of that model and shape function measured: the fixed rate assumed for it.
    #[default]
    Assumed,
}

/// Rates by model and shape function: the measured ones, and the defaults for the rest.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rates {
    /// (model, shape, one-thread rate, runs it is the median of).
    measured: Vec<(Model, ShapeKind, f64, u32)>,
}

impl Rates {
    /// The assumed rates alone.
    pub fn assumed() -> Rates {
        Rates::default()
    }

    /// Calibrated from `samples`, newest first: per model and shape function, the median of the
    /// latest [`CALIBRATION_RUNS`] one-thread rates (each run's rate over its threads' gain).
    /// Samples that are not finite and positive are ignored.
    pub fn calibrated(samples: &[RateSample]) -> Rates {
        let mut groups: Vec<(Model, ShapeKind, Vec<f64>)> = Vec::new();
        for s in samples {
            let one = s.particle_steps_per_s / thread_gain(s.model, s.threads);
            if !(one.is_finite() && one > 0.0) {
                continue;
            }
            match groups
                .iter_mut()
                .find(|(m, k, _)| *m == s.model && *k == s.shape)
            {
                Some((_, _, v)) if v.len() >= CALIBRATION_RUNS => {}
                Some((_, _, v)) => v.push(one),
                None => groups.push((s.model, s.shape, vec![one])),
            }
        }
        Rates {
            measured: groups
                .into_iter()
                .map(|(m, k, v)| (m, k, median(&v), v.len() as u32))
                .collect(),
        }
    }

    /// Particle-steps per second of a run of `model` with `shape` on `threads` threads, and
    /// what that figure is based on.
    pub fn rate(&self, model: Model, shape: ShapeKind, threads: u32) -> (f64, RateBasis) {
        let (one, basis) = match self
            .measured
            .iter()
            .find(|(m, k, _, _)| *m == model && *k == shape)
        {
            Some(&(_, _, r, runs)) => (r, RateBasis::Measured { runs }),
            None => (assumed_one_thread(model, shape), RateBasis::Assumed),
        };
        (one * thread_gain(model, threads), basis)
    }
}

/// A run's rate on `threads` threads over its rate on one. 3D scales with its threads (its
/// particle-to-grid runs in coloured blocks); a reduced model's section gains little past two
/// (its scatter runs in bands of 1024 particles): half again on two, nothing more.
pub fn thread_gain(model: Model, threads: u32) -> f64 {
    match model {
        Model::ThreeD => threads.max(1) as f64,
        Model::Axisymmetric | Model::PlaneStrain => 1.0 + 0.5 * (threads.clamp(1, 2) - 1) as f64,
    }
}

/// The one-thread rate assumed where none was measured, particle-steps/s. 3D: docs/validation.md
/// §1 measured 13.2–14.6 M on two threads for uGIMP from n = 4 to 10 and 20.6 M for linear shapes
/// at n = 8; the section: `crush bench-one` on the axisymmetric paper case measured 4.4 M
/// (uGIMP) and 6.6 M (linear) on one thread at n = 16; B-splines (docs/folding.md §4) 2.7 M in 3D
/// (the d = 10 tube at n = 3) and 5.5–6.4 M in the section, one thread each beside another run.
/// Rounded down to allow for a shared machine.
fn assumed_one_thread(model: Model, shape: ShapeKind) -> f64 {
    match (model, shape) {
        (Model::ThreeD, ShapeKind::Gimp) => 6.0e6,
        (Model::ThreeD, ShapeKind::Linear) => 9.0e6,
        (_, ShapeKind::Gimp) => 3.5e6,
        (_, ShapeKind::Linear) => 5.0e6,
        (Model::ThreeD, ShapeKind::Bspline) => 2.5e6,
        (_, ShapeKind::Bspline) => 3.5e6,
    }
}

/// The median of a non-empty list (the mean of the middle two for an even count).
fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(model: Model, shape: ShapeKind, rate: f64, threads: u32) -> RateSample {
        RateSample {
            model,
            shape,
            particle_steps_per_s: rate,
            threads,
        }
    }

    #[test]
    fn no_runs_give_the_assumed_rates_and_say_so() {
        let (r, basis) = Rates::calibrated(&[]).rate(Model::ThreeD, ShapeKind::Gimp, 2);
        assert_eq!(basis, RateBasis::Assumed);
        assert_eq!(r, 2.0 * assumed_one_thread(Model::ThreeD, ShapeKind::Gimp));
    }

    #[test]
    fn a_calibrated_rate_is_the_median_of_its_own_model_and_shape_per_thread() {
        let samples = [
            sample(Model::ThreeD, ShapeKind::Gimp, 10e6, 2),
            sample(Model::ThreeD, ShapeKind::Gimp, 4e6, 1),
            sample(Model::ThreeD, ShapeKind::Gimp, 24e6, 4),
            sample(Model::ThreeD, ShapeKind::Linear, 99e6, 1),
            sample(Model::Axisymmetric, ShapeKind::Gimp, 6e6, 2),
            sample(Model::ThreeD, ShapeKind::Gimp, f64::NAN, 2),
        ];
        let rates = Rates::calibrated(&samples);
        // One-thread rates 5, 4 and 6 M: the median is 5 M, doubled on two threads.
        assert_eq!(
            rates.rate(Model::ThreeD, ShapeKind::Gimp, 2),
            (10e6, RateBasis::Measured { runs: 3 })
        );
        // The section's 6 M on two threads is 4 M on one, 6 M again on two or more.
        assert_eq!(
            rates.rate(Model::Axisymmetric, ShapeKind::Gimp, 8),
            (6e6, RateBasis::Measured { runs: 1 })
        );
        assert_eq!(
            rates.rate(Model::PlaneStrain, ShapeKind::Gimp, 1).1,
            RateBasis::Assumed
        );
    }

    #[test]
    fn only_the_latest_runs_count() {
        let mut samples = vec![sample(Model::ThreeD, ShapeKind::Gimp, 1e6, 1); CALIBRATION_RUNS];
        samples.extend(vec![sample(Model::ThreeD, ShapeKind::Gimp, 9e6, 1); 50]);
        assert_eq!(
            Rates::calibrated(&samples).rate(Model::ThreeD, ShapeKind::Gimp, 1),
            (
                1e6,
                RateBasis::Measured {
                    runs: CALIBRATION_RUNS as u32
                }
            )
        );
    }
}
