//! The checks that make a spec a case, one function per section of the JSON, each naming
//! every field it refuses and why; [`super::case::Case::parse`] calls them in order and
//! collects every failure.

use super::checker::Checker;
use super::geometry::{CrossSection, Outline};
use super::material::checks as material_checks;
use super::spec::{
    wave_speed_m_s, CaseSpec, Contact, HardeningKind, LoadingMode, Material, MaterialModel, Model,
    Output, RateKind, Trigger, Tube, MAX_FRAMES, MAX_SERIES_PARTICLES,
};

/// The tube: every length positive, then its section's fields ([`CrossSection::check`]: those
/// of its shape and no other, the wall thinner than the section allows).
pub(super) fn tube(c: &mut Checker, t: &Tube) {
    c.positive("tube.thickness_mm", t.thickness_mm);
    c.positive("tube.length_mm", t.length_mm);
    CrossSection::check(c, t);
}

/// The material: positive moduli and density, a Poisson ratio below ½, a wave speed that
/// computes; a hardening law and a rate law with every constant they need and none they do not
/// ([`material_checks`]).
pub(super) fn material(c: &mut Checker, m: &Material) {
    c.positive("material.youngs_modulus_mpa", m.youngs_modulus_mpa);
    c.range(
        "material.poisson_ratio",
        m.poisson_ratio,
        -0.99,
        0.4999,
        "must be in [-0.99, 0.4999]",
    );
    c.positive("material.yield_stress_mpa", m.yield_stress_mpa);
    c.positive("material.density_kg_m3", m.density_kg_m3);
    let elastic = m.model == MaterialModel::Elastic;
    for (field, named) in [
        ("material.hardening", m.hardening != HardeningKind::None),
        ("material.rate", m.rate != RateKind::None),
    ] {
        if elastic && named {
            c.fail(field, "is for model j2: an elastic wall never yields");
        }
    }
    material_checks::hardening(c, m);
    material_checks::rate(c, m);
}

/// The loading: the plate speed, the crush and the start ramp against the tube and the material. Returns the crush and the ramp with their defaults filled in, mm.
pub(super) fn loading(c: &mut Checker, spec: &CaseSpec) -> (f64, f64) {
    let t = &spec.tube;
    let m = &spec.material;
    let l = &spec.loading;
    c.positive("loading.plate_speed_m_s", l.plate_speed_m_s);
    let crush = l.crush_distance_or_default();
    let wave = wave_speed_m_s(m);
    let material_ok = [m.youngs_modulus_mpa, m.density_kg_m3]
        .iter()
        .all(|v| v.is_finite() && *v > 0.0);
    if material_ok && !wave.is_finite() {
        // E / ρ overflows (E = 1e308 MPa, or ρ = 1e-300 kg/m³): no time step would be
        // stable, and the run would never advance (found by tests/solver/case_fuzz.rs).
        for f in ["material.youngs_modulus_mpa", "material.density_kg_m3"] {
            c.fail(
                f,
                "gives a wave speed sqrt(E / density) too large to compute; \
                 the ratio of E (MPa) to density (kg/m³) must be below about 1e300",
            );
        }
    }
    let scaling = spec.discretization.mass_scaling;
    let run_wave = wave / scaling.sqrt();
    if run_wave.is_finite() && l.plate_speed_m_s.is_finite() && l.plate_speed_m_s > 0.5 * run_wave {
        let scaled = match scaling == 1.0 {
            true => String::new(),
            false => format!(", {:.0} m/s under mass scaling {scaling}", 0.5 * run_wave),
        };
        c.fail(
            "loading.plate_speed_m_s",
            &format!(
                "must be below half the material's wave speed ({:.0} m/s{scaled})",
                0.5 * wave
            ),
        );
    }
    if let Some(test) = l.test_speed_m_s {
        if !(test.is_finite() && test > 0.0 && test <= l.plate_speed_m_s) {
            c.fail(
                "loading.test_speed_m_s",
                "must be a speed above 0 and at most the plate speed, m/s: the test's own \
                 speed, which the plate runs faster than to save steps (empty: the plate's)",
            );
        }
    }
    c.positive("loading.crush_distance_mm", crush);
    let ramp = l.ramp_or_default_mm(crush);
    if !(ramp.is_finite() && ramp >= 0.0) {
        c.fail("loading.ramp_mm", "must be a finite number >= 0");
    } else if crush.is_finite() && ramp > crush {
        c.fail(
            "loading.ramp_mm",
            &format!("must be at most the crush distance ({crush} mm)"),
        );
    }
    let section = CrossSection::of(t);
    let room = match l.mode {
        LoadingMode::Axial => t.length_mm,
        LoadingMode::Lateral => section.bore_mm(),
    };
    if crush.is_finite() && room.is_finite() && crush >= 0.95 * room {
        let what = match l.mode {
            LoadingMode::Axial => "95 % of tube.length_mm".to_string(),
            LoadingMode::Lateral => format!("95 % of {}", section.bore_formula()),
        };
        c.fail(
            "loading.crush_distance_mm",
            &format!("must be < {what} = {:.3} mm", 0.95 * room),
        );
    }
    (crush, ramp)
}

/// The contact: a friction coefficient in range.
pub(super) fn contact(c: &mut Checker, contact: &Contact) {
    c.range(
        "contact.friction",
        contact.friction,
        0.0,
        2.0,
        "must be in [0, 2]",
    );
}

/// The largest mass scaling: 100 lengthens the step tenfold, and the kinetic energy of the
/// paper's tube, under 1 % of the internal at 10 m/s, can then reach the verdict's 5 %.
pub const MAX_MASS_SCALING: f64 = 100.0;

/// The discretization: n within the model's range, a model that fits the loading and the trigger, the cell ratio and the CFL number.
pub(super) fn discretization(c: &mut Checker, spec: &CaseSpec) {
    let l = &spec.loading;
    let d = &spec.discretization;
    if !(1.0..=MAX_MASS_SCALING).contains(&d.mass_scaling) {
        c.fail(
            "discretization.mass_scaling",
            &format!(
                "must be a number in [1, {MAX_MASS_SCALING}]: the density's factor in the \
                 equations of motion (1: none; {MAX_MASS_SCALING} makes the time step 10 times \
                 longer and inertia 100 times larger)"
            ),
        );
    }
    let max_n = d.model.max_particles_through_thickness();
    if !(1..=max_n).contains(&d.particles_through_thickness) {
        c.fail(
            "discretization.particles_through_thickness",
            &format!(
                "must be an integer in [1, {max_n}] (model {})",
                d.model.name()
            ),
        );
    }
    let section = CrossSection::of(&spec.tube);
    if d.model == Model::Axisymmetric && !section.revolves() {
        let reason = format!(
            "axisymmetric needs a round tube: a {} section has no axis of symmetry to revolve \
             about (use model 3d)",
            section.name()
        );
        c.fail("discretization.model", &reason);
        c.fail("tube.section", &reason);
    }
    match (d.model, l.mode) {
        (Model::Axisymmetric, LoadingMode::Lateral) => c.fail(
            "discretization.model",
            "axisymmetric needs axial loading: a lateral crush is not axisymmetric \
             (use plane_strain)",
        ),
        (Model::PlaneStrain, LoadingMode::Axial) => c.fail(
            "discretization.model",
            "plane_strain needs lateral loading: an axial crush is not plane strain \
             (use axisymmetric)",
        ),
        _ => {}
    }
    if d.model != Model::ThreeD && spec.trigger.weak_fraction > 0.0 {
        let reason = format!(
            "a trigger's weak particles lie at random places around and along the tube, \
             which the {} section cannot hold: set trigger.weak_fraction to 0 or use model 3d",
            d.model.name()
        );
        c.fail("discretization.model", &reason);
        c.fail("trigger.weak_fraction", &reason);
    }
    c.range(
        "discretization.cell_to_particle_ratio",
        d.cell_to_particle_ratio,
        1.0,
        4.0,
        "must be in [1, 4]",
    );
    if d.cfl
        .is_some_and(|a| !(a.is_finite() && a > 0.0 && a <= 1.0))
    {
        c.fail("discretization.cfl", "must be > 0 and <= 1");
    }
}

/// The trigger: a weak fraction and strength ratio in range.
pub(super) fn trigger(c: &mut Checker, g: &Trigger) {
    c.range(
        "trigger.weak_fraction",
        g.weak_fraction,
        0.0,
        0.1,
        "must be in [0, 0.1]",
    );
    if !(g.strength_ratio.is_finite() && g.strength_ratio > 0.0 && g.strength_ratio <= 1.0) {
        c.fail("trigger.strength_ratio", "must be > 0 and <= 1");
    }
}

/// The output: a history of a sensible length; no series, or one of at least two frames (the
/// start and the end) and at most [`MAX_FRAMES`].
pub(super) fn output(c: &mut Checker, o: &Output) {
    if !(10..=100_000).contains(&o.history_points) {
        c.fail(
            "output.history_points",
            "must be an integer in [10, 100000]",
        );
    }
    if o.frames == 1 || o.frames > MAX_FRAMES {
        c.fail(
            "output.frames",
            &format!(
                "must be 0 (no time series) or an integer in [2, {MAX_FRAMES}]: the first frame \
                 is the start and the last the end of the crush"
            ),
        );
    }
}

/// A series of at most [`MAX_SERIES_PARTICLES`] particle states, so that its bytes are bounded.
pub(super) fn series_size(c: &mut Checker, o: &Output, particles: u64) {
    let states = o.frames as f64 * particles as f64;
    if states > MAX_SERIES_PARTICLES as f64 {
        let most = MAX_SERIES_PARTICLES / particles.max(1);
        c.fail(
            "output.frames",
            &format!(
                "gives {} frames × {particles} particles = {states:.3e} particle states, more \
                 than the {MAX_SERIES_PARTICLES} a series may hold (56 bytes each stored): this \
                 case may keep at most {most} frames",
                o.frames
            ),
        );
    }
}

/// A crush long enough for the grid to resolve ([`shortest_crush_mm`]).
pub(super) fn crush_resolved(c: &mut Checker, spec: &CaseSpec, crush: f64) {
    if let Some(shortest) = shortest_crush_mm(spec) {
        if crush.is_finite() && crush < shortest {
            c.fail(
                "loading.crush_distance_mm",
                &format!(
                    "must be at least {} mm, the plate's travel while a stress wave \
                     crosses one grid cell (plate speed × cell / sqrt(E / density)): in a \
                     shorter crush the grid cannot carry the wave, and the load is the \
                     momentum the plate gives the nodes it catches at once, which grows \
                     without bound as the crush shrinks",
                    three_digits(shortest)
                ),
            );
        }
    }
}

/// The label: at most 200 characters.
pub(super) fn label(c: &mut Checker, label: Option<&str>) {
    if let Some(label) = label {
        if label.chars().count() > 200 {
            c.fail("label", "must be at most 200 characters");
        }
    }
}

/// The shortest crush the grid resolves, mm: the plate's travel v · cell / c₀ while a stress
/// wave crosses one background cell, with the bar wave speed c₀ = √(E/ρ) (the slowest
/// longitudinal wave, so the bound is the larger one). `None` when a field it needs fails its
/// own check (that field is named instead).
///
/// A shorter crush ends before the wall can respond: the plate's first steps bring the nodes of
/// the particles it touches to its speed, whatever their mass, and the mean load is that
/// momentum over the crush, so it grows as 1 / crush and with the cell size. Measured with
/// `crush run` on the default PVC tube at 10 m/s: 455 kN (n = 2) and 204 kN (n = 4) at
/// 2e-4 mm, 46 and 21 kN at 2e-3 mm; 6.9 and 5.3 kN at 0.02 mm (about one cell's transit for
/// n = 2, two for n = 4); from 0.1 mm (five cells and more) the two agree within 1.5 % on the
/// elastic impact load of about 4.2 kN. The README's 8 mm tube at 20 m/s and n = 1 gave
/// 650 kN at 1e-3 mm, 6.5e102 N at 1e-100 mm, and a non-finite load at 1e-200 mm; its bound
/// is 0.082 mm.
fn shortest_crush_mm(spec: &CaseSpec) -> Option<f64> {
    let d = &spec.discretization;
    let m = &spec.material;
    let inputs = [
        spec.tube.thickness_mm,
        d.cell_to_particle_ratio,
        m.youngs_modulus_mpa,
        m.density_kg_m3,
        spec.loading.plate_speed_m_s,
    ];
    if d.particles_through_thickness == 0 || !inputs.iter().all(|v| v.is_finite() && *v > 0.0) {
        return None;
    }
    let cell_mm =
        spec.tube.thickness_mm / d.particles_through_thickness as f64 * d.cell_to_particle_ratio;
    let scaling = d.mass_scaling.max(1.0);
    let bar_wave_m_s = (m.youngs_modulus_mpa * 1e6 / (m.density_kg_m3 * scaling)).sqrt();
    let shortest = spec.loading.plate_speed_m_s * cell_mm / bar_wave_m_s;
    shortest.is_finite().then_some(shortest)
}

/// A length for a message, to three significant digits.
fn three_digits(x: f64) -> String {
    if !(1e-3..1e6).contains(&x) {
        return format!("{x:.2e}");
    }
    let decimals = (2 - x.log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}
