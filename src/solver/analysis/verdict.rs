//! How far to trust a result: a verdict — trusted, caution, not trusted — with every reason
//! named. Each rule reads something a run's numbers or its case show; each has a threshold
//! that says why it is where it is, and a test that triggers it. The verdict is the worst level
//! of its reasons (no reason: trusted). Some rules can be told before a run
//! ([`foreseen`]: the form warns with them); the others need its numbers ([`of_run`]).

use super::mode::{CollapseMode, ModeDetail};
use super::reference::fold_length_mm;
use crate::solver::model::case::{Case, LoadingMode, Model, Outline, ShapeKind};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How far a result can be trusted, worst last.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "snake_case")]
#[schemars(rename = "VerdictLevel", transform = crate::solver::model::schema::choices)]
pub enum Level {
    Trusted,
    Caution,
    NotTrusted,
}

impl Level {
    /// The level as the JSON spells it.
    pub fn name(self) -> &'static str {
        match self {
            Level::Trusted => "trusted",
            Level::Caution => "caution",
            Level::NotTrusted => "not_trusted",
        }
    }
}

/// One reason a result is less than trusted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Reason {
    /// Which rule: a stable name a client can match on.
    pub rule: Rule,
    pub level: Level,
    /// The rule's finding for this result, in a sentence.
    pub detail: String,
}

/// The rules.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
pub enum Rule {
    /// A wall thickness, d/t or l/d outside every tube measured: most often a unit slip.
    ImplausibleGeometry,
    /// Too few particles through the wall to resolve its bending.
    ThinResolution,
    /// The energy books do not close.
    EnergyBalance,
    /// Inertia carries a share of the energy: not a quasi-static crush.
    NotQuasiStatic,
    /// The crush is shorter than one fold.
    TooShortToFold,
    /// The collapse mode of such a tube depends on where the trigger's weak particles fall.
    SeedSensitiveMode,
    /// The run stopped on a blow-up.
    Unstable,
    /// The tube tipped over between the plates instead of folding or bending.
    TippedOver,
    /// The load fell to zero over a stretch of the crush: the tube floated between the plates.
    Unloaded,
    /// The wall not yet folded went oval: the tube did not fold progressively with the rest
    /// of it round.
    OvalisedWall,
    /// An end ring flattened on its plate into a pouch instead of folding.
    FlattenedEnd,
    /// Linear shape functions: where the folds start, the mode and the mean load follow the
    /// wall's motion through the grid, not the load alone.
    FrameDependent,
    /// A run made faster than its test — by mass scaling, or by a plate faster than the test's
    /// speed — whose inertia carries part of the load.
    SpedUp,
    /// A thin wall in 3D with no trigger: a perfect tube, with nothing to start lobes from.
    Untriggered,
}

impl Rule {
    /// The rule as the JSON spells it.
    pub fn name(self) -> &'static str {
        match self {
            Rule::ImplausibleGeometry => "implausible_geometry",
            Rule::ThinResolution => "thin_resolution",
            Rule::EnergyBalance => "energy_balance",
            Rule::NotQuasiStatic => "not_quasi_static",
            Rule::TooShortToFold => "too_short_to_fold",
            Rule::SeedSensitiveMode => "seed_sensitive_mode",
            Rule::Unstable => "unstable",
            Rule::TippedOver => "tipped_over",
            Rule::Unloaded => "unloaded",
            Rule::OvalisedWall => "ovalised_wall",
            Rule::FlattenedEnd => "flattened_end",
            Rule::FrameDependent => "frame_dependent",
            Rule::SpedUp => "sped_up",
            Rule::Untriggered => "untriggered",
        }
    }
}

/// A result's verdict: its level and every reason for it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Verdict {
    pub level: Level,
    pub reasons: Vec<Reason>,
}

impl Verdict {
    /// The verdict of these reasons: the worst of their levels, trusted without any.
    pub fn of(reasons: Vec<Reason>) -> Verdict {
        Verdict {
            level: reasons
                .iter()
                .map(|r| r.level)
                .max()
                .unwrap_or(Level::Trusted),
            reasons,
        }
    }

    /// A run that stopped on a blow-up: not trusted, whatever it printed before, with the
    /// diagnosis.
    pub fn unstable(diagnosis: &str) -> Verdict {
        Verdict::of(vec![Reason {
            rule: Rule::Unstable,
            level: Level::NotTrusted,
            detail: format!("the run stopped on a blow-up: {diagnosis}"),
        }])
    }
}

/// The verdict of a run that failed with this message: not trusted when the run stopped on a
/// blow-up ([`SolveError::Unstable`](crate::solver::engine::SolveError), whose message starts
/// "unstable at step"); none for a failure that says nothing of the physics (a store error,
/// attempts used up).
pub fn of_failure(message: &str) -> Option<Verdict> {
    message
        .starts_with(UNSTABLE_PREFIX)
        .then(|| Verdict::unstable(message))
}

/// How the message of a blow-up starts.
const UNSTABLE_PREFIX: &str = "unstable at step";

/// Energy-balance error beyond which a result is marked caution: the paper's examples close
/// their books to 0.7–1.5 % (docs/studies.md), so 2 % is past what a sound run shows.
pub const BALANCE_CAUTION: f64 = 0.02;
/// ... and not trusted: 5 % of the plates' work unaccounted for is the size of the effects a
/// mean load is read for.
pub const BALANCE_NOT_TRUSTED: f64 = 0.05;
/// E_kin / E_int beyond which a crush is not quasi-static (caution): at the paper's 10 m/s
/// the ratio stays below 1 % after the first millimetres.
pub const KINETIC_CAUTION: f64 = 0.05;
/// ... and beyond which the load is mostly inertia's (not trusted).
pub const KINETIC_NOT_TRUSTED: f64 = 0.25;
/// E_kin / E_int beyond which a run sped up past its test (mass scaling, or a plate faster
/// than the test's speed) is not trusted. Measured with `crush run` on mass-scaled runs
/// (docs/performance.md, *Mass scaling*): the paper's tube at n 4 reads 0.41 % unscaled and
/// 0.82 % at f = 4, its mean load 0.4 % from the unscaled run's; at f = 16 it reads 2.1 %,
/// the mean 5.2 % higher and the first peak an impact at the ramp's end; the d/t 14 tube at
/// n 3 reads 0.74 % unscaled and 1.5 % at f = 4, where it folds in rings instead of lobes at
/// a mean 12 % higher. 1 % lies between the runs that kept their answer and those that lost it.
pub const SPED_UP_KINETIC: f64 = 0.01;

/// What [`Rule::SpedUp`] says of a thin wall in 3D sped up past its test, whatever its kinetic
/// energy: such a wall picks its mode in the first millimetres, where a speed-up's inertia is
/// largest, and every one measured folded otherwise (docs/performance.md, *Mass scaling*). The
/// d/t 14 PVC tube on B-splines at n 4 (μ 0.3, 0.3 % trigger), unscaled a two-lobe diamond at
/// 15.635 kN with E_kin / E_int 0.81 %, folded in rings at f = 2, 4 and 16: 18.150, 18.931 and
/// 21.057 kN (+16, +21, +35 %) with 0.98, 1.16 and 4.4 %; so the 1 % that holds a thick wall's
/// speed-up passed the f = 2 run 16 % off. On uGIMP at n 3 f = 4 gave rings at +12 %.
pub const SPED_UP_THIN_WALL: &str = "run it at its test's speed, unscaled: a thin wall in 3D \
     picks its mode in the first millimetres, where a speed-up's inertia is largest, and every \
     sped-up thin wall measured folded in rings instead of lobes, its mean load 12-35 % high, \
     one of them with kinetic energy under 1 % of the internal (docs/performance.md, Mass \
     scaling)";

/// The reasons that can be told before the case runs.
pub fn foreseen(case: &Case) -> Vec<Reason> {
    let spec = case.spec();
    let geometry = case.geometry();
    let n = geometry.layers;
    let mut reasons: Vec<Reason> = implausible(geometry).into_iter().collect();
    // One particle through the wall gives it no bending stiffness (one stress point through
    // the thickness cannot carry a moment); with two the paper's tube comes out 23 % above its
    // converged mean load (3D uGIMP, 15.31 against 12.45 kN; docs/studies.md) and with
    // three 17 %.
    if n < 2 {
        reasons.push(Reason {
            rule: Rule::ThinResolution,
            level: Level::NotTrusted,
            detail: "use discretization.particles_through_thickness 2 or more (4 or more for \
                     a mean load within about 10 %): one particle through the wall cannot \
                     bend it"
                .into(),
        });
    } else if n < 4 {
        reasons.push(Reason {
            rule: Rule::ThinResolution,
            level: Level::Caution,
            detail: format!(
                "use 4 or more particles through the wall: with {n}, the paper's tube comes \
                 out 17–23 % above its converged mean load (docs/trust.md)"
            ),
        });
    }
    if geometry.mode == LoadingMode::Axial {
        let fold = fold_length_mm(case);
        let crush = case.crush_distance_mm();
        if crush < fold {
            reasons.push(Reason {
                rule: Rule::TooShortToFold,
                level: Level::Caution,
                detail: format!(
                    "crush further than one fold (2H = {fold:.2} mm, Alexander's fold length \
                     for this wall) for a folding load: this crush ({crush:.3} mm) gives the \
                     first collapse's"
                ),
            });
        }
        // The same crush seen from a frame moving along the axis at half the plate's speed
        // (both ends then cross the grid) folds otherwise on linear shapes (the mean 10–17 %
        // apart, another mode or folding end), and nearly alike on uGIMP (0.6 % on the d/t 14
        // tube, 4.4 % on the d20; docs/folding.md §4, "Which end folds first: the grid's frame").
        if geometry.model == Model::ThreeD && case.shape() == ShapeKind::Linear {
            reasons.push(Reason {
                rule: Rule::FrameDependent,
                level: Level::Caution,
                detail: FRAME_DEPENDENT.into(),
            });
        }
        let thin = crate::solver::model::case::is_thin(&geometry.section);
        if let (Model::ThreeD, true, Some(how)) = (geometry.model, thin, sped_up(case)) {
            reasons.push(Reason {
                rule: Rule::SpedUp,
                level: Level::NotTrusted,
                detail: format!("{SPED_UP_THIN_WALL} ({how})"),
            });
        }
        if geometry.model == Model::ThreeD && thin {
            reasons.push(match spec.trigger.weak_fraction > 0.0 {
                true => Reason {
                    rule: Rule::SeedSensitiveMode,
                    level: Level::Caution,
                    detail: "run an ensemble over trigger.seed and read the distribution: a \
                             thin wall's lobe count depends on where the trigger's weak \
                             particles fall (docs/folding.md)"
                        .into(),
                },
                false => Reason {
                    rule: Rule::Untriggered,
                    level: Level::Caution,
                    detail: UNTRIGGERED.into(),
                },
            });
        }
    }
    reasons
}

/// A tube whose dimensions no tube measured has ([`plausible`]): not trusted when a slip by a
/// factor of 1000 explains it (the case is then almost surely not the tube meant, and 10⁶ or
/// 10⁹ times costlier or cheaper than it); caution otherwise, a tube outside what the closed
/// forms and the validation reach. The detail starts with what to do.
fn implausible(geometry: &crate::solver::model::geometry::Geometry) -> Option<Reason> {
    let found = plausible::check(&geometry.section, geometry.length_mm)?;
    let out = found.out.join(", ");
    let (level, detail) = match &found.slip {
        Some(slip) => (
            match slip.factor == 25.4 {
                true => Level::Caution,
                false => Level::NotTrusted,
            },
            format!(
                "check the tube's units: {} As given, {out}, outside every tube measured \
                 (docs/trust.md)",
                slip.question
            ),
        ),
        None => (
            Level::Caution,
            format!(
                "check the tube's dimensions: {out}, outside every tube measured, where no \
                 closed form or validation run reaches (docs/trust.md)"
            ),
        ),
    };
    Some(Reason {
        rule: Rule::ImplausibleGeometry,
        level,
        detail,
    })
}

/// What [`Rule::FrameDependent`] says. The runs behind it (docs/folding.md §4): the d/t 14
/// PVC tube (n 3, platen friction) folds in rings from the moving plate at 17.35 kN, and in a
/// two-lobe diamond from the fixed one at 14.95 kN when the whole scene moves along the axis at
/// 5 m/s, the same crush; uGIMP folds it alike in both frames (17.10 and 17.20 kN).
const FRAME_DEPENDENT: &str = "run with discretization.shape \"gimp\" to compare: with linear \
     shape functions, where the folds start, the mode and the mean load follow the wall's \
     motion through the grid, not the load alone (docs/folding.md §4)";

/// What [`Rule::Untriggered`] says. A thin wall picks its mode from its imperfections, and a
/// tube with no trigger has none but the grid's: the d/t 14 PVC tube on its default B-splines
/// at n 4 (μ 0.3, 10 m/s) folded in three rings at 18.473 kN with no trigger, against a
/// two-lobe diamond at 15.635 kN (+18 %) with the 0.3 % trigger (docs/studies.md §9); the
/// source's own thin tubes fold in lobes only when imperfect (docs/validation.md, Figs. 10–15).
/// Caution, not more: no test here says which mode a real tube of a given d/t takes.
const UNTRIGGERED: &str = "run it beside one with trigger.weak_fraction 0.003: with no \
     trigger a thin wall is a perfect tube, with nothing to start lobes from, where a \
     real tube's imperfections may fold it in lobes; the d/t 14 PVC tube folded in rings 18 % \
     above its triggered diamond (docs/studies.md §9)";

/// The longest stretch of plate travel with no load on the plate before a crush is marked
/// not trusted, mm: the plates close steadily, so a tube in contact carries load all the way;
/// one millimetre allows for the contact settling at the start.
pub const UNLOADED_NOT_TRUSTED_MM: f64 = 1.0;

/// How much more oval than the folds make it the unfolded wall may be, in wall thicknesses,
/// before a crush is marked with caution. The folds' own two lobes reach along an elastic tube
/// (`reference::shell`: over 39 mm on the d/t 14 PVC tube, more than a fold length), so what is
/// judged is the oval beyond that reach (`ModeDetail::unfolded_excess_two_lobe_mm`). The
/// ring-folding runs of docs/folding.md §6 read at most 0.03 t of oval; the caution starts at
/// half the wall, leaving room for the measure's own error on a slice next to a fold.
pub const OVAL_CAUTION_T: f64 = 0.5;

/// How far an end ring may spread on its plate, over the tube's radius, before a crush is
/// marked with caution (`ModeDetail::end_spread`). The folding runs of docs/folding.md keep
/// both ends within 1.18 where their ends fold (the paper's tube 0.98, the aluminium tubes
/// 1.03, the PVC tubes on μ 0.3 plates 0.94–1.18); an end flattened shut spreads to
/// π/2 ≈ 1.57, and the runs whose far end squashed into a pouch read 1.54–1.62 (the leaning,
/// lobed foot of the t 0.76 example 1.31; the d20 tube's foot on μ 0.3 plates, half as
/// spread as on μ 0.02, 1.28).
pub const END_SPREAD_CAUTION: f64 = 1.25;

/// The figures of a finished run that its verdict reads (a summary's, of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunFigures {
    pub mode: CollapseMode,
    /// The longest stretch of plate travel with the plate unloaded, mm.
    pub longest_unloaded_mm: f64,
    /// The energy books' largest relative gap over the run.
    pub energy_balance_error: f64,
    /// Largest E_kin / E_int over the second half of the crush.
    pub kinetic_to_internal: f64,
}

/// The verdict of a finished run: the foreseen reasons and those its figures and its final
/// shape (`detail`) show.
pub fn of_run(case: &Case, run: &RunFigures, detail: &ModeDetail) -> Verdict {
    let mut reasons = foreseen(case);
    let t = case.geometry().section.thickness_mm();
    let folding = matches!(run.mode, CollapseMode::Ring | CollapseMode::Diamond { .. });
    if folding && detail.unfolded_excess_two_lobe_mm > OVAL_CAUTION_T * t {
        reasons.push(Reason {
            rule: Rule::OvalisedWall,
            level: Level::Caution,
            detail: format!(
                "do not quote this mean load as a progressive crush's: the wall not yet folded \
                 went oval, {:.2} mm ({:.1} t) beyond what the folds' own ovals leave at \
                 {:.0} mm from the fixed end (over {OVAL_CAUTION_T} t; docs/folding.md §6)",
                detail.unfolded_excess_two_lobe_mm,
                detail.unfolded_excess_two_lobe_mm / t,
                detail.unfolded_excess_two_lobe_at_mm,
            ),
        });
    }
    let spread = detail.end_spread[0].max(detail.end_spread[1]);
    if folding && spread > END_SPREAD_CAUTION {
        let end = match detail.end_spread[0] >= detail.end_spread[1] {
            true => "bottom (fixed)",
            false => "top (moving)",
        };
        reasons.push(Reason {
            rule: Rule::FlattenedEnd,
            level: Level::Caution,
            detail: format!(
                "hold the ends with a platen's friction (contact.friction 0.3): the {end} end \
                 spread to {spread:.2} times the tube's radius on its plate (over \
                 {END_SPREAD_CAUTION}; flattened shut is π/2 ≈ 1.57), a pouch instead of a \
                 fold (docs/folding.md §3)"
            ),
        });
    }
    if run.mode == CollapseMode::TippedOver {
        reasons.push(Reason {
            rule: Rule::TippedOver,
            level: Level::NotTrusted,
            detail: "hold the ends with plates with friction (contact.friction 0.3) and \
                disregard this load: the tube tipped over, an end left its plate while the \
                tube stayed straight (docs/folding.md)"
                .into(),
        });
    }
    if run.longest_unloaded_mm > UNLOADED_NOT_TRUSTED_MM {
        reasons.push(Reason {
            rule: Rule::Unloaded,
            level: Level::NotTrusted,
            detail: format!(
                "disregard this load and check how the tube sits on its plates: the load \
                stayed under 1 % of its peak over {:.1} mm of plate travel",
                run.longest_unloaded_mm
            ),
        });
    }
    let e = run.energy_balance_error;
    if let Some((level, over)) = graded(e, BALANCE_CAUTION, BALANCE_NOT_TRUSTED) {
        reasons.push(Reason {
            rule: Rule::EnergyBalance,
            level,
            detail: format!(
                "set discretization.cfl {} (half the case's) to roughly halve the error at \
                 twice the steps: the energy books close to {:.1} % of the plates' work (over \
                 {:.0} % is {}; docs/folding.md §5, `crush study step` measures it)",
                0.5 * case.cfl(),
                100.0 * e,
                100.0 * over,
                level.name().replace('_', " "),
            ),
        });
    }
    let k = run.kinetic_to_internal;
    let foreseen_speed_up = reasons.iter().any(|r| r.rule == Rule::SpedUp);
    if let Some(how) = sped_up(case) {
        if k > SPED_UP_KINETIC && !foreseen_speed_up {
            reasons.push(Reason {
                rule: Rule::SpedUp,
                level: Level::NotTrusted,
                detail: format!(
                    "lower the speed-up ({how}): kinetic energy reaches {:.0} % of the \
                     internal energy in the second half of the crush (over {:.0} %), so \
                     inertia carries part of the load",
                    100.0 * k,
                    100.0 * SPED_UP_KINETIC
                ),
            });
        }
    } else if let Some((level, _)) = graded(k, KINETIC_CAUTION, KINETIC_NOT_TRUSTED) {
        reasons.push(Reason {
            rule: Rule::NotQuasiStatic,
            level,
            detail: format!(
                "slow the plate or lengthen the crush: kinetic energy reaches {:.0} % of the \
                 internal energy in the second half of the crush, so inertia carries part of \
                 the load",
                100.0 * k
            ),
        });
    }
    Verdict::of(reasons)
}

/// How a case runs faster than its test, if it does: its mass scaling, its plate faster than
/// the test's speed, or both, as the reason names them.
fn sped_up(case: &Case) -> Option<String> {
    let spec = case.spec();
    let f = spec.discretization.mass_scaling;
    let l = &spec.loading;
    let mut how = Vec::new();
    if f > 1.0 {
        how.push(format!("discretization.mass_scaling {f}"));
    }
    if let Some(test) = l.test_speed_m_s.filter(|t| *t < l.plate_speed_m_s) {
        how.push(format!(
            "the plate at {} m/s for a test at {test} m/s",
            l.plate_speed_m_s
        ));
    }
    (!how.is_empty()).then(|| how.join(", "))
}

/// The level of a figure with two thresholds, and the threshold it passed: none at or below
/// `caution`, caution up to `not_trusted`, not trusted beyond.
fn graded(value: f64, caution: f64, not_trusted: f64) -> Option<(Level, f64)> {
    if value > not_trusted {
        Some((Level::NotTrusted, not_trusted))
    } else if value > caution {
        Some((Level::Caution, caution))
    } else {
        None
    }
}

pub mod plausible;

#[cfg(test)]
mod tests;
