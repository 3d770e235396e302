//! One harness for every caller of the solver — `crush run`, the studies, the bench and the
//! server's workers: a case run on a rayon pool of its own, so that a run uses the threads it
//! was given whatever else the process runs, and its results do not depend on them (every sum
//! of a step runs in a fixed order).

use super::analysis::error_bar::{self, Climb, ErrorBar, Rung};
use super::analysis::estimate::{
    error_bar_cost_fraction, three_d_ladder_cost_fraction, UNASKED_ERROR_BAR_FRACTION,
};
use super::engine::scene::Scene;
use super::model::case::Model;
use super::{Case, Observer, Resume, RunOutput, RungProgress, SolveError};
use std::sync::atomic::AtomicBool;

/// The machine's cores (1 when it cannot tell).
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// A pool of solver threads that runs cases.
pub struct Runner {
    pool: rayon::ThreadPool,
}

impl Runner {
    /// A pool of `threads` solver threads (0: one per core), the i-th named `name(i)`.
    pub fn new(
        threads: usize,
        name: impl Fn(usize) -> String + Send + Sync + 'static,
    ) -> Result<Runner, rayon::ThreadPoolBuildError> {
        let threads = if threads == 0 { cores() } else { threads };
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(name)
            .build()
            .map(|pool| Runner { pool })
    }

    /// Solver threads in the pool.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// [`super::run`] on the pool.
    pub fn run(
        &self,
        case: &Case,
        observer: &mut (dyn Observer + Send),
        cancel: &AtomicBool,
    ) -> Result<RunOutput, SolveError> {
        self.pool.install(|| super::run(case, observer, cancel))
    }

    /// [`super::resume`] on the pool, or [`super::run`] without a checkpoint.
    pub fn resume(
        &self,
        case: &Case,
        from: Option<Resume>,
        observer: &mut (dyn Observer + Send),
        cancel: &AtomicBool,
    ) -> Result<RunOutput, SolveError> {
        self.pool.install(|| match from {
            Some(from) => super::resume(case, from, observer, cancel),
            None => super::run(case, observer, cancel),
        })
    }

    /// [`super::run_scene`] on the pool, with the scene built from `case` and then changed by
    /// `change` on the pool's thread.
    pub fn run_changed(
        &self,
        case: &Case,
        change: impl FnOnce(&mut Scene) + Send,
        observer: &mut (dyn Observer + Send),
        cancel: &AtomicBool,
    ) -> Result<RunOutput, SolveError> {
        self.pool.install(|| {
            let mut scene = Scene::from_case(case);
            change(&mut scene);
            super::run_scene(case, scene, observer, cancel)
        })
    }

    /// Whether a run of `case` may price its error bar after it: the case asks for one, or its
    /// ladder costs at most [`UNASKED_ERROR_BAR_FRACTION`] of the run (the run's summary can
    /// still show that it has no ladder).
    pub fn may_price_error_bar(case: &Case) -> bool {
        case.spec().output.error_bar
            || error_bar_cost_fraction(case).is_some_and(|f| f <= UNASKED_ERROR_BAR_FRACTION)
    }

    /// The run's error bar ([`error_bar`]), or why it has none, in the output's summary: its
    /// reduced twin run at the ladder's resolutions on the pool when the case asks for it
    /// (`output.error_bar`) or when that costs at most [`UNASKED_ERROR_BAR_FRACTION`] of the
    /// run; else the summary says why not (no ladder for this run, or what it would cost). A
    /// 3D ladder ([`Climb::ThreeD`]) is priced only when asked: from n = 4 on it costs more
    /// than that.
    /// `ladder` is told each rung's progress and result, and hands back the rungs an earlier
    /// attempt finished, which are not run again.
    pub fn add_error_bar_if_asked(
        &self,
        case: &Case,
        out: &mut RunOutput,
        ladder: &mut (dyn LadderObserver + Send),
        cancel: &AtomicBool,
    ) -> Result<(), SolveError> {
        if case.spec().output.error_bar {
            return self.add_error_bar(case, out, ladder, cancel);
        }
        match error_bar::ladder(case, out.summary.mode) {
            Err(why) => {
                out.summary.error_bar = Some(ErrorBar::Unavailable { why });
                return Ok(());
            }
            Ok(error_bar::Rungs {
                climb: Climb::ThreeD { why_not_section },
                rungs,
            }) => {
                let coarser: Vec<String> = rungs
                    .iter()
                    .filter(|(_, c)| c.is_some())
                    .map(|(k, _)| k.to_string())
                    .collect();
                let cost = three_d_ladder_cost_fraction(case).map_or_else(String::new, |f| {
                    format!(" for about {:.0} % of this run's time", 100.0 * f)
                });
                out.summary.error_bar = Some(ErrorBar::Unavailable {
                    why: format!(
                        "{why_not_section}; not priced: a 3D ladder (this case at n = {}) \
                         would price it{cost}, and is priced only when asked; set \
                         output.error_bar to price it",
                        coarser.join(" and "),
                    ),
                });
                return Ok(());
            }
            Ok(_) => {}
        }
        match error_bar_cost_fraction(case) {
            Some(f) if f <= UNASKED_ERROR_BAR_FRACTION => {
                self.add_error_bar(case, out, ladder, cancel)?
            }
            Some(f) => {
                out.summary.error_bar = Some(ErrorBar::Unavailable {
                    why: format!(
                        "not priced: its section at three resolutions would cost about {f:.1} \
                         times this run (unasked, an error bar may add {:.0} %); set \
                         output.error_bar to price it",
                        100.0 * UNASKED_ERROR_BAR_FRACTION
                    ),
                })
            }
            None => {}
        }
        Ok(())
    }

    /// The run's error bar whether or not the case asked for it (see
    /// [`Runner::add_error_bar_if_asked`]).
    pub fn add_error_bar(
        &self,
        case: &Case,
        out: &mut RunOutput,
        ladder: &mut (dyn LadderObserver + Send),
        cancel: &AtomicBool,
    ) -> Result<(), SolveError> {
        let bar = match error_bar::ladder(case, out.summary.mode) {
            Err(why) => ErrorBar::Unavailable { why },
            Ok(error_bar::Rungs { rungs, .. }) => {
                let total = rungs.len();
                let mut done = Vec::with_capacity(total);
                let mut model = None;
                for (index, (n, twin)) in rungs.into_iter().enumerate() {
                    let rung = match twin {
                        Some(twin) => {
                            model = Some(twin.spec().discretization.model);
                            match ladder.done(index, n) {
                                Some(rung) => rung,
                                None => {
                                    let mut rung_observer = RungObserver {
                                        ladder: &mut *ladder,
                                        at: RungProgress {
                                            rung: index as u32 + 1,
                                            rungs: total as u32,
                                            n,
                                            fraction: 0.0,
                                        },
                                    };
                                    let summary =
                                        self.run(&twin, &mut rung_observer, cancel)?.summary;
                                    let rung = summary.rung(n);
                                    ladder.on_rung(index, &rung);
                                    rung
                                }
                            }
                        }
                        None => out.summary.rung(n),
                    };
                    done.push(rung);
                }
                let three_d = case.spec().discretization.model == Model::ThreeD;
                let model = model.unwrap_or(case.spec().discretization.model);
                let n = case.spec().discretization.particles_through_thickness;
                error_bar::from_rungs(model, done, &out.summary.rung(n), three_d)
            }
        };
        out.summary.error_bar = Some(bar);
        Ok(())
    }

    /// Anything else on the pool (the bench's timed steps).
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.pool.install(f)
    }
}

/// What the pricing of a run's error bar tells as it goes, and the rungs it need not run again.
/// Every method defaults to nothing.
pub trait LadderObserver {
    /// Rung `index` (from 0, at `n` particles through the wall) as an earlier attempt finished
    /// it: it is not run again.
    fn done(&self, _index: usize, _n: u32) -> Option<Rung> {
        None
    }
    /// How far the rung that runs is, once per history row of its run.
    fn on_rung_progress(&mut self, _progress: &RungProgress) {}
    /// Rung `index` (from 0) is done.
    fn on_rung(&mut self, _index: usize, _rung: &Rung) {}
}

impl LadderObserver for () {}

/// A rung's run observed for its ladder: its progress, as the ladder's.
struct RungObserver<'a> {
    ladder: &'a mut (dyn LadderObserver + Send),
    at: RungProgress,
}

impl Observer for RungObserver<'_> {
    fn on_progress(&mut self, progress: &super::Progress) {
        self.at.fraction = progress.fraction;
        self.ladder.on_rung_progress(&self.at);
    }
}

#[cfg(test)]
mod tests;
