//! The error bar of a run's mean load: an interval for the converged answer, and so for the
//! run's own discretization error, priced by a ladder of reduced twins. N.
//!
//! Basis: the tube's section (axisymmetric for an axial crush, plane strain for a lateral one)
//! converges in seconds, and at the same n the 3D run and its section agree within 0.2–0.5 %
//! from n = 6 on (docs/studies.md §8). So the section is run at three resolutions m, 1.5 m
//! and 2 m with m = max(n, [`LOWEST_RUNG`]) (a section's own run is the rung it matches), the
//! converged value is read off by Richardson extrapolation (or, when the ladder does not
//! converge monotonically, taken as the finest rung with the ladder's whole spread as its
//! uncertainty), and for a 3D run the interval is widened by the gap between the run and its
//! section at the same n.
//!
//! A 3D run whose collapse its section cannot fold (a diamond, a global buckle, a tube that
//! tipped over, or any axial crush of a rectangular tube) climbs a 3D ladder instead, when the
//! case asks for an error bar: the same case at n − 2 and n − 1, and the run itself at n, read
//! the same way with h = 1/n and no twin gap (the run is its own finest rung). Those rungs cost
//! ((n − 2)/n)⁴ + ((n − 1)/n)⁴ of the run (21 % at n = 3, 38 % at n = 4, 68 % at n = 6, 1.36
//! times at n = 16), from n = 4 on more than an unasked error bar may add, so it is priced only
//! when asked and an unasked run says how to ask for it instead.
//!
//! The first collapse peak ([`super::measures`]) gets an interval of its own from the same
//! rungs, read the same way ([`PeakInterval`]), when the run and every rung have one.
//!
//! It covers the resolution error of the mean load and of the first collapse peak with uGIMP
//! shape functions. It does not cover: linear shape functions (no converged answer on thin
//! walls yet), the spread over trigger.seed of a 3D run's lobes, or the model's own error
//! against a real tube (material, friction, rate).

use super::mode::CollapseMode;
use super::richardson::{richardson, Extrapolation};
use crate::solver::model::case::{Case, Limits, LoadingMode, Model, ShapeKind};
pub use crate::solver::model::ladder::LOWEST_RUNG;
use crate::solver::model::ladder::{rungs, three_d_rungs, three_d_too_coarse, THREE_D_LOWEST_N};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The error bar of a run's mean load, or why it has none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "basis", rename_all = "snake_case")]
pub enum ErrorBar {
    /// Priced by a ladder of the reduced twin.
    ReducedLadder(Ladder),
    /// Priced by coarser 3D runs of the same case (n − 2, n − 1) and the run itself, for a 3D
    /// run whose collapse its section cannot fold.
    ThreeDLadder(Ladder),
    /// No basis for this run; `why` says which.
    Unavailable { why: String },
}

/// A ladder's verdict on the converged mean load, N, and on the run's error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Ladder {
    /// The model the rungs ran in.
    pub model: Model,
    /// Each rung: n and its mean load (N) and wall time (s), coarsest first.
    pub rungs: Vec<Rung>,
    /// The best estimate of the converged mean load, N.
    pub estimate_n: f64,
    /// The converged mean load lies in [low_n, high_n] (N).
    pub low_n: f64,
    pub high_n: f64,
    /// The run's mean load against the estimate: run / estimate − 1.
    pub error: f64,
    /// The same against the interval's ends: the run's error lies in [error_low, error_high]
    /// (error_high null when the interval reaches down to zero load).
    pub error_low: f64,
    pub error_high: Option<f64>,
    /// Richardson's observed order, when the ladder converges monotonically; the estimate is
    /// the extrapolation when it is trusted (order in [0.5, 4]), else the finest rung.
    pub order: Option<f64>,
    pub extrapolated: bool,
    /// |run − twin at the same n| / estimate: what the section does not share with the run
    /// (0 for a section's own ladder, and for a 3D ladder, whose finest rung is the run).
    pub twin_gap: f64,
    /// Wall time of the rungs run for it, s, and that over the run's own.
    pub cost_s: f64,
    pub cost_fraction: f64,
    /// What the interval covers and what it does not.
    pub covers: String,
    /// The first collapse peak's interval from the same rungs; null when the run or a rung
    /// has no first peak (its load never dropped).
    pub first_peak: Option<PeakInterval>,
}

/// The first collapse peak's interval, N, read off the ladder as the mean load's is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PeakInterval {
    /// The best estimate of the converged first collapse peak, N.
    pub estimate_n: f64,
    /// The converged first peak lies in [low_n, high_n] (N).
    pub low_n: f64,
    pub high_n: f64,
    /// The run's first peak against the estimate: run / estimate − 1.
    pub error: f64,
    /// Richardson's observed order, when the rungs' peaks converge monotonically.
    pub order: Option<f64>,
    pub extrapolated: bool,
    /// |run − twin at the same n| / estimate (0 for a ladder of the run's own model).
    pub twin_gap: f64,
}

/// One rung of the ladder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Rung {
    pub n: u32,
    pub mean_load_n: f64,
    /// The rung's first collapse peak, N; null where its load never dropped.
    pub first_peak_load_n: Option<f64>,
    pub wall_time_s: f64,
}

/// One quantity read off the ladder: its estimate and interval, N.
struct Reading {
    estimate: f64,
    low: f64,
    high: f64,
    extrapolation: Option<Extrapolation>,
    trusted: bool,
    twin_gap: f64,
}

/// Reads one quantity's converged value off `values` (n, value; coarsest first; the three
/// finest are the ladder proper) for a run whose value is `run_value`: Richardson's
/// extrapolation when trusted, with the whole way from the finest rung to it as its
/// uncertainty; else the finest rung with the ladder's whole spread. The half-width adds the
/// gap between a 3D run and its twin at the same n (`twin`: the rungs ran in another model),
/// and [`MODEL_GAP_FLOOR`].
fn read(values: &[(u32, f64)], run_value: f64, run_n: u32, twin: bool) -> Reading {
    let finest = values[values.len() - 1].1;
    let ladder = &values[values.len() - 3..];
    let points: Vec<(f64, f64)> = ladder.iter().map(|&(n, v)| (1.0 / n as f64, v)).collect();
    let extrapolation = richardson(&points);
    let trusted = extrapolation.filter(|e| e.trustworthy);
    let (estimate, spread) = match trusted {
        // The extrapolation's own uncertainty is taken as the whole way from the finest rung
        // to it: generous, since a trusted order makes the remaining error far smaller.
        Some(e) => (e.value, (finest - e.value).abs()),
        None => (
            finest,
            ladder
                .iter()
                .map(|&(_, v)| (v - finest).abs())
                .fold(0.0, f64::max),
        ),
    };
    let twin_gap = match values.iter().find(|&&(n, _)| n == run_n) {
        Some(&(_, at_n)) if twin => (run_value - at_n).abs(),
        _ => 0.0,
    };
    let half = spread + twin_gap + MODEL_GAP_FLOOR * estimate.abs();
    Reading {
        estimate,
        // A crush load is the plates' push, never below zero: a spread wider than the
        // estimate reaches down to zero load, not past it.
        low: (estimate - half).max(0.0),
        high: estimate + half,
        extrapolation,
        trusted: trusted.is_some(),
        twin_gap,
    }
}

/// The first collapse peak's interval, when the run and every rung have a first peak.
fn first_peak(rungs: &[Rung], run: &Rung, twin: bool) -> Option<PeakInterval> {
    let run_peak = run.first_peak_load_n?;
    let values: Option<Vec<(u32, f64)>> = rungs
        .iter()
        .map(|r| r.first_peak_load_n.map(|p| (r.n, p)))
        .collect();
    let r = read(&values?, run_peak, run.n, twin);
    Some(PeakInterval {
        estimate_n: r.estimate,
        low_n: r.low,
        high_n: r.high,
        error: run_peak / r.estimate - 1.0,
        order: r.extrapolation.map(|e| e.order).filter(|o| o.is_finite()),
        extrapolated: r.trusted,
        twin_gap: r.twin_gap / r.estimate.abs().max(f64::MIN_POSITIVE),
    })
}

/// The floor of the interval's half-width, as a share of the estimate: the 3D run and its
/// section differ by 0.2–0.5 % at the same n once resolved, a difference no ladder of the
/// section can see; a 3D ladder keeps the same floor, as three coarse rungs can agree by
/// chance.
pub const MODEL_GAP_FLOOR: f64 = 0.005;

/// The runs a ladder climbs.
#[derive(Debug, Clone, PartialEq)]
pub enum Climb {
    /// The tube's section (reduced model) at the ladder's resolutions.
    Section,
    /// The 3D case itself at n − 2 and n − 1; `why_not_section` says why its section does not
    /// price this run.
    ThreeD { why_not_section: String },
}

/// The rungs to run for a run's error bar: what they climb, and each rung's n with its case
/// (`None` for the rung that is the run itself).
#[derive(Debug, Clone)]
pub struct Rungs {
    pub climb: Climb,
    pub rungs: Vec<(u32, Option<Case>)>,
}

/// The rungs to run for `case`, after it collapsed in `mode`: its section's ladder where the
/// section can fold that way (uGIMP), else for a 3D uGIMP or B-spline run the 3D ladder; or why
/// there is no ladder (the case's shape functions or its n).
pub fn ladder(case: &Case, mode: CollapseMode) -> Result<Rungs, String> {
    let spec = case.spec();
    let three_d = spec.discretization.model == Model::ThreeD;
    let folded_alike = matches!(mode, CollapseMode::Ring | CollapseMode::Flattening);
    let section = rungs(spec, case.shape()).and_then(|r| {
        if three_d && !folded_alike {
            return Err(format!(
                "the run collapsed as {}: its section can fold only as {}, so a ladder of the \
                 section does not price this run's error",
                mode.kind().replace('_', " "),
                match spec.loading.mode {
                    LoadingMode::Axial => "rings",
                    LoadingMode::Lateral => "a flattening",
                }
            ));
        }
        Ok(r)
    });
    let (climb, specs) = match section {
        Ok(r) => (Climb::Section, r),
        Err(why) if three_d && case.shape() != ShapeKind::Linear => {
            match three_d_rungs(spec, case.shape()) {
                Ok(r) => (
                    Climb::ThreeD {
                        why_not_section: why,
                    },
                    r,
                ),
                Err(too_coarse) => return Err(format!("{why}; {too_coarse}")),
            }
        }
        Err(why) => return Err(why),
    };
    let what = match climb {
        Climb::Section => "the section",
        Climb::ThreeD { .. } => "the 3D run",
    };
    let rungs = specs
        .into_iter()
        .map(|(k, twin)| match twin {
            None => Ok((k, None)),
            // Held to the runner's limits with the case that asked for them (`Case::parse`).
            Some(twin) => Case::parse(twin, &Limits::unbounded())
                .map(|c| (k, Some(c)))
                .map_err(|e| format!("{what} at n = {k} cannot be run: {e}")),
        })
        .collect::<Result<_, _>>()?;
    Ok(Rungs { climb, rungs })
}

/// The error bar from the rungs' results; `run` is the run's own figures as a rung at its own
/// n (`Summary::rung`); `three_d`: whether the run is 3D (else the section itself). Rungs of
/// `model` [`Model::ThreeD`] are a 3D ladder: [`ErrorBar::ThreeDLadder`].
pub fn from_rungs(model: Model, rungs: Vec<Rung>, run: &Rung, three_d: bool) -> ErrorBar {
    let run_n = run.n;
    let f = run.mean_load_n;
    let climbs_3d = model == Model::ThreeD;
    if climbs_3d && run_n < THREE_D_LOWEST_N {
        return ErrorBar::Unavailable {
            why: three_d_too_coarse(run_n),
        };
    }
    if rungs.len() < 3 {
        return ErrorBar::Unavailable {
            why: "fewer than three rungs ran".into(),
        };
    }
    // Whether the rungs ran in another model than the run: then the run is not one of them,
    // and the gap between it and its twin at the same n widens the interval.
    let twin = three_d != climbs_3d;
    let values: Vec<(u32, f64)> = rungs.iter().map(|r| (r.n, r.mean_load_n)).collect();
    let Reading {
        estimate,
        low,
        high,
        extrapolation,
        trusted,
        twin_gap,
    } = read(&values, f, run_n, twin);
    let cost_s: f64 = rungs
        .iter()
        .filter(|r| twin || r.n != run_n)
        .map(|r| r.wall_time_s)
        .sum();
    let ns = rungs
        .iter()
        .map(|r| r.n.to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let how = match (trusted, extrapolation) {
        (true, Some(e)) => format!(" extrapolated at order {:.2}", e.order),
        (_, Some(e)) => format!(
            " (Richardson not trusted, order {:.2}: the finest rung, with the ladder's spread)",
            e.order
        ),
        (_, None) => " (not monotone: the finest rung, with the ladder's spread)".into(),
    };
    let covers = if climbs_3d {
        format!(
            "the resolution error of the 3D run's mean load and first collapse peak, from 3D \
             runs of the same case at n = {ns}{how}; not the spread over trigger.seed (the \
             lobe count), or the model's error against a real tube"
        )
    } else {
        format!(
            "the resolution error of the mean load and the first collapse peak, from the {} \
             section at n = {ns}{how}; not the model's error against a real tube, or lobes",
            model.name().replace('_', " "),
        )
    };
    let ladder = Ladder {
        model,
        estimate_n: estimate,
        low_n: low,
        high_n: high,
        error: f / estimate - 1.0,
        error_low: f / high - 1.0,
        error_high: (low > 0.0).then(|| f / low - 1.0),
        order: extrapolation.map(|e| e.order).filter(|o| o.is_finite()),
        extrapolated: trusted,
        twin_gap: twin_gap / estimate.abs().max(f64::MIN_POSITIVE),
        cost_fraction: cost_s / run.wall_time_s.max(1e-9),
        cost_s,
        covers,
        first_peak: first_peak(&rungs, run, twin),
        rungs,
    };
    if climbs_3d {
        ErrorBar::ThreeDLadder(ladder)
    } else {
        ErrorBar::ReducedLadder(ladder)
    }
}

#[cfg(test)]
mod tests;
