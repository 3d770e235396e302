//! Solver throughput for wall-time guesses, particle-steps per second: the assumed defaults by
//! model, shape function and material law, and the rates calibrated from runs measured on this
//! machine (the median of the latest runs of the same model and shape, each over its law's
//! factor). Pure arithmetic on what the caller measured: the service reads its finished jobs,
//! `crush bench-plan` its own runs.

use crate::solver::model::case::{Model, ShapeKind};
use crate::solver::model::material::given::{HardeningKind, Material, MaterialModel, RateKind};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Runs of one model and shape function that a calibrated rate is the median of: the latest
/// ones, so that a faster solver or a busier machine shows within that many jobs.
pub const CALIBRATION_RUNS: usize = 20;

/// The fewest particles of a run that calibrates a rate. A step costs 15–210 µs besides its
/// particles, 70 µs in the median (README's smoke case, 66 particles, took 3.1–16 ms for its 66
/// steps, 6.9 ms in the median: `crush run`, one thread, five runs on a 2-core machine shared
/// with other builds), 3 % of a step of this many particles at 2 M particle-steps/s and 8 % at
/// most: below that, a run's rate says more of those costs than of its particles.
pub const CALIBRATION_MIN_PARTICLES: u64 = 5_000;

/// The fewest steps of a run that calibrates a rate: building the grid and the particles' books
/// takes about as long as 16 steps (33 155 particles: 3.65 s for 242 steps and 10.4 s for 719 on
/// one thread, medians of three runs, 14 ms a step and 0.23 s besides), 3 % of a run of this
/// many.
pub const CALIBRATION_MIN_STEPS: u64 = 500;

/// One finished run's cost, as the solver measured it (`RunCost`), with what sets its rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateSample {
    pub model: Model,
    pub shape: ShapeKind,
    pub law: LawKind,
    pub particles: u64,
    pub steps: u64,
    /// The run's wall time, s.
    pub wall_time_s: f64,
    pub threads: u32,
}

impl RateSample {
    /// Particles × steps over the wall time.
    pub fn particle_steps_per_s(&self) -> f64 {
        self.particles as f64 * self.steps as f64 / self.wall_time_s
    }

    /// Whether the run is large enough for its rate to be its particles' (at least
    /// [`CALIBRATION_MIN_PARTICLES`] and [`CALIBRATION_MIN_STEPS`]).
    pub fn calibrates(&self) -> bool {
        self.particles >= CALIBRATION_MIN_PARTICLES && self.steps >= CALIBRATION_MIN_STEPS
    }
}

/// What a material law costs a step, by the work its stress update does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawKind {
    /// Linear elastic.
    Elastic,
    /// J2 with a constant yield stress: a closed-form radial return, four particles at once
    /// (the paper's PVC, `aa6060_t5`).
    PerfectlyPlastic,
    /// J2 with a hardening or a rate law: the flow stress evaluated for every particle and a
    /// Newton iteration for each yielding one, a particle at a time.
    Metal {
        hardening: HardeningKind,
        rate: RateKind,
    },
}

impl LawKind {
    /// The kind of the law a case's material section names (as `MaterialLaw::of` chooses it).
    pub fn of(m: &Material) -> LawKind {
        match m.model {
            MaterialModel::Elastic => LawKind::Elastic,
            MaterialModel::J2 if m.hardening == HardeningKind::None && m.rate == RateKind::None => {
                LawKind::PerfectlyPlastic
            }
            MaterialModel::J2 => LawKind::Metal {
                hardening: m.hardening,
                rate: m.rate,
            },
        }
    }
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
    /// (model, shape, one-thread rate of the paper's law, runs it is the median of).
    measured: Vec<(Model, ShapeKind, f64, u32)>,
}

impl Rates {
    /// The assumed rates alone.
    pub fn assumed() -> Rates {
        Rates::default()
    }

    /// Calibrated from `samples`, newest first: per model and shape function, the median of the
    /// latest [`CALIBRATION_RUNS`] one-thread rates (each run's rate over its threads' gain and
    /// its law's factor), of the runs large enough ([`RateSample::calibrates`]). Samples whose
    /// rate is not finite and positive are ignored.
    pub fn calibrated(samples: &[RateSample]) -> Rates {
        let mut groups: Vec<(Model, ShapeKind, Vec<f64>)> = Vec::new();
        for s in samples.iter().filter(|s| s.calibrates()) {
            let one = s.particle_steps_per_s()
                / thread_gain(s.model, s.threads)
                / law_factor(s.model, s.law);
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

    /// Particle-steps per second of a run of `model` with `shape` and a law of `law` on
    /// `threads` threads, and what that figure is based on.
    pub fn rate(
        &self,
        model: Model,
        shape: ShapeKind,
        law: LawKind,
        threads: u32,
    ) -> (f64, RateBasis) {
        let (one, basis) = match self
            .measured
            .iter()
            .find(|(m, k, _, _)| *m == model && *k == shape)
        {
            Some(&(_, _, r, runs)) => (r, RateBasis::Measured { runs }),
            None => (assumed_one_thread(model, shape), RateBasis::Assumed),
        };
        (
            one * law_factor(model, law) * thread_gain(model, threads),
            basis,
        )
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

/// A law's rate over the paper's (perfectly plastic J2, which `aa6060_t5` shares) in the same
/// model: a metal's law evaluates its flow stress for every particle, a particle at a time, and
/// iterates for each yielding one. One law (a hardening or a rate law) 0.7, or 0.6 with
/// Cowper–Symonds' rate (0.5 in a section); with both a hardening and a rate law, 0.85 of that.
/// Measured on the cases `python3 scripts/rates.py --shapes gimp --crush-mm 1` runs (its case:
/// the AA6060 tube of t 1.67, d 48.33 at l 20 in 3D, n 3, 29 448 particles, about 2 000 steps),
/// one thread, the laws run in turn on a 2-core machine shared with other builds (load average
/// 3): over `aa6060_t5`'s 2.63 M particle-steps/s (PVC's 2.75 M), Ludwik alone 0.72, Swift alone
/// 0.68, Johnson–Cook alone 0.62, Cowper–Symonds alone (`mild_steel`) 0.61, Ludwik and
/// Johnson–Cook (`aa6061_t6`) 0.60, Swift and Cowper–Symonds (`stainless_304`) 0.50; an elastic
/// wall of PVC's constants 1.15 of PVC's. In the section, `docs/materials/al6060_dt25.json`
/// crushed 10 mm (`--crush-mm 10 --shapes gimp`, 760 particles, about 17 000 steps):
/// `mild_steel` 0.51, `stainless_304` 0.41, `aa6061_t6` 0.70 of `aa6060_t5`'s 3.1–4.2 M (two
/// runs). A tabulated hardening curve, and the section's laws not named here, were not
/// measured: they take the factor of their kind.
pub fn law_factor(model: Model, law: LawKind) -> f64 {
    match law {
        LawKind::PerfectlyPlastic => 1.0,
        LawKind::Elastic => 1.15,
        LawKind::Metal { hardening, rate } => {
            let one = match (model, rate) {
                (Model::ThreeD, RateKind::CowperSymonds) => 0.6,
                (_, RateKind::CowperSymonds) => 0.5,
                _ => 0.7,
            };
            if hardening != HardeningKind::None && rate != RateKind::None {
                0.85 * one
            } else {
                one
            }
        }
    }
}

/// The one-thread rate of the paper's law assumed where none was measured, particle-steps/s:
/// a 2-core AMD EPYC, idle, release build. 3D: `crush bench --n 6 --threads 2 --repeats 3
/// --steps 60` gave medians of 8.31 M (linear) and 5.62 M (uGIMP) on two threads, and whole
/// 8 mm crushes of the AA6060-T5 tube (d 48.33, t 1.67, n 3) 7.99 M (linear) and 4.94 M (uGIMP,
/// μ 0.3); the section: the README's first run (axisymmetric, n 6) 3.33 M on two threads.
/// B-splines in 3D: the whole 60 mm crush of the d/t 14 tube at n 4 (110 528 particles, the
/// same machine idle) ran 4.91 M on two threads, a particle-step 1.1 times uGIMP's
/// (docs/folding.md §4); in the section, scaled from uGIMP by their ratio on a faster machine
/// (5.5 against 4.4 M). Rounded down: a faster machine sees
/// shorter runs than these say, and a server calibrates on its own runs.
fn assumed_one_thread(model: Model, shape: ShapeKind) -> f64 {
    match (model, shape) {
        (Model::ThreeD, ShapeKind::Gimp) => 2.6e6,
        (Model::ThreeD, ShapeKind::Linear) => 4.0e6,
        (_, ShapeKind::Gimp) => 2.2e6,
        (_, ShapeKind::Linear) => 3.1e6,
        (Model::ThreeD, ShapeKind::Bspline) => 2.4e6,
        (_, ShapeKind::Bspline) => 2.2e6,
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
    use crate::solver::model::material::given::Preset;

    /// A run of 10 000 particles × 1 000 steps (large enough to calibrate) at `rate`.
    fn sample(model: Model, shape: ShapeKind, rate: f64, threads: u32) -> RateSample {
        RateSample {
            model,
            shape,
            law: LawKind::PerfectlyPlastic,
            particles: 10_000,
            steps: 1_000,
            wall_time_s: 1e7 / rate,
            threads,
        }
    }

    /// `rate` at the paper's law, on one thread.
    fn pvc(rates: &Rates, model: Model, shape: ShapeKind, threads: u32) -> (f64, RateBasis) {
        rates.rate(model, shape, LawKind::PerfectlyPlastic, threads)
    }

    #[test]
    fn no_runs_give_the_assumed_rates_and_say_so() {
        let (r, basis) = pvc(&Rates::calibrated(&[]), Model::ThreeD, ShapeKind::Gimp, 2);
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
        let (r, basis) = pvc(&rates, Model::ThreeD, ShapeKind::Gimp, 2);
        assert!((r / 10e6 - 1.0).abs() < 1e-12, "{r}");
        assert_eq!(basis, RateBasis::Measured { runs: 3 });
        // The section's 6 M on two threads is 4 M on one, 6 M again on two or more.
        let (r, basis) = pvc(&rates, Model::Axisymmetric, ShapeKind::Gimp, 8);
        assert!((r / 6e6 - 1.0).abs() < 1e-12, "{r}");
        assert_eq!(basis, RateBasis::Measured { runs: 1 });
        assert_eq!(
            pvc(&rates, Model::PlaneStrain, ShapeKind::Gimp, 1).1,
            RateBasis::Assumed
        );
    }

    #[test]
    fn only_the_latest_runs_count() {
        let mut samples = vec![sample(Model::ThreeD, ShapeKind::Gimp, 1e6, 1); CALIBRATION_RUNS];
        samples.extend(vec![sample(Model::ThreeD, ShapeKind::Gimp, 9e6, 1); 50]);
        let (r, basis) = pvc(
            &Rates::calibrated(&samples),
            Model::ThreeD,
            ShapeKind::Gimp,
            1,
        );
        assert!((r / 1e6 - 1.0).abs() < 1e-12, "{r}");
        assert_eq!(
            basis,
            RateBasis::Measured {
                runs: CALIBRATION_RUNS as u32
            }
        );
    }

    /// What broke: README's 66-particle smoke jobs (66 steps in 3–16 ms, 0.3–1.4 M
    /// particle-steps/s, against 6 M assumed) set the server's 3D rate, and the default case was
    /// estimated at 11 minutes where it takes under one. Runs too small to say their
    /// particles' rate leave the rate alone; a large run beside them sets it.
    #[test]
    fn tiny_runs_do_not_set_a_rate() {
        let smoke = RateSample {
            model: Model::ThreeD,
            shape: ShapeKind::Gimp,
            law: LawKind::PerfectlyPlastic,
            particles: 66,
            steps: 66,
            wall_time_s: 0.008,
            threads: 1,
        };
        let few_steps = RateSample {
            particles: 50_000,
            steps: 100,
            wall_time_s: 3.0,
            ..smoke
        };
        assert!(!smoke.calibrates() && !few_steps.calibrates());
        let tiny = vec![smoke; 100];
        let rates = Rates::calibrated(&tiny);
        assert_eq!(
            rates.rate(Model::ThreeD, ShapeKind::Gimp, LawKind::PerfectlyPlastic, 2),
            Rates::assumed().rate(Model::ThreeD, ShapeKind::Gimp, LawKind::PerfectlyPlastic, 2)
        );
        let mut mixed = vec![smoke, few_steps, smoke];
        mixed.push(sample(Model::ThreeD, ShapeKind::Gimp, 3e6, 1));
        assert_eq!(
            pvc(
                &Rates::calibrated(&mixed),
                Model::ThreeD,
                ShapeKind::Gimp,
                1
            ),
            (3e6, RateBasis::Measured { runs: 1 })
        );
    }

    #[test]
    fn the_law_sets_its_kind_and_its_factor_scales_both_rates() {
        let law = |preset| LawKind::of(&preset_material(preset));
        assert_eq!(law(Preset::Pvc), LawKind::PerfectlyPlastic);
        assert_eq!(law(Preset::Aa6060T5), LawKind::PerfectlyPlastic);
        let metal = |hardening, rate| LawKind::Metal { hardening, rate };
        use {HardeningKind as H, RateKind as R};
        assert_eq!(law(Preset::Aa6061T6), metal(H::Ludwik, R::JohnsonCook));
        assert_eq!(law(Preset::MildSteel), metal(H::None, R::CowperSymonds));
        assert_eq!(law(Preset::Stainless304), metal(H::Swift, R::CowperSymonds));
        let elastic = Material {
            model: MaterialModel::Elastic,
            ..Material::default()
        };
        assert_eq!(LawKind::of(&elastic), LawKind::Elastic);

        // A steel run of 2 M calibrates the paper's law at 2 M over the steel's factor, and a
        // steel case is then timed at 2 M again.
        let model = Model::ThreeD;
        let steel = law(Preset::MildSteel);
        let run = RateSample {
            law: steel,
            ..sample(model, ShapeKind::Linear, 2e6, 1)
        };
        let rates = Rates::calibrated(&[run]);
        let (r, _) = pvc(&rates, model, ShapeKind::Linear, 1);
        assert!((r * law_factor(model, steel) / 2e6 - 1.0).abs() < 1e-12);
        let (r, _) = rates.rate(model, ShapeKind::Linear, steel, 1);
        assert!((r / 2e6 - 1.0).abs() < 1e-12, "{r}");
        for model in [Model::ThreeD, Model::Axisymmetric] {
            for hardening in [H::None, H::Table, H::Swift, H::Ludwik] {
                for rate in [R::None, R::CowperSymonds, R::JohnsonCook] {
                    let f = law_factor(model, metal(hardening, rate));
                    assert!(f > 0.0 && f <= 1.0, "{hardening:?} {rate:?}: {f}");
                }
            }
            for law in [LawKind::Elastic, steel] {
                let f = law_factor(model, law);
                assert!(f > 0.0 && f.is_finite(), "{model:?} {law:?}: {f}");
                let (r, _) = Rates::assumed().rate(model, ShapeKind::Gimp, law, 1);
                assert_eq!(r, f * assumed_one_thread(model, ShapeKind::Gimp));
            }
        }
    }

    fn preset_material(preset: Preset) -> Material {
        serde_json::from_value(serde_json::json!({ "preset": preset.name() })).unwrap()
    }
}
