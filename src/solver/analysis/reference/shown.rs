//! Which of a case's closed forms fit its scene — its loading, cross-section, material and the
//! mode it folded in — each with the range it holds in, and why each of the others is left
//! out. Reports show these; the summary keeps every closed form. Units: N, mm, MPa.
//!
//! Imports the references and the case alone: the mode enters as the lobes seen and whether
//! the column buckled, so that this file sits below the mode's.

use super::{References, RoundReferences, DIAMOND_LOBES};
use crate::solver::model::case::{Case, LoadingMode, Outline};
use crate::solver::model::spec::RateKind;

use super::hexagonal::HexagonalReferences;
use super::rectangular::RectangularReferences;

/// A closed form that fits the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Shown {
    /// Who, and which form: "Alexander (1960), ring folds".
    pub name: String,
    pub load_n: f64,
    /// Where the form holds, in a phrase.
    pub range: String,
    /// The one the run's mean load is compared with.
    pub primary: bool,
}

/// A closed form left out, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct LeftOut {
    pub name: &'static str,
    pub why: String,
}

/// What a run showed that decides which forms fit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Seen {
    /// The lobes of a diamond mode; `None` for any other mode.
    pub lobes: Option<u32>,
    /// Whether the column buckled as a whole.
    pub buckled: bool,
}

/// The scene's closed forms and the ones left out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Fitting {
    pub shown: Vec<Shown>,
    pub left_out: Vec<LeftOut>,
}

/// Young's modulus from which a wall is a metal's, MPa: magnesium alloys, the least stiff
/// structural metals, have 45 GPa; polymers such as the paper's PVC (3.4 GPa) and their
/// fibre-reinforced forms along the tube stay below 20 GPa. Abramowicz & Jones's round-tube
/// constants and Guillow's fit were fitted to metal tubes' tests.
pub const METAL_MODULUS_MPA: f64 = 20_000.0;

/// How many times the folding load the column's Euler load may be and global buckling still
/// compete: a progressive crush's load peaks at about twice its mean (the default case, the
/// paper's tube in 3D: 27.3 kN largest against a 13.9 kN mean), so a column whose Euler load is
/// within three times the folding load may buckle before it folds; past that it folds.
pub const EULER_COMPETES: f64 = 3.0;

/// The closed forms that fit `case` after a run that showed `seen`.
pub fn fitting(case: &Case, references: &References, seen: Seen) -> Fitting {
    let mut f = Fitting::default();
    let axial = case.geometry().mode == LoadingMode::Axial;
    match references {
        References::Round(r) if axial => round_axial(case, r, seen, &mut f),
        References::Round(r) => round_lateral(r, &mut f),
        References::Rectangular(r) if axial => rectangular_axial(case, r, seen, &mut f),
        References::Rectangular(_) => f.left_out.push(LeftOut {
            name: "every closed form",
            why: "none covers a rectangular tube crushed laterally".into(),
        }),
        References::Hexagonal(r) if axial => hexagonal_axial(r, seen, &mut f),
        References::Hexagonal(_) => f.left_out.push(LeftOut {
            name: "every closed form",
            why: "none covers a hexagonal tube crushed laterally".into(),
        }),
    }
    f
}

fn round_axial(case: &Case, r: &RoundReferences, seen: Seen, f: &mut Fitting) {
    let material = &case.spec().material;
    let sigma0 = r.metal.flow_stress_mpa;
    f.shown.push(Shown {
        name: "Alexander (1960), ring folds".into(),
        load_n: r.alexander_ring_n,
        range: format!("rigid-plastic wall at σ0 {sigma0:.1} MPa, folding in rings"),
        primary: true,
    });
    f.left_out.push(LeftOut {
        name: "DeRuntz & Hodge",
        why: "a lateral crush's".into(),
    });
    match seen.lobes {
        Some(n) if DIAMOND_LOBES.contains(&n) => {
            let d = r.diamond.iter().find(|d| d.lobes == n);
            if let Some(d) = d {
                f.shown.push(Shown {
                    name: format!("Johnson, Soden & Al-Hassani (1977), {n} lobes, fixed hinges"),
                    load_n: d.stationary_n,
                    range: "diamond folds: a lower bound".into(),
                    primary: false,
                });
                f.shown.push(Shown {
                    name: format!("Johnson, Soden & Al-Hassani (1977), {n} lobes, moving hinges"),
                    load_n: d.travelling_n,
                    range: "diamond folds: an upper bound".into(),
                    primary: false,
                });
            }
        }
        Some(n) => f.left_out.push(LeftOut {
            name: "Johnson, Soden & Al-Hassani's diamond",
            why: format!(
                "given for {} to {} lobes, the run folded {n}",
                DIAMOND_LOBES.start(),
                DIAMOND_LOBES.end()
            ),
        }),
        None => f.left_out.push(LeftOut {
            name: "Johnson, Soden & Al-Hassani's diamond",
            why: "the run did not fold in lobes".into(),
        }),
    }
    euler(r.euler_clamped_n, r.alexander_ring_n, seen, f);
    let modulus = material.youngs_modulus_mpa;
    if modulus < METAL_MODULUS_MPA {
        f.left_out.push(LeftOut {
            name: "Abramowicz & Jones's and Guillow's metal-tube forms",
            why: format!(
                "fitted to metal tubes; this wall's E {:.1} GPa is not a metal's",
                modulus / 1000.0
            ),
        });
        return;
    }
    let m = &r.metal;
    f.shown.push(Shown {
        name: "Abramowicz & Jones (1984), round, static".into(),
        load_n: m.abramowicz_jones_n,
        range: format!(
            "metal tube in rings, effective crush distance; σ0 = ({:.0} + {:.0})/2 MPa",
            m.yield_stress_mpa, m.ultimate_stress_mpa
        ),
        primary: false,
    });
    rate_scaled(
        "Abramowicz & Jones (1984), round, at the strain rate",
        m.abramowicz_jones_dynamic_n,
        (m.rate_factor, m.strain_rate_per_s),
        material.rate,
        f,
    );
    let d_over_t = case.geometry().section.width_mm() / case.geometry().section.thickness_mm();
    if m.guillow_in_range {
        f.shown.push(Shown {
            name: "Guillow, Lu & Grzebieta (2001), fit, static".into(),
            load_n: m.guillow_n,
            range: format!("6060-T5 tubes' tests, d/t 10-450 (this {d_over_t:.1})"),
            primary: false,
        });
        rate_scaled(
            "Guillow, Lu & Grzebieta (2001), at the strain rate",
            m.guillow_dynamic_n,
            (m.rate_factor, m.strain_rate_per_s),
            material.rate,
            f,
        );
    } else {
        f.left_out.push(LeftOut {
            name: "Guillow, Lu & Grzebieta's fit",
            why: format!("made on d/t 10-450; this tube's is {d_over_t:.1}"),
        });
    }
}

fn round_lateral(r: &RoundReferences, f: &mut Fitting) {
    match r.deruntz_hodge_mean_n {
        Some(p) => f.shown.push(Shown {
            name: "DeRuntz & Hodge (1963), mean over the crush".into(),
            load_n: p,
            range: "rigid-plastic ring flattened by line loads, crush below d".into(),
            primary: true,
        }),
        None => f.left_out.push(LeftOut {
            name: "DeRuntz & Hodge's mean",
            why: "the crush reaches the diameter, where the formula ends".into(),
        }),
    }
    f.shown.push(Shown {
        name: "DeRuntz & Hodge (1963), at first contact".into(),
        load_n: r.deruntz_hodge_initial_n,
        range: "the plastic collapse load of the ring".into(),
        primary: false,
    });
    f.left_out.push(LeftOut {
        name: "Alexander, Johnson et al., Abramowicz & Jones, Guillow, Euler",
        why: "an axial crush's".into(),
    });
}

fn rectangular_axial(case: &Case, r: &RectangularReferences, seen: Seen, f: &mut Fitting) {
    f.shown.push(Shown {
        name: "Abramowicz & Jones (1984), square, static".into(),
        load_n: r.abramowicz_jones_n,
        range: format!(
            "superfolding element over the effective crush; side c {:.1} mm, σ0 {:.1} MPa",
            r.mean_side_mm, r.flow_stress_mpa
        ),
        primary: true,
    });
    rate_scaled(
        "Abramowicz & Jones (1984), square, at the strain rate",
        r.abramowicz_jones_dynamic_n,
        (r.rate_factor, r.strain_rate_per_s),
        case.spec().material.rate,
        f,
    );
    f.shown.push(Shown {
        name: "Wierzbicki & Abramowicz (1983), superfolding".into(),
        load_n: r.wierzbicki_abramowicz_n,
        range: "folds crushed flat: below a real crush, whose folds do not close".into(),
        primary: false,
    });
    euler(r.euler_clamped_n, r.abramowicz_jones_n, seen, f);
}

/// A hexagonal tube crushed axially: no folding mean load to show; Euler's load where it
/// could undercut the squash load, which bounds any folding load from above.
fn hexagonal_axial(r: &HexagonalReferences, seen: Seen, f: &mut Fitting) {
    f.left_out.push(LeftOut {
        name: "a folding mean load",
        why: "no closed form here covers a hexagonal tube's folds: the superfolding \
              element's coefficients for a 120° corner are not checked against their source"
            .into(),
    });
    // No folding load to weigh Euler's against: the squash load stands above any.
    if seen.buckled || r.euler_clamped_n < EULER_COMPETES * r.squash_n {
        euler(r.euler_clamped_n, r.squash_n, seen, f);
    } else {
        f.left_out.push(LeftOut {
            name: "Euler, clamped ends",
            why: format!(
                "{:.0} kN, {:.0} times the squash load σ0·A, which no folding load exceeds: the \
                 column folds before it could buckle",
                r.euler_clamped_n / 1000.0,
                r.euler_clamped_n / r.squash_n
            ),
        });
    }
}

/// A form times the rate law's factor, or why there is none.
fn rate_scaled(
    name: &'static str,
    load: Option<f64>,
    (factor, rate): (f64, f64),
    law: RateKind,
    f: &mut Fitting,
) {
    match load {
        Some(p) if law != RateKind::None => f.shown.push(Shown {
            name: name.into(),
            load_n: p,
            range: format!("x {factor:.3}, the rate law's factor at {rate:.0} /s"),
            primary: false,
        }),
        _ => f.left_out.push(LeftOut {
            name,
            why: "the material has no rate law: the static form is the dynamic one".into(),
        }),
    }
}

/// The column's Euler load where global buckling competes with folding, else why not.
fn euler(euler_n: f64, folding_n: f64, seen: Seen, f: &mut Fitting) {
    if seen.buckled || euler_n < EULER_COMPETES * folding_n {
        f.shown.push(Shown {
            name: "Euler, clamped ends".into(),
            load_n: euler_n,
            range: "global buckling of the column".into(),
            primary: false,
        });
    } else {
        f.left_out.push(LeftOut {
            name: "Euler, clamped ends",
            why: format!(
                "{:.0} kN, {:.0} times the folding load: the column folds before it could \
                 buckle",
                euler_n / 1000.0,
                euler_n / folding_n
            ),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::analysis::reference::references;
    use crate::solver::Limits;

    fn case(json: &str) -> Case {
        let spec = crate::solver::model::case::spec_from_json(json).unwrap();
        Case::parse(spec, &Limits::unbounded()).unwrap()
    }

    fn names(f: &Fitting) -> Vec<&str> {
        f.shown.iter().map(|s| s.name.as_str()).collect()
    }

    fn left(f: &Fitting) -> Vec<&str> {
        f.left_out.iter().map(|s| s.name).collect()
    }

    /// The paper's PVC tube in a ring crush: Alexander alone; no lateral form, no metal form
    /// (PVC is no metal), no Euler (322 kN against 10.6 kN), no diamond (no lobes).
    #[test]
    fn an_axial_pvc_ring_crush_shows_alexander_alone_and_says_why_not_the_rest() {
        let c = case("{}");
        let f = fitting(&c, &references(&c), Seen::default());
        assert_eq!(names(&f), vec!["Alexander (1960), ring folds"]);
        assert!(f.shown[0].primary);
        let out = left(&f);
        for name in [
            "DeRuntz & Hodge",
            "Johnson, Soden & Al-Hassani's diamond",
            "Euler, clamped ends",
            "Abramowicz & Jones's and Guillow's metal-tube forms",
        ] {
            assert!(out.contains(&name), "{name} not left out: {out:?}");
        }
    }

    /// A diamond of 3 lobes shows that lobe count's two hinge bounds and no other.
    #[test]
    fn a_diamond_shows_its_own_lobe_count_s_bounds() {
        let c = case(r#"{"tube": {"thickness_mm": 1.27, "mean_diameter_mm": 20.32}}"#);
        let r = references(&c);
        let f = fitting(
            &c,
            &r,
            Seen {
                lobes: Some(3),
                buckled: false,
            },
        );
        let diamond: Vec<_> = f
            .shown
            .iter()
            .filter(|s| s.name.starts_with("Johnson"))
            .collect();
        assert_eq!(diamond.len(), 2);
        assert!(diamond.iter().all(|s| s.name.contains("3 lobes")));
        assert!(diamond[0].load_n < diamond[1].load_n, "lower bound first");
    }

    /// A long slender tube, or one that buckled, shows its Euler load.
    #[test]
    fn euler_shows_where_the_column_may_buckle() {
        let slender = case(
            r#"{"tube": {"thickness_mm": 0.5, "mean_diameter_mm": 10, "length_mm": 800},
                "material": {"preset": "aa6060_t5"}}"#,
        );
        let r = references(&slender);
        let (References::Round(round), f) = (&r, fitting(&slender, &r, Seen::default())) else {
            panic!("round")
        };
        assert!(round.euler_clamped_n < EULER_COMPETES * round.alexander_ring_n);
        assert!(names(&f).contains(&"Euler, clamped ends"));
        let stubby = case("{}");
        let f = fitting(
            &stubby,
            &references(&stubby),
            Seen {
                lobes: None,
                buckled: true,
            },
        );
        assert!(names(&f).contains(&"Euler, clamped ends"), "it buckled");
    }

    /// A metal with a rate law shows the metal forms static and at the rate; one without a
    /// rate law says the static form is the dynamic one.
    #[test]
    fn metal_forms_show_for_metals_with_their_rate_factor_where_the_law_has_one() {
        let steel = case(
            r#"{"material": {"preset": "mild_steel"},
                "tube": {"thickness_mm": 2, "mean_diameter_mm": 50, "length_mm": 150}}"#,
        );
        let f = fitting(&steel, &references(&steel), Seen::default());
        let shown = names(&f);
        assert!(shown.contains(&"Abramowicz & Jones (1984), round, static"));
        assert!(shown.contains(&"Abramowicz & Jones (1984), round, at the strain rate"));
        assert!(shown.contains(&"Guillow, Lu & Grzebieta (2001), fit, static"));
        let aluminium = case(
            r#"{"material": {"preset": "aa6060_t5"},
                "tube": {"thickness_mm": 1.67, "mean_diameter_mm": 48.33, "length_mm": 100}}"#,
        );
        let f = fitting(&aluminium, &references(&aluminium), Seen::default());
        assert!(names(&f).contains(&"Abramowicz & Jones (1984), round, static"));
        assert!(left(&f).contains(&"Abramowicz & Jones (1984), round, at the strain rate"));
    }

    /// A lateral crush shows DeRuntz & Hodge and none of the axial forms.
    #[test]
    fn a_lateral_crush_shows_deruntz_hodge_alone() {
        let c = case(r#"{"loading": {"mode": "lateral"}}"#);
        let f = fitting(&c, &references(&c), Seen::default());
        assert_eq!(
            names(&f),
            vec![
                "DeRuntz & Hodge (1963), mean over the crush",
                "DeRuntz & Hodge (1963), at first contact"
            ]
        );
        assert!(f.shown[0].primary);
    }

    /// A square tube axially: Abramowicz & Jones primary, Wierzbicki & Abramowicz beside it;
    /// laterally, nothing, with the reason.
    #[test]
    fn a_square_tube_shows_its_own_forms() {
        let axial = case(
            r#"{"tube": {"section": "rectangular", "thickness_mm": 1.5, "side_a_mm": 40,
                "side_b_mm": 40, "corner_radius_mm": 2, "length_mm": 120},
                "material": {"preset": "aa6060_t5"}}"#,
        );
        let f = fitting(&axial, &references(&axial), Seen::default());
        assert_eq!(f.shown[0].name, "Abramowicz & Jones (1984), square, static");
        assert!(f.shown[0].primary);
        assert!(names(&f).contains(&"Wierzbicki & Abramowicz (1983), superfolding"));
        let lateral = case(
            r#"{"tube": {"section": "rectangular", "thickness_mm": 1.5, "side_a_mm": 40,
                "side_b_mm": 40, "corner_radius_mm": 2, "length_mm": 120},
                "loading": {"mode": "lateral"}}"#,
        );
        let f = fitting(&lateral, &references(&lateral), Seen::default());
        assert!(f.shown.is_empty());
        assert_eq!(f.left_out.len(), 1);
    }
}
