//! Each check of the suite read off its scene's run: ours (with its error bar and verdict), the
//! reference, their ratio and whether ours lies in the band. Units: kN, %. Imports `suite.rs`
//! and `cache.rs` of the validate folder.

use super::cache::Entry;
use super::suite::{parse, Band, Check, Group, Kind, Quantity, RefValue, Scene};
use crate::solver::analysis::error_bar::ErrorBar;
use crate::solver::{estimate, CollapseMode};
use std::collections::BTreeMap;

/// Where a check came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    InBand,
    OutOfBand,
    /// Shown beside ours, not judged.
    Shown,
    /// The scene did not run (it stopped, or this profile leaves it out).
    Missing,
}

impl Status {
    pub fn mark(self) -> &'static str {
        match self {
            Status::InBand => "in band",
            Status::OutOfBand => "OUT OF BAND",
            Status::Shown => "shown",
            Status::Missing => "not run",
        }
    }
}

/// One check, read.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    pub scene: String,
    pub group: Group,
    pub figure: String,
    pub quantity: Quantity,
    /// Ours as a number in the quantity's unit (a mode: none).
    pub ours: Option<f64>,
    /// Ours as printed, with its error bar where the run has one.
    pub ours_text: String,
    pub verdict: String,
    pub reference: Option<f64>,
    pub reference_text: String,
    pub kind: Kind,
    pub source: String,
    pub ratio: Option<f64>,
    pub band: String,
    pub reason: String,
    pub status: Status,
}

/// A mode as the report prints it: `ring`, `diamond 2`, `global_buckling`.
pub fn mode_text(m: &CollapseMode) -> String {
    match m {
        CollapseMode::Diamond { lobes } => format!("diamond {lobes}"),
        other => other.kind().to_string(),
    }
}

/// The verdict's level, and its rules where it is not trusted.
pub fn verdict_text(e: &Entry) -> String {
    let v = &e.summary.verdict;
    let rules: Vec<&str> = v
        .reasons
        .iter()
        .filter(|r| r.level != crate::solver::analysis::verdict::Level::Trusted)
        .map(|r| r.rule.name())
        .collect();
    match rules.is_empty() {
        true => v.level.name().to_string(),
        false => format!("{} ({})", v.level.name(), rules.join(", ")),
    }
}

/// The mean load's error bar as printed: the interval the converged load lies in, kN, or why
/// there is none.
pub fn error_bar_text(e: &Entry) -> String {
    let expected = e
        .summary
        .expected_error
        .percent
        .map(|p| format!("expected ±{p:.1} %"));
    match &e.summary.error_bar {
        Some(ErrorBar::ReducedLadder(l) | ErrorBar::ThreeDLadder(l)) => {
            format!("converged in [{:.2}, {:.2}]", l.low_n / 1e3, l.high_n / 1e3)
        }
        _ => expected.unwrap_or_else(|| "no error bar".into()),
    }
}

/// The mean load's error bar as an interval, kN: where a ladder gave one.
fn interval_kn(e: &Entry) -> Option<(f64, f64)> {
    match &e.summary.error_bar {
        Some(ErrorBar::ReducedLadder(l) | ErrorBar::ThreeDLadder(l)) => {
            Some((l.low_n / 1e3, l.high_n / 1e3))
        }
        _ => None,
    }
}

/// The quantity of a run, as a number (none for a mode, or a first peak the load never gave).
fn value(q: Quantity, scene: &Scene, e: Option<&Entry>) -> Option<f64> {
    if q == Quantity::Particles {
        return parse(&scene.case).map(|c| estimate(&c, 1).particles as f64);
    }
    let s = &e?.summary;
    match q {
        Quantity::MeanLoadKn => Some(s.mean_load_n / 1e3),
        Quantity::FirstPeakKn => s.measures.first_peak_load_n.map(|p| p / 1e3),
        Quantity::Folds => Some(f64::from(s.folds)),
        Quantity::KineticToInternalPct => Some(100.0 * s.kinetic_to_internal),
        Quantity::Mode | Quantity::Particles => None,
    }
}

fn number(q: Quantity, x: f64) -> String {
    match q {
        Quantity::MeanLoadKn | Quantity::FirstPeakKn => format!("{x:.3} kN"),
        Quantity::Folds => format!("{x:.0}"),
        Quantity::KineticToInternalPct => format!("{x:.2} %"),
        Quantity::Particles => format!("{x:.0}"),
        Quantity::Mode => String::new(),
    }
}

/// Every check of the suite, read off `runs` (by scene id).
pub fn judge(scenes: &[Scene], checks: &[Check], runs: &BTreeMap<String, Entry>) -> Vec<Row> {
    checks
        .iter()
        .map(|c| {
            let scene = |id: &str| scenes.iter().find(|s| s.id == id).expect("suite checked");
            judge_one(c, &scene, runs)
        })
        .collect()
}

/// Check `c` read off `runs`; `scene` finds a scene by id (the check's own, or the one its
/// reference names).
fn judge_one<'a>(
    c: &Check,
    scene: &dyn Fn(&str) -> &'a Scene,
    runs: &BTreeMap<String, Entry>,
) -> Row {
    let own = scene(&c.scene);
    let entry = runs.get(&c.scene);
    let ours = value(c.quantity, own, entry);
    let mode = entry.map(|e| e.summary.mode);
    let ours_text = match (c.quantity, ours, mode) {
        (Quantity::Mode, _, Some(m)) => mode_text(&m),
        (Quantity::MeanLoadKn, Some(x), _) => {
            format!(
                "{} ({})",
                number(c.quantity, x),
                error_bar_text(entry.unwrap())
            )
        }
        (_, Some(x), _) => number(c.quantity, x),
        _ => "–".into(),
    };
    let (reference, reference_text) = match &c.reference {
        RefValue::Number(x) => (Some(*x), number(c.quantity, *x)),
        RefValue::Mode { kind, lobes } => (
            None,
            match lobes {
                Some(l) => format!("{kind} {l}"),
                None => kind.clone(),
            },
        ),
        RefValue::Scene(id) => {
            let x = value(c.quantity, scene(id), runs.get(id));
            (
                x,
                x.map_or("–".into(), |x| {
                    format!("{} ({id})", number(c.quantity, x))
                }),
            )
        }
    };
    let ratio = match (ours, reference) {
        (Some(a), Some(b)) if b != 0.0 => Some(a / b),
        _ => None,
    };
    let missing = entry.is_none() && c.quantity != Quantity::Particles;
    let status = match c.band {
        _ if missing => Status::Missing,
        Band::Shown => Status::Shown,
        Band::Ratio { low, high } => match ratio {
            Some(r) if r >= low - 1e-12 && r <= high + 1e-12 => Status::InBand,
            _ => Status::OutOfBand,
        },
        Band::AtMost(x) => match ours {
            Some(v) if v <= x => Status::InBand,
            _ => Status::OutOfBand,
        },
        Band::SameMode => match (&c.reference, mode) {
            (RefValue::Mode { kind, .. }, Some(m)) if m.kind() == kind => Status::InBand,
            _ => Status::OutOfBand,
        },
        Band::HoldsReference => match (entry.and_then(interval_kn), reference) {
            (Some((low, high)), Some(x)) if (low..=high).contains(&x) => Status::InBand,
            _ => Status::OutOfBand,
        },
    };
    let band = match c.band {
        Band::Ratio { low, high } if low == high => format!("= {low}"),
        Band::Ratio { low, high } => format!("{low:.2}–{high:.2}"),
        Band::AtMost(x) => format!("≤ {}", number(c.quantity, x)),
        Band::SameMode => "same mode".into(),
        Band::HoldsReference => "inside ours' error bar".into(),
        Band::Shown => "–".into(),
    };
    Row {
        scene: c.scene.clone(),
        group: own.group,
        figure: c.figure.clone(),
        quantity: c.quantity,
        ours,
        ours_text,
        verdict: entry.map_or("–".into(), verdict_text),
        reference,
        reference_text,
        kind: c.kind,
        source: c.source.clone(),
        ratio,
        band,
        reason: c.reason.clone(),
        status,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn check(band: Band, reference: f64) -> Check {
        Check {
            scene: "s".into(),
            figure: "mean load".into(),
            quantity: Quantity::MeanLoadKn,
            reference: RefValue::Number(reference),
            kind: Kind::Measured,
            source: "a test".into(),
            band,
            reason: "because".into(),
        }
    }

    #[test]
    fn a_ratio_band_judges_ours_over_the_reference_a_missing_run_is_not_a_pass_and_an_error_bar_holds_another_scene_s_run(
    ) {
        let scene = Scene {
            id: "s".into(),
            group: Group::Paper,
            title: "t".into(),
            case: json!({"discretization": {"model": "axisymmetric", "particles_through_thickness": 1},
                         "loading": {"crush_distance_mm": 0.5}}),
            run: true,
        };
        let case = parse(&scene.case).unwrap();
        let out =
            crate::solver::run(&case, &mut (), &std::sync::atomic::AtomicBool::new(false)).unwrap();
        let ours = out.summary.mean_load_n / 1e3;
        let mut runs = BTreeMap::new();
        runs.insert(
            "s".to_string(),
            Entry {
                summary: out.summary,
                history: out.history,
                shape_png: None,
                wall_s: 0.0,
            },
        );
        let band = Band::Ratio {
            low: 0.9,
            high: 1.1,
        };
        let find = |_: &str| &scene;
        let inside = judge_one(&check(band, ours / 1.05), &find, &runs);
        assert_eq!(inside.status, Status::InBand);
        assert!((inside.ratio.unwrap() - 1.05).abs() < 1e-12);
        let outside = judge_one(&check(band, ours / 1.2), &find, &runs);
        assert_eq!(outside.status, Status::OutOfBand);
        let none = judge_one(&check(band, ours), &find, &BTreeMap::new());
        assert_eq!(none.status, Status::Missing);

        // Held to another scene's run: its number is that scene's, and the band asks that it
        // lie inside ours' error bar.
        let ladder = |low_kn: f64, high_kn: f64| {
            let bar = json!({"basis": "three_d_ladder", "model": "3d", "rungs": [],
                "estimate_n": 1e3 * ours, "low_n": 1e3 * low_kn, "high_n": 1e3 * high_kn,
                "error": 0.0, "error_low": 0.0, "error_high": 0.0, "order": null,
                "extrapolated": false, "twin_gap": 0.0, "cost_s": 0.0, "cost_fraction": 0.0,
                "covers": ""});
            serde_json::from_value::<ErrorBar>(bar).unwrap()
        };
        let mut finer = runs["s"].clone();
        finer.summary.mean_load_n *= 1.1;
        runs.insert("finer".to_string(), finer);
        let held = Check {
            reference: RefValue::Scene("finer".into()),
            ..check(Band::HoldsReference, 0.0)
        };
        let mut judged = |low: f64, high: f64| {
            runs.get_mut("s").unwrap().summary.error_bar = Some(ladder(low, high));
            judge_one(&held, &find, &runs)
        };
        let holds = judged(ours, 1.2 * ours);
        assert_eq!(holds.reference, Some(1.1 * ours), "the other scene's mean");
        assert_eq!(holds.status, Status::InBand);
        assert_eq!(judged(0.9 * ours, 1.05 * ours).status, Status::OutOfBand);
        runs.get_mut("s").unwrap().summary.error_bar = None;
        assert_eq!(
            judge_one(&held, &find, &runs).status,
            Status::OutOfBand,
            "no error bar holds nothing"
        );
    }
}
