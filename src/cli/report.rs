//! The text a finished run prints: loads in kN, energy in J, the collapse mode with its reason,
//! the closed-form references with the ratio of our mean load to the primary one, and the cost.

use crate::solver::analysis::curve::UNLOADED_FRACTION;
use crate::solver::analysis::error_bar::ErrorBar;
use crate::solver::analysis::expected::ExpectedError;
use crate::solver::analysis::mode::ModeDetail;
use crate::solver::analysis::reference::shown::{fitting, Seen};
use crate::solver::analysis::reference::References;
use crate::solver::analysis::verdict::END_SPREAD_CAUTION;
use crate::solver::analysis::verdict::{Level, Verdict};
use crate::solver::model::case::{LoadingMode, Outline};
use crate::solver::{Case, CaseError, CollapseMode, Summary};
use std::fmt::Write;

/// The readable summary of a run: what ran, the verdict, the loads with their error, the
/// crash measures, the mode, the energy books, the references that fit and the cost.
pub fn format_report(case: &Case, s: &Summary, detail: &ModeDetail) -> String {
    // Writing to a String cannot fail; the results are ignored.
    let mut o = String::new();
    scene_lines(&mut o, case);
    verdict_lines(&mut o, &s.verdict, s);
    load_lines(&mut o, s);
    measure_lines(&mut o, s);
    mode_lines(&mut o, s, detail);
    book_lines(&mut o, s);
    let _ = writeln!(o);
    references_lines(&mut o, case, s);
    let _ = writeln!(o);
    cost_lines(&mut o, s);
    o
}

/// The label, the tube and its crush, and the shape functions that ran.
fn scene_lines(o: &mut String, case: &Case) {
    let spec = case.spec();
    let loading = match spec.loading.mode {
        LoadingMode::Axial => "axial",
        LoadingMode::Lateral => "lateral",
    };
    if let Some(label) = &spec.label {
        let _ = writeln!(o, "{label}");
    }
    let section = case.geometry().section.describe();
    let _ = writeln!(
        o,
        "tube {section}, l {} mm; {loading} crush at {} m/s",
        spec.tube.length_mm, spec.loading.plate_speed_m_s
    );
    let shape = case.shape_choice();
    let _ = writeln!(
        o,
        "shape functions {}",
        shape.default_reason.as_deref().unwrap_or(shape.kind.name())
    );
    let _ = writeln!(o);
}

/// The verdict's line and each reason under it.
fn verdict_lines(o: &mut String, v: &Verdict, s: &Summary) {
    let _ = writeln!(o, "  verdict          {}", verdict_line(v, s));
    for reason in &v.reasons {
        let _ = writeln!(
            o,
            "                   {} ({}): {}",
            reason.level.name(),
            reason.rule.name(),
            reason.detail
        );
    }
}

/// The mean load against the primary reference, its error bar and expected error, the peak,
/// the first collapse peak and the mean after it.
fn load_lines(o: &mut String, s: &Summary) {
    let r = &s.references;
    let against = match r.primary_n() {
        Some(p) => format!(
            "{} x {} {}",
            ratio(s.mean_load_n, p),
            r.primary().name(),
            kn(p)
        ),
        None => "no closed form reaches this crush".into(),
    };
    let _ = writeln!(o, "  mean load        {}   ({against})", kn(s.mean_load_n));
    error_bar_lines(o, s);
    let e = &s.expected_error;
    let size = e
        .percent
        .map_or_else(|| "none".to_string(), |p| format!("±{p:.1} %"));
    let _ = writeln!(o, "  expected error   {size}   ({})", e.basis);
    let _ = writeln!(
        o,
        "  peak load        {}   (the largest, over the whole crush)",
        kn(s.peak_load_n)
    );
    let m = &s.measures;
    match (m.first_peak_load_n, m.first_peak_displacement_mm) {
        (Some(p), Some(u)) => {
            let _ = writeln!(o, "  first peak       {}   at {u:.2} mm", kn(p));
        }
        _ => {
            let _ = writeln!(o, "  first peak       none (the load never drops)");
        }
    }
    if let (Some(after), Some(cfe)) = (m.mean_load_after_first_peak_n, m.crush_force_efficiency) {
        let _ = writeln!(
            o,
            "  mean after it    {}   crush-force efficiency {cfe:.2}",
            kn(after)
        );
    }
}

/// The priced error bar of the mean load and the first collapse peak, or why there is none.
fn error_bar_lines(o: &mut String, s: &Summary) {
    match &s.error_bar {
        Some(ErrorBar::ReducedLadder(l) | ErrorBar::ThreeDLadder(l)) => {
            let _ = writeln!(
                o,
                "  error bar        converged mean load in [{}, {}], best {}: this run {:+.1} % ({:+.1} .. {} %)",
                kn(l.low_n),
                kn(l.high_n),
                kn(l.estimate_n),
                100.0 * l.error,
                100.0 * l.error_low,
                l.error_high
                    .map_or_else(|| "+∞".to_string(), |e| format!("{:+.1}", 100.0 * e))
            );
            if let Some(p) = &l.first_peak {
                let _ = writeln!(
                    o,
                    "                   converged first collapse peak in [{}, {}], best {}: this run {:+.1} %",
                    kn(p.low_n),
                    kn(p.high_n),
                    kn(p.estimate_n),
                    100.0 * p.error
                );
            }
            let _ = writeln!(
                o,
                "                   {}; cost {:.1} s ({:.0} % of the run)",
                l.covers,
                l.cost_s,
                100.0 * l.cost_fraction
            );
        }
        Some(ErrorBar::Unavailable { why }) => {
            let _ = writeln!(o, "  error bar        none: {why}");
        }
        None => {}
    }
}

/// The energy absorbed, the tube's mass and specific energy, the mass scaling, the crush.
fn measure_lines(o: &mut String, s: &Summary) {
    let m = &s.measures;
    let _ = writeln!(
        o,
        "  energy absorbed  {:.3} J   ({:.3} J dissipated: plastic + friction)",
        s.energy_absorbed_mj / 1000.0,
        m.energy_dissipated_mj / 1000.0
    );
    let _ = writeln!(
        o,
        "  tube mass        {:.2} g   specific energy absorption {:.3} J/g",
        m.tube_mass_g, m.specific_energy_absorption_j_per_g
    );
    if let Some(scaling) = m.mass_scaling {
        let _ = writeln!(
            o,
            "  mass scaling     f {}: {:.2} g added in the equations of motion only",
            scaling.factor, scaling.added_mass_g
        );
    }
    let _ = writeln!(o, "  crush distance   {:.2} mm", s.crush_distance_mm);
}

/// The folds, the mode with its reason and the figures the mode rule read.
fn mode_lines(o: &mut String, s: &Summary, detail: &ModeDetail) {
    let _ = writeln!(
        o,
        "  folds            {} (from the shape; {} load drops)",
        s.folds, s.load_drops
    );
    let _ = writeln!(o, "  mode             {}", mode_name(s.mode));
    let _ = writeln!(o, "                   {}", detail.reason);
    if let Some(f) = detail.faces {
        let _ = writeln!(
            o,
            "                   folded slices by their faces: {} symmetric, {} asymmetric, \
             {} extensional",
            f.symmetric, f.asymmetric, f.extensional
        );
    }
    let amps: Vec<String> = detail
        .harmonic_amplitude_mm
        .iter()
        .map(|a| format!("{a:.2}"))
        .collect();
    let _ = writeln!(
        o,
        "                   harmonics 0..8 [mm]: {}",
        amps.join(" ")
    );
    let _ = writeln!(
        o,
        "                   centre-line drift {:.2} mm, {:.2} mm from the line through its ends \
         (global above {:.2} mm)",
        detail.max_drift_mm, detail.bend_mm, detail.drift_threshold_mm
    );
    let _ = writeln!(
        o,
        "                   end rings {:.2} (bottom) and {:.2} mm (top) off their plates \
         (left above {:.2} mm)",
        detail.end_lift_mm[0], detail.end_lift_mm[1], detail.end_lift_threshold_mm
    );
    if detail.end_spread != [0.0; 2] {
        let _ = writeln!(
            o,
            "                   end rings spread to {:.2} (bottom) and {:.2} (top) times the \
             radius about their centres (flattened above {:.2})",
            detail.end_spread[0], detail.end_spread[1], END_SPREAD_CAUTION
        );
    }
    if detail.unfolded_slices > 0 {
        let _ = writeln!(
            o,
            "                   unfolded wall ({} slices): two lobes of {:.2} mm at most, at {:.0} \
             mm from the fixed end before the crush; {:.2} mm beyond what the folds' two lobes \
             ({:.2} mm) leave on an elastic tube (e-folding {:.0} mm)",
            detail.unfolded_slices,
            detail.unfolded_two_lobe_mm,
            detail.unfolded_two_lobe_at_mm,
            detail.unfolded_excess_two_lobe_mm,
            detail.folds_two_lobe_mm,
            detail.two_lobe_decay_mm
        );
    }
}

/// The energy balance, every term of the books, the kinetic ratio and the unloaded travel.
fn book_lines(o: &mut String, s: &Summary) {
    let _ = writeln!(
        o,
        "  energy balance   {:.2} % error",
        100.0 * s.energy_balance_error
    );
    let e = &s.energy;
    let _ = writeln!(
        o,
        "                   work top {:.3} J, bottom {:.3} J = kinetic {:.3} + elastic {:.3} \
         + plastic {:.3} + friction {:.3} + contact {:.3} + residual {:.3} J",
        e.work_top_mj / 1e3,
        e.work_bottom_mj / 1e3,
        e.kinetic_mj / 1e3,
        e.elastic_mj / 1e3,
        e.plastic_mj / 1e3,
        e.friction_mj / 1e3,
        e.contact_mj / 1e3,
        e.residual_mj / 1e3
    );
    let _ = writeln!(
        o,
        "  E_kin / E_int    {:.2} % at most over the second half",
        100.0 * s.kinetic_to_internal
    );
    let _ = writeln!(
        o,
        "  unloaded         {:.2} mm of travel at most with the load below {:.0} % of its peak",
        s.longest_unloaded_mm,
        100.0 * UNLOADED_FRACTION
    );
}

/// The run's particles, steps, time step range, wall time and rate.
fn cost_lines(o: &mut String, s: &Summary) {
    let c = &s.cost;
    let _ = writeln!(
        o,
        "cost: {} particles, {} steps, dt {} .. {} ms",
        c.particles,
        c.steps,
        sci(c.dt_min_ms),
        sci(c.dt_max_ms)
    );
    let _ = writeln!(
        o,
        "      wall {:.1} s, {:.3e} particle-steps/s on {} threads",
        c.wall_time_s, c.particle_steps_per_s, c.threads
    );
}

/// The verdict's level, and for a trusted run what that holds it to: no rule flagged it, and
/// the mean load is within its priced error bar, or expected within the measured guide's
/// error, or no figure bounds it.
fn verdict_line(v: &Verdict, s: &Summary) -> String {
    if v.level != Level::Trusted {
        return v.level.name().to_string();
    }
    let within = match (&s.error_bar, &s.expected_error) {
        (Some(ErrorBar::ReducedLadder(l) | ErrorBar::ThreeDLadder(l)), _) => format!(
            "within {:+.1} .. {} % of the converged mean load by its error bar",
            100.0 * l.error_low,
            l.error_high
                .map_or_else(|| "+∞".to_string(), |e| format!("{:+.1}", 100.0 * e))
        ),
        (
            _,
            ExpectedError {
                percent: Some(p), ..
            },
        ) => {
            format!("expected within ±{p:.1} % of the converged mean load")
        }
        _ => "no measured figure bounds its error".into(),
    };
    format!("trusted: no rule flagged it; {within}")
}

/// The closed forms that fit the scene, each with its range, and those left out with why
/// (`reference::shown`); the rectangular tube's fold length and the round metal tube's flow
/// stress, rate and fold wavelength where they were shown.
fn references_lines(o: &mut String, case: &Case, s: &Summary) {
    let seen = Seen {
        lobes: match s.mode {
            CollapseMode::Diamond { lobes } => Some(lobes),
            _ => None,
        },
        buckled: s.mode == CollapseMode::GlobalBuckling,
    };
    let f = fitting(case, &s.references, seen);
    let _ = writeln!(
        o,
        " {:<49} {:>11}   {:<9}   holds for",
        "references that fit this crush", "load", "mean / it"
    );
    for r in &f.shown {
        let mark = if r.primary { "*" } else { " " };
        let _ = writeln!(
            o,
            " {mark}{:<48} {:>11}   {:<9}   {}",
            r.name,
            kn(r.load_n),
            ratio(s.mean_load_n, r.load_n),
            r.range
        );
    }
    if f.shown.iter().any(|r| r.primary) {
        let _ = writeln!(o, "  (* the one the mean load is compared with)");
    }
    match &s.references {
        References::Rectangular(r) if !f.shown.is_empty() => {
            let _ = writeln!(
                o,
                "  a fold takes 2H = {:.1} mm of tube and {:.1} mm of crush (Wierzbicki-Abramowicz, \
                 Abramowicz-Jones)",
                2.0 * r.half_fold_length_mm,
                r.effective_crush_per_fold_mm,
            );
        }
        References::Round(r) if f.shown.iter().any(|x| x.name.starts_with("Abramowicz")) => {
            let m = &r.metal;
            let _ = writeln!(
                o,
                "  metal forms: fold wavelength 2H {:.2} mm, strain rate {:.3e} /s, rate factor {:.3}",
                m.fold_wavelength_mm, m.strain_rate_per_s, m.rate_factor
            );
        }
        _ => {}
    }
    for l in &f.left_out {
        let _ = writeln!(o, "  not shown: {}: {}", l.name, l.why);
    }
}

/// Every reason a case was rejected, one per line.
pub fn format_case_error(source: &str, e: &CaseError) -> String {
    match e {
        CaseError::Malformed {
            field: Some(f),
            message,
        } => format!("{source}: malformed at {f}: {message}"),
        CaseError::Malformed {
            field: None,
            message,
        } => format!("{source}: malformed: {message}"),
        CaseError::Invalid(errors) => {
            let mut o = format!("{source}: {} field(s) rejected:", errors.len());
            for f in errors {
                let _ = write!(o, "\n  {}: {}", f.field, f.reason);
            }
            o
        }
    }
}

pub fn mode_name(mode: CollapseMode) -> String {
    match mode {
        CollapseMode::Ring => "axisymmetric ring".into(),
        CollapseMode::Diamond { lobes } => format!("diamond, {lobes} lobes"),
        CollapseMode::GlobalBuckling => "global (Euler) buckling".into(),
        CollapseMode::Flattening => "lateral flattening".into(),
        CollapseMode::TippedOver => "tipped over between the plates".into(),
        CollapseMode::Symmetric => "symmetric (read face by face)".into(),
        CollapseMode::AsymmetricMixed => "asymmetric mixed (read face by face)".into(),
        CollapseMode::Extensional => "extensional (read face by face)".into(),
    }
}

fn kn(n: f64) -> String {
    format!("{:.3} kN", n / 1000.0)
}

fn ratio(ours: f64, reference: f64) -> String {
    if reference > 0.0 && ours.is_finite() {
        format!("{:.3}", ours / reference)
    } else {
        "n/a".into()
    }
}

fn sci(v: f64) -> String {
    format!("{v:.3e}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::analysis::reference::references;
    use crate::solver::{Limits, RunCost};

    fn summary(case: &Case, mean: f64, mode: CollapseMode) -> Summary {
        let figures = crate::solver::analysis::verdict::RunFigures {
            mode,
            longest_unloaded_mm: 0.0,
            energy_balance_error: 0.0123,
            kinetic_to_internal: 0.004,
        };
        let verdict =
            crate::solver::analysis::verdict::of_run(case, &figures, &ModeDetail::default());
        Summary {
            mean_load_n: mean,
            peak_load_n: 15_200.0,
            energy_absorbed_mj: mean * 50.0,
            crush_distance_mm: 50.0,
            folds: 4,
            load_drops: 0,
            energy_balance_error: 0.0123,
            energy: Default::default(),
            measures: Default::default(),
            kinetic_to_internal: 0.004,
            longest_unloaded_mm: 0.0,
            mode,
            references: references(case),
            cost: RunCost {
                particles: 35_000,
                steps: 1000,
                threads: 2,
                ..Default::default()
            },
            shape: case.shape_choice().clone(),
            verdict,
            error_bar: None,
            expected_error: crate::solver::analysis::expected::of_case(case),
        }
    }

    #[test]
    fn axial_report_compares_with_alexander() {
        let case = Case::from_json(r#"{"label": "pvc axial"}"#, &Limits::default()).unwrap();
        // Alexander is 10 570.7 N; 10 570.7 · 0.9 = 9 513.6 N reads as ratio 0.900.
        let s = summary(&case, 9_513.6, CollapseMode::Diamond { lobes: 3 });
        let text = format_report(
            &case,
            &s,
            &ModeDetail {
                reason: "because".into(),
                unfolded_slices: 12,
                unfolded_two_lobe_mm: 1.234,
                unfolded_two_lobe_at_mm: 20.4,
                unfolded_excess_two_lobe_mm: 0.456,
                end_spread: [1.04, 1.6],
                folds_two_lobe_mm: 2.5,
                two_lobe_decay_mm: 13.6,
                ..Default::default()
            },
        );
        assert!(text.starts_with("pvc axial\n"), "{text}");
        assert!(
            text.contains(
                "unfolded wall (12 slices): two lobes of 1.23 mm at most, at 20 mm from the \
                 fixed end before the crush; 0.46 mm beyond what the folds' two lobes (2.50 mm) \
                 leave on an elastic tube (e-folding 14 mm)"
            ),
            "{text}"
        );
        assert!(
            text.contains(
                "end rings spread to 1.04 (bottom) and 1.60 (top) times the radius about their \
                 centres (flattened above 1.25)"
            ),
            "{text}"
        );
        assert!(
            text.contains("\nshape functions gimp: the default for a wall of d/t = 6.9"),
            "{text}"
        );
        assert!(
            text.contains("mean load        9.514 kN   (0.900 x Alexander ring 10.571 kN)"),
            "{text}"
        );
        assert!(text.contains("energy absorbed  475.680 J"), "{text}");
        assert!(
            text.contains("mode             diamond, 3 lobes\n                   because"),
            "{text}"
        );
        assert!(text.contains("energy balance   1.23 % error"), "{text}");
        // Only the forms of an axial crush of PVC in three lobes; the rest named with why.
        let alexander = text
            .lines()
            .find(|l| l.starts_with(" *Alexander (1960), ring folds "))
            .expect(&text);
        assert!(alexander.contains(" 10.571 kN   0.900 "), "{text}");
        assert!(text.contains("3 lobes, fixed hinges"), "{text}");
        assert!(!text.contains("2 lobes") && !text.contains("n/a"), "{text}");
        for why in [
            "not shown: DeRuntz & Hodge: a lateral crush's",
            "not shown: Euler, clamped ends: 322 kN, 30 times the folding load",
            "not shown: Abramowicz & Jones's and Guillow's metal-tube forms: fitted to metal \
             tubes; this wall's E 3.4 GPa is not a metal's",
        ] {
            assert!(text.contains(why), "{why}\n{text}");
        }
        assert!(!text.contains("metal forms:"), "{text}");
        assert!(text.contains("cost: 35000 particles, 1000 steps"), "{text}");
        assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    }

    #[test]
    fn the_report_gives_the_verdict_above_the_numbers_with_each_reason() {
        let case = Case::from_json(
            r#"{"discretization": {"particles_through_thickness": 2}}"#,
            &Limits::default(),
        )
        .unwrap();
        let mut s = summary(&case, 9_513.6, CollapseMode::Ring);
        s.energy_balance_error = 0.06;
        s.verdict = crate::solver::analysis::verdict::of_run(
            &case,
            &s.verdict_figures(),
            &ModeDetail::default(),
        );
        let text = format_report(&case, &s, &ModeDetail::default());
        let verdict = text.find("  verdict          not_trusted\n").expect(&text);
        assert!(verdict < text.find("mean load").unwrap(), "{text}");
        assert!(
            text.contains(
                "caution (thin_resolution): use 4 or more particles through the wall: with 2"
            ),
            "{text}"
        );
        assert!(
            text.contains("not_trusted (energy_balance): set discretization.cfl")
                && text.contains("the energy books close to 6.0 %"),
            "{text}"
        );
    }

    #[test]
    fn lateral_report_compares_with_deruntz_hodge() {
        let case =
            Case::from_json(r#"{"loading": {"mode": "lateral"}}"#, &Limits::default()).unwrap();
        // DeRuntz-Hodge mean over 12.5 mm is 6 401.8 N.
        let text = format_report(
            &case,
            &summary(&case, 6_401.8, CollapseMode::Flattening),
            &ModeDetail::default(),
        );
        assert!(
            text.contains("(1.000 x DeRuntz-Hodge mean 6.402 kN)"),
            "{text}"
        );
        assert!(text.contains("lateral flattening"), "{text}");
    }

    #[test]
    fn every_rejected_field_is_listed() {
        let err = Case::from_json(
            r#"{"tube": {"thickness_mm": -1}, "contact": {"friction": 9}}"#,
            &Limits::default(),
        )
        .unwrap_err();
        let text = format_case_error("bad.json", &err);
        assert!(text.starts_with("bad.json: 2 field(s) rejected:"), "{text}");
        assert!(
            text.contains("\n  tube.thickness_mm: must be a finite number > 0"),
            "{text}"
        );
        assert!(
            text.contains("\n  contact.friction: must be in [0, 2]"),
            "{text}"
        );
    }
}
