//! What `crush validate` runs and what each run is compared with: the scenes (a case each, as
//! JSON), the checks (one figure of one scene beside one reference, with the band it must stay
//! in and why), and the figures. Units: kN, mm, %; a check's reference is in its quantity's unit.
//!
//! The seed paper's scenes are here; the measured tubes come from `measured.rs`. Imports only
//! `measured.rs` of the validate folder.

use super::measured::{self, MeasuredTube};
use crate::solver::analysis::expected;
use crate::solver::analysis::reference::References;
use crate::solver::{references, Case, Limits};
use serde_json::{json, Value};

/// Which scenes run, and at what resolution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Profile {
    /// Under two minutes: the paper's tube in its section at n 2, the particle counts and one
    /// measured tube (the test suite runs it).
    Ci,
    /// Under ten minutes on 2 cores: sections where the scene has a symmetry, coarse 3D where
    /// it has none.
    Quick,
    /// The resolutions the references need: hours.
    Full,
}

impl Profile {
    pub fn name(self) -> &'static str {
        match self {
            Profile::Ci => "ci",
            Profile::Quick => "quick",
            Profile::Full => "full",
        }
    }
}

/// The report's parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Group {
    /// Yang, Meguid & Zhang (2013): its scenes and figures.
    Paper,
    /// Tubes crushed in testing machines, from the literature.
    Measured,
    /// A thin wall's 3D convergence: its coarse runs' error bars held to its finest run.
    ThinWalls,
}

/// What a reference is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// The seed paper's own MPM result.
    PaperMpm,
    /// A tube crushed in a testing machine.
    Measured,
    /// A closed-form theory.
    Theory,
    /// An empirical fit to tests.
    Fit,
    /// Another run of crush (a rate-independent wall at another speed).
    Crush,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::PaperMpm => "the paper's MPM",
            Kind::Measured => "measured",
            Kind::Theory => "theory",
            Kind::Fit => "empirical fit",
            Kind::Crush => "crush",
        }
    }
}

/// The figure of a run a check reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Mean load over the crush, kN.
    MeanLoadKn,
    /// First collapse peak, kN.
    FirstPeakKn,
    /// Folds counted on the final shape.
    Folds,
    /// The collapse mode's kind (`ring`, `diamond`, `global_buckling`, …).
    Mode,
    /// Largest E_kin / E_int over the second half, %.
    KineticToInternalPct,
    /// Tube particles (from the case: no run).
    Particles,
}

/// What a check's reference is.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RefValue {
    /// A number in the quantity's unit.
    Number(f64),
    /// A mode's kind, as `CollapseMode::kind` spells it, with its lobes where told.
    Mode { kind: String, lobes: Option<u32> },
    /// The same quantity of another scene.
    Scene(String),
}

/// Where ours must lie against the reference.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Band {
    /// ours / reference within [low, high].
    Ratio { low: f64, high: f64 },
    /// ours at most this (in the quantity's unit).
    AtMost(f64),
    /// The same mode kind (lobes shown, not judged).
    SameMode,
    /// The reference lies inside ours' error bar (the interval the converged value lies in).
    HoldsReference,
    /// Shown beside ours, not judged.
    Shown,
}

/// One figure of one scene beside one reference.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Check {
    pub scene: String,
    pub figure: String,
    pub quantity: Quantity,
    pub reference: RefValue,
    pub kind: Kind,
    pub source: String,
    pub band: Band,
    /// Why the band is what it is, or why the reference is only shown.
    pub reason: String,
}

/// One case the suite runs (or, with `run` false, only builds: its particle count).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Scene {
    pub id: String,
    pub group: Group,
    pub title: String,
    pub case: Value,
    pub run: bool,
}

/// A plot of several scenes' load curves, or of one scene's energies.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Figure {
    pub id: String,
    pub group: Group,
    pub title: String,
    pub scenes: Vec<String>,
    pub what: Plot,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Plot {
    /// Load (kN) against plate travel (mm), one line a scene.
    LoadCurves,
    /// Kinetic and internal energy (J) against plate travel, of the first scene.
    Energies,
    /// Wall time (s) against particles, log–log, a point a scene.
    WallTime,
}

/// Everything a profile runs and reports.
pub struct Suite {
    pub scenes: Vec<Scene>,
    pub checks: Vec<Check>,
    pub figures: Vec<Figure>,
    /// What this profile leaves out that the full one runs, one sentence each.
    pub leaves_out: Vec<String>,
}

/// The paper, as every check of its figures names it.
pub const PAPER: &str = "Yang, Meguid & Zhang, Sci China Phys Mech Astron 56 (2013), \
                         doi:10.1007/s11433-013-5073-x";

/// The band a comparison with the paper's MPM gets: this run's expected error (the planner's,
/// from the convergence studies) plus 10 % for the paper's own resolution, or 25 % where no
/// study guides this run.
fn paper_band(case: &Value) -> (Band, String) {
    let expected = parse(case).and_then(|c| expected::of_case(&c).percent);
    match expected {
        Some(p) => {
            let half = (p.abs() + 10.0) / 100.0;
            (
                Band::Ratio {
                    low: 1.0 - half,
                    high: 1.0 + half,
                },
                format!(
                    "±{:.0} %: this run's expected error ({p:.1} %, from the convergence \
                     studies) plus 10 % for the paper's own resolution",
                    100.0 * half
                ),
            )
        }
        None => (
            Band::Ratio {
                low: 0.75,
                high: 1.25,
            },
            "±25 %: no convergence study guides this run's error".into(),
        ),
    }
}

/// The case, parsed without limits; `None` if it does not parse (a suite bug the tests catch).
pub fn parse(case: &Value) -> Option<Case> {
    Case::from_json(&case.to_string(), &Limits::unbounded()).ok()
}

/// The paper's axial tube (t 3.2, d 22.2, l 76.2, μ 0.02, 50 mm) at `n`, in `model`.
fn paper_axial(n: u32, model: &str, speed: f64, label: &str) -> Value {
    json!({
        "label": label,
        "loading": {"mode": "axial", "plate_speed_m_s": speed, "crush_distance_mm": 50.0},
        "discretization": {"particles_through_thickness": n, "shape": "gimp", "model": model},
        "output": {"final_state": model == "3d", "error_bar": speed == 10.0},
    })
}

/// A PVC thin tube of the paper's on a platen's μ 0.3, with or without its 0.3 % trigger.
fn paper_thin(t: f64, d: f64, n: u32, trigger: bool, label: &str) -> Value {
    json!({
        "label": label,
        "tube": {"thickness_mm": t, "mean_diameter_mm": d, "length_mm": 76.2},
        "loading": {"mode": "axial", "plate_speed_m_s": 10.0, "crush_distance_mm": 50.0},
        "contact": {"friction": 0.3},
        "discretization": {"particles_through_thickness": n},
        "trigger": {"weak_fraction": if trigger { 0.003 } else { 0.0 }, "seed": 1},
    })
}

/// A closed form a scene is shown beside.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Form {
    Alexander,
    Diamond(u32),
    DeruntzHodge,
    Euler,
    /// Abramowicz & Jones, and Guillow's fit where D/t is in its range.
    Metal,
}

struct Builder {
    suite: Suite,
}

impl Builder {
    fn scene(&mut self, id: &str, group: Group, title: &str, case: Value) {
        self.suite.scenes.push(Scene {
            id: id.into(),
            group,
            title: title.into(),
            case,
            run: true,
        });
    }

    #[allow(clippy::too_many_arguments)]
    fn check(
        &mut self,
        scene: &str,
        figure: &str,
        quantity: Quantity,
        reference: RefValue,
        kind: Kind,
        source: &str,
        band: Band,
        reason: &str,
    ) {
        self.suite.checks.push(Check {
            scene: scene.into(),
            figure: figure.into(),
            quantity,
            reference,
            kind,
            source: source.into(),
            band,
            reason: reason.into(),
        });
    }

    /// A mean load beside the paper's MPM figure, in the band [`paper_band`] gives.
    fn paper_mean(&mut self, scene: &str, kn: f64, source: &str) {
        let case = &self.find(scene).case;
        let (band, reason) = paper_band(case);
        self.check(
            scene,
            "mean load",
            Quantity::MeanLoadKn,
            RefValue::Number(kn),
            Kind::PaperMpm,
            source,
            band,
            &reason,
        );
    }

    /// The paper's tube's mean load (13.2 kN) and its three folds over 50 mm.
    fn paper_axial_checks(&mut self, scene: &str, source: &str) {
        self.paper_mean(scene, 13.2, source);
        self.check(
            scene,
            "folds",
            Quantity::Folds,
            RefValue::Number(3.0),
            Kind::PaperMpm,
            source,
            Band::Ratio {
                low: 1.0,
                high: 1.0,
            },
            "the same count: three folds form over 50 mm",
        );
    }

    /// The closed forms that reach `scene`'s tube beside its mean load (and Euler's load beside
    /// its first peak), shown and not judged: `forms` picks which.
    fn closed_forms(&mut self, scene: &str, forms: &[Form]) {
        let Some(case) = parse(&self.find(scene).case) else {
            return;
        };
        let theory = |name: &str| (Kind::Theory, name.to_string());
        let mut rows: Vec<(Quantity, f64, Kind, String)> = Vec::new();
        // Each shape's forms, where the case's section has them.
        let refs = references(&case);
        if let References::Round(r) = &refs {
            for f in forms {
                match f {
                    Form::Alexander => {
                        let (k, n) = theory("Alexander (1960), ring mode");
                        rows.push((Quantity::MeanLoadKn, r.alexander_ring_n, k, n));
                    }
                    Form::Diamond(lobes) => {
                        if let Some(d) = r.diamond.iter().find(|d| d.lobes == *lobes) {
                            let (k, n) = theory(&format!(
                                "Johnson, Soden & Al-Hassani (1977), {lobes} lobes, \
                                     travelling hinge"
                            ));
                            rows.push((Quantity::MeanLoadKn, d.travelling_n, k, n));
                        }
                    }
                    Form::DeruntzHodge => {
                        if let Some(p) = r.deruntz_hodge_mean_n {
                            let (k, n) = theory("DeRuntz & Hodge (1963), mean over the crush");
                            rows.push((Quantity::MeanLoadKn, p, k, n));
                        }
                    }
                    Form::Euler => {
                        let (k, n) = theory("Euler, clamped ends");
                        rows.push((Quantity::FirstPeakKn, r.euler_clamped_n, k, n));
                    }
                    Form::Metal => {
                        let (k, n) = theory("Abramowicz & Jones (1984), effective crush");
                        rows.push((Quantity::MeanLoadKn, r.metal.abramowicz_jones_n, k, n));
                        if r.metal.guillow_in_range {
                            rows.push((
                                Quantity::MeanLoadKn,
                                r.metal.guillow_n,
                                Kind::Fit,
                                "Guillow, Lu & Grzebieta (2001), 6060-T5 tests".into(),
                            ));
                        }
                    }
                }
            }
        }
        if let References::Rectangular(r) = &refs {
            if forms.contains(&Form::Metal) {
                let (k, n) = theory("Abramowicz & Jones (1984), square tube");
                rows.push((Quantity::MeanLoadKn, r.abramowicz_jones_n, k, n));
                let (k, n) = theory("Wierzbicki & Abramowicz (1983)");
                rows.push((Quantity::MeanLoadKn, r.wierzbicki_abramowicz_n, k, n));
            }
        }
        for (quantity, load_n, kind, name) in rows {
            let figure = match quantity {
                Quantity::FirstPeakKn => "first peak",
                _ => "mean load",
            };
            self.check(
                scene,
                figure,
                quantity,
                RefValue::Number(load_n / 1e3),
                kind,
                &name,
                Band::Shown,
                "shown: a closed form, not a measurement, at the case's flow stress",
            );
        }
    }

    fn find(&self, id: &str) -> &Scene {
        self.suite
            .scenes
            .iter()
            .find(|s| s.id == id)
            .unwrap_or_else(|| panic!("no scene {id}"))
    }

    fn figure(&mut self, id: &str, group: Group, title: &str, scenes: &[&str], what: Plot) {
        let scenes: Vec<String> = scenes
            .iter()
            .filter(|s| self.suite.scenes.iter().any(|x| x.id == **s && x.run))
            .map(|s| s.to_string())
            .collect();
        if !scenes.is_empty() {
            self.suite.figures.push(Figure {
                id: id.into(),
                group,
                title: title.into(),
                scenes,
                what,
            });
        }
    }
}

/// The suite of `profile`.
pub fn suite(profile: Profile) -> Suite {
    let mut b = Builder {
        suite: Suite {
            scenes: Vec::new(),
            checks: Vec::new(),
            figures: Vec::new(),
            leaves_out: Vec::new(),
        },
    };
    paper(&mut b, profile);
    thin_walls(&mut b, profile);
    let tubes = measured::tubes();
    for (i, tube) in tubes.iter().enumerate() {
        if profile != Profile::Ci || i == 0 {
            measured_tube(&mut b, tube, profile);
        }
    }
    if profile == Profile::Ci {
        // The ladder of the paper's tube runs its section at n 8, 12 and 16: over a minute.
        for scene in &mut b.suite.scenes {
            scene.case["output"]["error_bar"] = json!(false);
        }
        b.suite.leaves_out.push(
            "every scene but the paper's section at n 2, its particle counts and the first \
             measured tube; and the error bars, whose ladder on the paper's tube runs its \
             section at n 8, 12 and 16"
                .into(),
        );
    }
    b.suite
}

/// The seed paper's scenes and figures.
fn paper(b: &mut Builder, profile: Profile) {
    let g = Group::Paper;
    let fig24 = format!("{PAPER}, Figs. 2 and 4");
    // Table 1: the particle counts of the paper's tube at n 2–10 (no run: the lattice alone).
    for (n, count) in [(2, 4.6e3), (4, 35e3), (6, 113e3), (8, 273e3), (10, 527e3)] {
        let id = format!("paper-3d-n{n}");
        let case = paper_axial(n, "3d", 10.0, &format!("the paper's tube, 3D, n {n}"));
        let runs = match profile {
            Profile::Ci => false,
            Profile::Quick => n <= 4,
            Profile::Full => n <= 8,
        };
        b.suite.scenes.push(Scene {
            id: id.clone(),
            group: g,
            title: format!("the paper's tube in 3D, n {n}, 50 mm"),
            case,
            run: runs,
        });
        b.check(
            &id,
            "tube particles",
            Quantity::Particles,
            RefValue::Number(count),
            Kind::PaperMpm,
            &format!("{PAPER}, Table 1"),
            Band::Ratio {
                low: 0.9,
                high: 1.1,
            },
            "±10 %: the paper gives its counts to two or three figures, and where a lattice \
             meets the tube's ends differs by a layer of particles",
        );
        if runs {
            b.paper_axial_checks(&id, &fig24);
            b.check(
                &id,
                "mode",
                Quantity::Mode,
                RefValue::Mode {
                    kind: "ring".into(),
                    lobes: None,
                },
                Kind::PaperMpm,
                &fig24,
                Band::SameMode,
                "a thick wall (d/t 7) folds as rings",
            );
        }
    }
    // The section at n 2–8: the converged reference 3D approaches.
    let sections: &[u32] = match profile {
        Profile::Ci => &[2],
        _ => &[2, 4, 6, 8],
    };
    for &n in sections {
        let id = format!("paper-axisym-n{n}");
        b.scene(
            &id,
            g,
            &format!("the paper's tube, axisymmetric section, n {n}, 50 mm"),
            paper_axial(
                n,
                "axisymmetric",
                10.0,
                &format!("the paper's tube, axisymmetric, n {n}"),
            ),
        );
        b.paper_axial_checks(&id, &fig24);
    }
    let finest_section = format!("paper-axisym-n{}", sections[sections.len() - 1]);
    b.closed_forms(&finest_section, &[Form::Alexander]);
    b.figure(
        "paper-section",
        g,
        "The paper's tube, axisymmetric section at n 2–8: load against plate travel",
        &[
            "paper-axisym-n2",
            "paper-axisym-n4",
            "paper-axisym-n6",
            "paper-axisym-n8",
        ],
        Plot::LoadCurves,
    );
    if profile == Profile::Ci {
        return;
    }
    // Fig. 5: the kinetic energy beside the internal, on the finest 3D run.
    let finest = if profile == Profile::Full {
        "paper-3d-n8"
    } else {
        "paper-3d-n4"
    };
    b.check(
        finest,
        "E_kin / E_int, second half",
        Quantity::KineticToInternalPct,
        RefValue::Number(5.0),
        Kind::PaperMpm,
        &format!("{PAPER}, Fig. 5"),
        Band::AtMost(5.0),
        "at most 5 %: the kinetic energy stays small beside the internal in a quasi-static \
         crush (the verdict's own bound)",
    );
    // Fig. 6: the plate at 5 and 15 m/s against 10 m/s, in the section at n 4.
    for speed in [5.0, 15.0] {
        let id = format!("paper-axisym-n4-{speed:.0}m_s");
        b.scene(
            &id,
            g,
            &format!("the paper's tube, axisymmetric section, n 4, plate at {speed:.0} m/s"),
            paper_axial(
                4,
                "axisymmetric",
                speed,
                &format!("the paper's tube, axisymmetric, n 4, {speed:.0} m/s"),
            ),
        );
        b.check(
            &id,
            "mean load",
            Quantity::MeanLoadKn,
            RefValue::Scene("paper-axisym-n4".into()),
            Kind::Crush,
            &format!("{PAPER}, Fig. 6 (5, 10 and 15 m/s)"),
            Band::Ratio {
                low: 0.95,
                high: 1.05,
            },
            "±5 %: the PVC wall is rate independent, so only inertia can move the load between \
             5, 10 and 15 m/s; compared with the same section at 10 m/s",
        );
    }
    // Figs. 3 and 7: the lateral crush.
    let lateral_n = if profile == Profile::Full { 4 } else { 2 };
    let lateral = |model: &str, n: u32| {
        json!({
            "label": format!("the paper's tube, lateral, {model}, n {n}"),
            "loading": {"mode": "lateral", "plate_speed_m_s": 10.0, "crush_distance_mm": 12.5},
            "discretization": {"particles_through_thickness": n, "shape": "gimp", "model": model},
            "output": {"final_state": model == "3d", "error_bar": true},
        })
    };
    let lateral_scenes = [
        ("paper-lateral-plane-n4", "plane_strain", 4),
        ("paper-lateral-3d", "3d", lateral_n),
    ];
    for (id, model, n) in lateral_scenes {
        b.scene(
            id,
            g,
            &format!("the paper's tube crushed laterally 12.5 mm, {model}, n {n}"),
            lateral(model, n),
        );
        b.paper_mean(id, 5.763, &format!("{PAPER}, Figs. 3 and 7 (5 763 N)"));
        b.check(
            id,
            "mode",
            Quantity::Mode,
            RefValue::Mode {
                kind: "flattening".into(),
                lobes: None,
            },
            Kind::PaperMpm,
            &format!("{PAPER}, Fig. 3"),
            Band::SameMode,
            "a ring flattened across a diameter",
        );
        b.closed_forms(id, &[Form::DeruntzHodge]);
    }
    // Figs. 10–15: the thin tubes, t/d 0.063 and 0.038, with and without the trigger.
    let thin_n = if profile == Profile::Full { 4 } else { 2 };
    let mut thin = vec![(1.27, 20.32, 2.7, 2, "thin-d20")];
    if profile == Profile::Full {
        thin.push((0.76, 19.81, 1.0, 3, "thin-d19"));
    }
    let triggers: &[bool] = match profile {
        Profile::Full => &[true, false],
        _ => &[true],
    };
    for (t, d, kn, lobes, stem) in thin {
        for &trigger in triggers {
            let id = format!("{stem}-{}", if trigger { "trigger" } else { "plain" });
            let with = if trigger {
                "0.3 % trigger"
            } else {
                "no trigger"
            };
            b.scene(
                &id,
                g,
                &format!(
                    "PVC t {t} d {d} (t/d {:.3}), {with}, μ 0.3, n {thin_n}",
                    t / d
                ),
                paper_thin(t, d, thin_n, trigger, &format!("PVC t {t} d {d}, {with}")),
            );
            let figs = format!("{PAPER}, Figs. 10–15");
            b.paper_mean(&id, kn, &figs);
            b.closed_forms(&id, &[Form::Alexander, Form::Diamond(lobes)]);
            b.check(
                &id,
                "mode",
                Quantity::Mode,
                RefValue::Mode {
                    kind: "diamond".into(),
                    lobes: Some(lobes),
                },
                Kind::PaperMpm,
                &figs,
                Band::Shown,
                "shown: the lobe count follows the trigger's draw (the verdict's \
                 seed_sensitive_mode), and on the platen's μ 0.3 the code's tubes fold from \
                 both ends where the paper's folded from the moving plate",
            );
        }
    }
    // The Euler tube: d 10 (l/d 7.6) on the plates that hold it, and on the paper's.
    let euler_n = if profile == Profile::Full { 4 } else { 2 };
    let mut frictions = vec![0.3];
    if profile == Profile::Full {
        frictions.push(0.02);
    }
    for mu in frictions {
        let id = format!("euler-d10-mu{mu}");
        let mut case = paper_thin(
            1.27,
            10.0,
            euler_n,
            true,
            &format!("PVC t 1.27 d 10, μ {mu}"),
        );
        case["contact"]["friction"] = json!(mu);
        b.scene(
            &id,
            g,
            &format!("PVC t 1.27 d 10 (l/d 7.6), 0.3 % trigger, μ {mu}, n {euler_n}"),
            case,
        );
        let (kind, reason) = if mu >= 0.2 {
            (
                "global_buckling",
                "a column this slender bends as a whole once its end rings have folded",
            )
        } else {
            (
                "tipped_over",
                "shown: on the paper's near-frictionless plates its ends slide and it tips over \
                 (what the paper's friction does), where a platen holds it to bend",
            )
        };
        b.check(
            &id,
            "mode",
            Quantity::Mode,
            RefValue::Mode {
                kind: kind.into(),
                lobes: None,
            },
            Kind::PaperMpm,
            &format!("{PAPER}, the Euler tube"),
            if mu >= 0.2 {
                Band::SameMode
            } else {
                Band::Shown
            },
            reason,
        );
        b.closed_forms(&id, &[Form::Euler]);
    }
    b.figure(
        "paper-3d",
        g,
        "The paper's tube in 3D (Figs. 2, 4): load against plate travel",
        &["paper-3d-n2", "paper-3d-n4", "paper-3d-n6", "paper-3d-n8"],
        Plot::LoadCurves,
    );
    b.figure(
        "paper-energies",
        g,
        "Kinetic and internal energy (Fig. 5)",
        &[finest],
        Plot::Energies,
    );
    b.figure(
        "paper-speeds",
        g,
        "Plate at 5, 10 and 15 m/s (Fig. 6), section at n 4",
        &[
            "paper-axisym-n4-5m_s",
            "paper-axisym-n4",
            "paper-axisym-n4-15m_s",
        ],
        Plot::LoadCurves,
    );
    b.figure(
        "paper-lateral",
        g,
        "The lateral crush (Figs. 3, 7)",
        &["paper-lateral-plane-n4", "paper-lateral-3d"],
        Plot::LoadCurves,
    );
    b.figure(
        "paper-thin",
        g,
        "The thin tubes, with and without the trigger (Figs. 10–15), and the Euler tube",
        &[
            "thin-d20-trigger",
            "thin-d20-plain",
            "thin-d19-trigger",
            "thin-d19-plain",
            "euler-d10-mu0.3",
            "euler-d10-mu0.02",
        ],
        Plot::LoadCurves,
    );
    let timed: Vec<String> = b
        .suite
        .scenes
        .iter()
        .filter(|s| s.run && s.group == Group::Paper)
        .map(|s| s.id.clone())
        .collect();
    let timed: Vec<&str> = timed.iter().map(String::as_str).collect();
    b.figure(
        "paper-wall-time",
        g,
        "Wall time against particles (Fig. 8), every run of this report",
        &timed,
        Plot::WallTime,
    );
    if profile == Profile::Quick {
        b.suite.leaves_out.extend([
            "the paper's tube in 3D at n 6 and 8 (its particle counts are checked without a run)"
                .to_string(),
            "the thin tubes at n 4 (here n 2), the t 1.27 d 20.32 tube without its trigger, and \
             the t 0.76 d 19.81 tube (t/d 0.038, 1.0 kN, three lobes): about two hours at n 4"
                .into(),
            "the lateral crush in 3D at n 4 (here n 2)".into(),
            "the Euler tube on the paper's μ 0.02, where it tips over".into(),
        ]);
    }
}

/// The d/t 14 PVC tube of the 3D convergence study (docs/studies.md §9): t 3.2, d 44.8,
/// l 125.4, 60 mm at 10 m/s on a platen's μ 0.3 with the 0.3 % trigger, on the default shape
/// functions (B-splines for this wall on these plates).
fn dt14(n: u32, error_bar: bool) -> Value {
    json!({
        "label": format!("PVC t 3.2 d 44.8 (d/t 14), n {n}"),
        "tube": {"thickness_mm": 3.2, "mean_diameter_mm": 44.8, "length_mm": 125.4},
        "loading": {"mode": "axial", "plate_speed_m_s": 10.0, "crush_distance_mm": 60.0},
        "contact": {"friction": 0.3},
        "discretization": {"particles_through_thickness": n},
        "trigger": {"weak_fraction": 0.003, "strength_ratio": 0.01, "seed": 1},
        "output": {"final_state": true, "error_bar": error_bar},
    })
}

/// A thin wall in 3D, where no section stands in: the d/t 14 tube at n 3 and 4, each with
/// its 3D ladder's error bar, held to the same tube at n 6; and n 4 beside n 6. Full profile
/// only (about an hour on 2 cores).
fn thin_walls(b: &mut Builder, profile: Profile) {
    if profile != Profile::Full {
        if profile == Profile::Quick {
            b.suite.leaves_out.push(
                "the d/t 14 tube's 3D convergence (n 3 and 4 with their 3D error bars, held to \
                 n 6): about an hour on 2 cores"
                    .into(),
            );
        }
        return;
    }
    let g = Group::ThinWalls;
    let finest = "dt14-n6";
    for n in [3, 4, 6] {
        b.scene(
            &format!("dt14-n{n}"),
            g,
            &format!("PVC t 3.2 d 44.8 (d/t 14), 0.3 % trigger, μ 0.3, B-splines, n {n}, 60 mm"),
            dt14(n, n < 6),
        );
    }
    let source = "crush at n 6, the finest run of docs/studies.md §9";
    for n in [3, 4] {
        b.check(
            &format!("dt14-n{n}"),
            "mean load",
            Quantity::MeanLoadKn,
            RefValue::Scene(finest.into()),
            Kind::Crush,
            source,
            Band::HoldsReference,
            "what an error bar claims: the interval of the 3D ladder (this case at n − 2, \
             n − 1 and n) holds the finer run's mean",
        );
    }
    for (quantity, figure) in [
        (Quantity::MeanLoadKn, "mean load"),
        (Quantity::FirstPeakKn, "first peak"),
    ] {
        b.check(
            "dt14-n4",
            figure,
            quantity,
            RefValue::Scene(finest.into()),
            Kind::Crush,
            source,
            Band::Ratio {
                low: 0.95,
                high: 1.05,
            },
            "±5 %: on B-splines the study found the mean load within 1.8 % from n 4 to 6, each \
             folding from the fixed end (uGIMP's alternates 10 % with the parity of n: \
             docs/studies.md §9)",
        );
    }
    b.figure(
        "dt14",
        g,
        "The d/t 14 tube in 3D at n 3, 4 and 6: load against plate travel",
        &["dt14-n3", "dt14-n4", finest],
        Plot::LoadCurves,
    );
}

/// One measured tube: its scene and the checks against the test and the theories beside it.
fn measured_tube(b: &mut Builder, tube: &MeasuredTube, profile: Profile) {
    let id = format!("measured-{}", tube.id);
    let (case, how) = measured::case(tube, profile == Profile::Full);
    b.scene(
        &id,
        Group::Measured,
        &format!("{} ({how})", tube.title()),
        case,
    );
    let source = format!("{}, {} ({})", tube.source, tube.table, tube.units_note);
    let expected = parse(&b.find(&id).case).and_then(|c| expected::of_case(&c).percent);
    let (half, why) = match expected {
        Some(p) => (
            (p.abs() + 15.0) / 100.0,
            format!("this run's expected error ({p:.1} %) plus 15 %"),
        ),
        None => (
            0.30,
            "30 %: no convergence study guides this run's error, plus 15 %".into(),
        ),
    };
    let reason = format!(
        "±{:.0} %: {why} for the material (a perfectly plastic wall at the flow stress \
         (σy + σu)/2 where the paper gives no hardening fit, and the test's own scatter)",
        100.0 * half
    );
    let band = Band::Ratio {
        low: 1.0 - half,
        high: 1.0 + half,
    };
    if let Some(mean) = tube.measured.mean_kn {
        b.check(
            &id,
            "mean load",
            Quantity::MeanLoadKn,
            RefValue::Number(mean),
            Kind::Measured,
            &source,
            band,
            &reason,
        );
    }
    if let Some(peak) = tube.measured.peak_kn {
        b.check(
            &id,
            "first peak",
            Quantity::FirstPeakKn,
            RefValue::Number(peak),
            Kind::Measured,
            &source,
            Band::Shown,
            "shown: the first peak depends on the tube's end and imperfections, which the \
             model does not have",
        );
    }
    b.check(
        &id,
        "mode",
        Quantity::Mode,
        RefValue::Mode {
            kind: tube.measured.mode.clone(),
            lobes: tube.measured.lobes,
        },
        Kind::Measured,
        &source,
        Band::Shown,
        "shown: the observed mode beside ours",
    );
    for (name, kn) in &tube.theory_columns {
        b.check(
            &id,
            "mean load",
            Quantity::MeanLoadKn,
            RefValue::Number(*kn),
            Kind::Theory,
            &format!("{name}, as printed in {source}"),
            Band::Shown,
            "shown: a theory printed beside the test, not a measurement",
        );
    }
    b.closed_forms(&id, &[Form::Alexander, Form::Metal]);
    b.figure(
        &id,
        Group::Measured,
        &tube.title(),
        &[id.as_str()],
        Plot::LoadCurves,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_of_every_profile_parses_and_every_check_names_a_scene() {
        for profile in [Profile::Ci, Profile::Quick, Profile::Full] {
            let s = suite(profile);
            for scene in &s.scenes {
                let text = scene.case.to_string();
                if let Err(e) = Case::from_json(&text, &Limits::unbounded()) {
                    panic!("{}: {e}", scene.id);
                }
            }
            for c in &s.checks {
                assert!(
                    s.scenes.iter().any(|x| x.id == c.scene),
                    "{:?}: {} names no scene",
                    profile,
                    c.scene
                );
                if let RefValue::Scene(other) = &c.reference {
                    assert!(s.scenes.iter().any(|x| &x.id == other && x.run));
                }
            }
            let mut ids: Vec<&str> = s.scenes.iter().map(|x| x.id.as_str()).collect();
            ids.sort();
            ids.dedup();
            assert_eq!(ids.len(), s.scenes.len(), "{profile:?}: a scene id repeats");
        }
    }

    #[test]
    fn quick_leaves_out_what_full_runs_and_says_so() {
        let quick = suite(Profile::Quick);
        let full = suite(Profile::Full);
        let ran = |s: &Suite| s.scenes.iter().filter(|x| x.run).count();
        assert!(ran(&full) > ran(&quick));
        assert!(!quick.leaves_out.is_empty());
        assert!(full.leaves_out.is_empty());
    }
}
