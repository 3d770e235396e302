//! The crush case: the JSON a user writes (serde, units in the field names: mm, MPa, kg/m³, m/s)
//! and its validation into a [`Case`] the rest of the solver can trust.
//!
//! Omitted fields take the PVC defaults of the design page (t = 3.2 mm, d = 22.2 mm, l = 76.2 mm,
//! E = 3378.4 MPa, ν = 0.42, σy = 65.5 MPa, ρ = 1380 kg/m³ — the density is our assumption, the
//! source gives none; rigid PVC lies between 1300 and 1450 kg/m³).

use crate::solver::model::input::{clip_quoted, object, object_from_str};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::fmt;

/// Whole case as written by a user. Every section and field may be omitted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct CaseSpec {
    /// Free text carried along with the case (not used by the physics).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    #[serde(deserialize_with = "object")]
    pub tube: Tube,
    #[serde(deserialize_with = "object")]
    pub material: Material,
    #[serde(deserialize_with = "object")]
    pub loading: Loading,
    #[serde(deserialize_with = "object")]
    pub contact: Contact,
    #[serde(deserialize_with = "object")]
    pub discretization: Discretization,
    #[serde(deserialize_with = "object")]
    pub trigger: Trigger,
    #[serde(deserialize_with = "object")]
    pub output: Output,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Tube {
    /// Wall thickness t.
    pub thickness_mm: f64,
    /// Mean diameter d, measured at the wall's mid-surface.
    pub mean_diameter_mm: f64,
    /// Length l along the tube axis.
    pub length_mm: f64,
}

impl Default for Tube {
    fn default() -> Self {
        Tube {
            thickness_mm: 3.2,
            mean_diameter_mm: 22.2,
            length_mm: 76.2,
        }
    }
}

/// Constitutive model of the wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MaterialModel {
    /// Elastic–perfectly plastic, von Mises (J2) yield, radial return.
    #[default]
    J2,
    /// Linear elastic, never yields (a stability check, not a crash material).
    Elastic,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Material {
    pub model: MaterialModel,
    pub youngs_modulus_mpa: f64,
    pub poisson_ratio: f64,
    pub yield_stress_mpa: f64,
    pub density_kg_m3: f64,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            model: MaterialModel::J2,
            youngs_modulus_mpa: 3378.4,
            poisson_ratio: 0.42,
            yield_stress_mpa: 65.5,
            density_kg_m3: 1380.0,
        }
    }
}

/// How the plates meet the tube.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LoadingMode {
    /// Plates normal to the tube axis.
    #[default]
    Axial,
    /// Tube lying between the plates, flattened across a diameter.
    Lateral,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Loading {
    pub mode: LoadingMode,
    /// Constant speed of the moving (top) plate; the bottom plate is fixed.
    pub plate_speed_m_s: f64,
    /// How far the top plate travels. Omitted: 50 mm axial, 12.5 mm lateral.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crush_distance_mm: Option<f64>,
    /// Travel over which the top plate comes up to speed (its velocity rising linearly in
    /// time), mm; 0 starts it at full speed, an impact. Part of the crush distance, at most
    /// all of it. Omitted: [`DEFAULT_RAMP_MM`], or half the crush distance if that is less.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ramp_mm: Option<f64>,
}

/// The default plate-speed ramp, mm: the shortest of those measured that brings the start
/// peak of a mild-steel tube within 2.5 % of a ramp twice as long (`docs/validation.md` §6).
pub const DEFAULT_RAMP_MM: f64 = 0.5;

impl Default for Loading {
    fn default() -> Self {
        Loading {
            mode: LoadingMode::Axial,
            plate_speed_m_s: 10.0,
            crush_distance_mm: None,
            ramp_mm: None,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Contact {
    /// Coulomb friction coefficient μ between tube and plates.
    pub friction: f64,
}

impl Default for Contact {
    fn default() -> Self {
        Contact { friction: 0.02 }
    }
}

/// Shape functions of the background grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// Trilinear hat functions (standard MPM).
    Linear,
    /// Uniform GIMP: the particle is a box of side h that never changes.
    Gimp,
}

/// The d/t from which a 3D case that names no shape function runs with linear shapes.
/// `docs/validation.md` §4, "Which shape function for which wall", holds the runs behind it:
/// at d/t 6.9 both shapes fold the paper's tube in rings and uGIMP closes its books better; at
/// d/t 9.4 and 26 uGIMP let tubes tip over that linear shapes fold progressively.
pub const LINEAR_FROM_D_OVER_T: f64 = 8.0;

impl ShapeKind {
    /// The name a case uses.
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Linear => "linear",
            ShapeKind::Gimp => "gimp",
        }
    }

    /// The shape functions for a case that names none, and why. In 3D a thin wall
    /// (d/t ≥ [`LINEAR_FROM_D_OVER_T`]) gets linear shapes: with uGIMP some such tubes fold at
    /// both plates and then tip over between the near-frictionless plates of the source, where
    /// linear shapes fold them progressively, as the source's tubes did. Every other case gets
    /// uGIMP, which converges with n where linear shapes do not (the reduced models, §7).
    pub fn default_for(tube: &Tube, model: Model) -> ShapeChoice {
        let slenderness = tube.mean_diameter_mm / tube.thickness_mm;
        let (kind, why) = match model {
            Model::ThreeD if slenderness >= LINEAR_FROM_D_OVER_T => (
                ShapeKind::Linear,
                format!(
                    "linear: the default for a thin wall (d/t = {slenderness:.1} >= \
                     {LINEAR_FROM_D_OVER_T}), which uGIMP can let tip over"
                ),
            ),
            Model::ThreeD => (
                ShapeKind::Gimp,
                format!(
                    "gimp: the default for a wall of d/t = {slenderness:.1} < {LINEAR_FROM_D_OVER_T}"
                ),
            ),
            _ => (
                ShapeKind::Gimp,
                "gimp: the default of the reduced models, where it converges".into(),
            ),
        };
        ShapeChoice {
            kind,
            default_reason: Some(why),
        }
    }
}

/// Which kinematics the solver models. The reduced models run the tube's section (the same
/// particles, grid, shape functions, contact and material as 3D, on two axes) and report
/// whole-tube loads and energies; they show only what their symmetry allows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Model {
    /// The whole tube in 3D.
    #[default]
    #[serde(rename = "3d")]
    ThreeD,
    /// The (r, z) half-plane of an axially loaded tube: every ring mode, no lobes, no buckling.
    #[serde(rename = "axisymmetric")]
    Axisymmetric,
    /// The cross-section of a laterally loaded tube, ε along the axis zero: no end effects.
    #[serde(rename = "plane_strain")]
    PlaneStrain,
}

impl Model {
    /// The name a case uses.
    pub fn name(self) -> &'static str {
        match self {
            Model::ThreeD => "3d",
            Model::Axisymmetric => "axisymmetric",
            Model::PlaneStrain => "plane_strain",
        }
    }

    /// The largest n the model accepts: a section holds n² / (3D's n²·π d / t) of the particles,
    /// so the reduced models can go far finer than 3D for the same cost.
    pub fn max_particles_through_thickness(self) -> u32 {
        match self {
            Model::ThreeD => 16,
            Model::Axisymmetric | Model::PlaneStrain => 64,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Discretization {
    /// n: particles through the wall; the particle spacing is h = t / n in every direction.
    #[serde(deserialize_with = "whole::<_, u32>")]
    pub particles_through_thickness: u32,
    /// k: background cell size = k · h.
    pub cell_to_particle_ratio: f64,
    /// α in Δt = α · cell / max(c + |v|).
    pub cfl: f64,
    /// Omitted: chosen by the wall and the model ([`ShapeKind::default_for`]);
    /// [`Case::shape`] is the one that runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeKind>,
    /// Share one volumetric strain rate and one pressure among the particles of each grid cell
    /// (as in a Q1–P0 element), against volumetric locking of the incompressible plastic flow.
    pub volumetric_averaging: bool,
    /// 3D, or a reduced model for a scene with a symmetry (see [`Model`]).
    pub model: Model,
}

impl Default for Discretization {
    fn default() -> Self {
        Discretization {
            particles_through_thickness: 4,
            cell_to_particle_ratio: 2.0,
            cfl: 0.5,
            shape: None,
            volumetric_averaging: true,
            model: Model::ThreeD,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Trigger {
    /// Fraction of tube particles made weak (0.003 in the source); 0 disables the trigger.
    pub weak_fraction: f64,
    /// Yield stress of a weak particle divided by σy.
    pub strength_ratio: f64,
    /// Seed of the random choice of weak particles.
    #[serde(deserialize_with = "whole::<_, u64>")]
    pub seed: u64,
}

impl Default for Trigger {
    fn default() -> Self {
        Trigger {
            weak_fraction: 0.0,
            strength_ratio: 0.01,
            seed: 1,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Output {
    /// Number of history rows, at equal plate-displacement intervals.
    #[serde(deserialize_with = "whole::<_, u32>")]
    pub history_points: u32,
    /// Keep the final particle state (positions and plastic strain, 16 bytes a particle) for
    /// the deformed-tube picture and the VTU download. A sweep that needs only the numbers can
    /// leave it out.
    pub final_state: bool,
}

impl Default for Output {
    fn default() -> Self {
        Output {
            history_points: 500,
            final_state: true,
        }
    }
}

/// An integer field read from any JSON number with no fractional part: JSON (and the contract's
/// JSON Schema `integer`) counts `500.0` as the integer 500, so the parser does too.
fn whole<'de, D, T>(de: D) -> Result<T, D::Error>
where
    D: serde::Deserializer<'de>,
    T: TryFrom<u64>,
{
    use serde::de::Error;
    let n = serde_json::Number::deserialize(de)?;
    let whole = match (n.as_u64(), n.as_f64()) {
        (Some(u), _) => Some(u),
        // Below 2⁶⁴ and whole: the conversion is exact.
        (None, Some(f)) if (0.0..18_446_744_073_709_551_616.0).contains(&f) && f.fract() == 0.0 => {
            Some(f as u64)
        }
        _ => None,
    };
    whole
        .and_then(|u| T::try_from(u).ok())
        .ok_or_else(|| D::Error::custom(format!("expected a whole number in range, not {n}")))
}

/// Limits a caller puts on what it is willing to run. Every count is computed in floating
/// point before it is compared, so no case can overflow its way past a limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Tube particles (never more than [`PARTICLE_ID_LIMIT`], whatever this says).
    pub max_particles: u64,
    /// Explicit steps at the initial time step.
    pub max_steps: u64,
    /// Particles × steps: the work of the run, which sets its wall time.
    pub max_particle_steps: u64,
}

/// The solver numbers particles with `u32` ids: no case may have more, whatever the limits.
pub const PARTICLE_ID_LIMIT: u64 = u32::MAX as u64;

impl Default for Limits {
    /// The server's defaults. Each admits every case in `examples/` at its own resolution with
    /// room: the costliest there, axial_t0.76_d19.81 (n = 4), needs 525 310 particles, 66 051
    /// steps and 3.47e10 particle-steps, so the margins are 9.5× on particles, 151× on steps
    /// and 14× on particle-steps (`every_example_case_fits_the_default_limits_with_room` holds
    /// them). 5e11 particle-steps is about 56 h on one thread at the estimate's 2.5 M/s; 1e7
    /// steps bounds the per-step overhead of a small case that creeps.
    fn default() -> Self {
        Limits {
            max_particles: 5_000_000,
            max_steps: 10_000_000,
            max_particle_steps: 500_000_000_000,
        }
    }
}

impl Limits {
    /// No limit but the particle ids' (bench runs, and re-reading a job that already ran).
    pub const fn unbounded() -> Limits {
        Limits {
            max_particles: PARTICLE_ID_LIMIT,
            max_steps: u64::MAX,
            max_particle_steps: u64::MAX,
        }
    }
}

/// One rejected field: its dotted path and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FieldError {
    pub field: String,
    pub reason: String,
}

/// Everything wrong with a case, every field named.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CaseError {
    /// The text is not JSON, or a field has the wrong type or an unknown name.
    #[error("malformed case: {message}")]
    Malformed {
        field: Option<String>,
        message: String,
    },
    /// The JSON parses but makes no physical or computational sense.
    #[error("invalid case: {}", list(.0))]
    Invalid(Vec<FieldError>),
}

fn list(errors: &[FieldError]) -> String {
    errors
        .iter()
        .map(|e| format!("{} {}", e.field, e.reason))
        .collect::<Vec<_>>()
        .join("; ")
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.field, self.reason)
    }
}

/// A case that has been checked: every number finite and in range, the particle count within
/// the caller's limit. Only [`Case::parse`] makes one.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    spec: CaseSpec,
    crush_distance_mm: f64,
    /// Exact, and within the limits `parse` was given.
    particles: u64,
    /// Estimated at the initial time step, within the limits `parse` was given.
    steps: u64,
    ramp_mm: f64,
    shape: ShapeChoice,
}

/// The shape functions a case runs with, and whether the case named them.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShapeChoice {
    pub kind: ShapeKind,
    /// Why the default is this one, when the case named no shape functions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default_reason: Option<String>,
}

impl Case {
    /// JSON text → valid case, or every reason it is not.
    pub fn from_json(text: &str, limits: &Limits) -> Result<Case, CaseError> {
        let spec = spec_from_json(text)?;
        Case::parse(spec, limits)
    }

    /// Checks every field and collects every failure.
    pub fn parse(spec: CaseSpec, limits: &Limits) -> Result<Case, CaseError> {
        let mut c = Checker::default();
        let t = &spec.tube;
        c.positive("tube.thickness_mm", t.thickness_mm);
        c.positive("tube.mean_diameter_mm", t.mean_diameter_mm);
        c.positive("tube.length_mm", t.length_mm);
        if t.thickness_mm.is_finite()
            && t.mean_diameter_mm.is_finite()
            && t.thickness_mm >= t.mean_diameter_mm / 2.0
        {
            c.fail(
                "tube.thickness_mm",
                "must be < mean_diameter_mm / 2 (the wall would close the bore)",
            );
        }
        let m = &spec.material;
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
        let l = &spec.loading;
        c.positive("loading.plate_speed_m_s", l.plate_speed_m_s);
        let crush = l.crush_distance_mm.unwrap_or(match l.mode {
            LoadingMode::Axial => 50.0,
            LoadingMode::Lateral => 12.5,
        });
        let wave = wave_speed_m_s(m);
        let material_ok = [m.youngs_modulus_mpa, m.density_kg_m3]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0);
        if material_ok && !wave.is_finite() {
            // E / ρ overflows (E = 1e308 MPa, or ρ = 1e-300 kg/m³): no time step would be
            // stable, and the run would never advance (found by tests/case_fuzz.rs).
            for f in ["material.youngs_modulus_mpa", "material.density_kg_m3"] {
                c.fail(
                    f,
                    "gives a wave speed sqrt(E / density) too large to compute; \
                     the ratio of E (MPa) to density (kg/m³) must be below about 1e300",
                );
            }
        }
        if wave.is_finite() && l.plate_speed_m_s.is_finite() && l.plate_speed_m_s > 0.5 * wave {
            c.fail(
                "loading.plate_speed_m_s",
                &format!(
                    "must be below half the material's wave speed ({:.0} m/s)",
                    0.5 * wave
                ),
            );
        }
        c.positive("loading.crush_distance_mm", crush);
        let ramp = l.ramp_mm.unwrap_or(DEFAULT_RAMP_MM.min(0.5 * crush));
        if !(ramp.is_finite() && ramp >= 0.0) {
            c.fail("loading.ramp_mm", "must be a finite number >= 0");
        } else if crush.is_finite() && ramp > crush {
            c.fail(
                "loading.ramp_mm",
                &format!("must be at most the crush distance ({crush} mm)"),
            );
        }
        let room = match l.mode {
            LoadingMode::Axial => t.length_mm,
            LoadingMode::Lateral => t.mean_diameter_mm - t.thickness_mm,
        };
        if crush.is_finite() && room.is_finite() && crush >= 0.95 * room {
            let what = match l.mode {
                LoadingMode::Axial => "95 % of tube.length_mm",
                LoadingMode::Lateral => "95 % of the bore (mean_diameter_mm - thickness_mm)",
            };
            c.fail(
                "loading.crush_distance_mm",
                &format!("must be < {what} = {:.3} mm", 0.95 * room),
            );
        }
        c.range(
            "contact.friction",
            spec.contact.friction,
            0.0,
            2.0,
            "must be in [0, 2]",
        );
        let d = &spec.discretization;
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
        if !(d.cfl.is_finite() && d.cfl > 0.0 && d.cfl <= 1.0) {
            c.fail("discretization.cfl", "must be > 0 and <= 1");
        }
        let g = &spec.trigger;
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
        if !(10..=100_000).contains(&spec.output.history_points) {
            c.fail(
                "output.history_points",
                "must be an integer in [10, 100000]",
            );
        }
        if let Some(shortest) = shortest_crush_mm(&spec) {
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
        if let Some(label) = &spec.label {
            if label.chars().count() > 200 {
                c.fail("label", "must be at most 200 characters");
            }
        }
        if !c.errors.is_empty() {
            return Err(CaseError::Invalid(c.errors));
        }
        let (particles, steps) = c.costs(&spec, crush, limits);
        match (particles, steps) {
            (Some(particles), Some(steps)) if c.errors.is_empty() => Ok(Case {
                shape: match spec.discretization.shape {
                    Some(kind) => ShapeChoice {
                        kind,
                        default_reason: None,
                    },
                    None => ShapeKind::default_for(&spec.tube, d.model),
                },
                spec,
                crush_distance_mm: crush,
                particles,
                steps,
                ramp_mm: ramp,
            }),
            _ => Err(CaseError::Invalid(c.errors)),
        }
    }

    pub fn spec(&self) -> &CaseSpec {
        &self.spec
    }

    /// Particle spacing h = t / n, mm.
    pub fn spacing_mm(&self) -> f64 {
        self.spec.tube.thickness_mm / self.spec.discretization.particles_through_thickness as f64
    }

    /// Background cell size k · h, mm.
    pub fn cell_mm(&self) -> f64 {
        self.spacing_mm() * self.spec.discretization.cell_to_particle_ratio
    }

    /// The shape functions the case runs with: its own, or the default for its wall.
    pub fn shape(&self) -> ShapeKind {
        self.shape.kind
    }

    /// [`Case::shape`] with whether, and why, it was chosen for the case.
    pub fn shape_choice(&self) -> &ShapeChoice {
        &self.shape
    }

    /// Crush distance with the mode's default filled in, mm.
    pub fn crush_distance_mm(&self) -> f64 {
        self.crush_distance_mm
    }

    /// Start ramp with its default filled in, mm.
    pub fn ramp_mm(&self) -> f64 {
        self.ramp_mm
    }

    /// Number of tube particles the scene will hold.
    pub fn particle_count(&self) -> u64 {
        self.particles
    }

    /// Explicit steps to the end of the crush at the initial time step (the estimate the
    /// limits were checked against; the run takes more where the material stiffens).
    pub fn step_count(&self) -> u64 {
        self.steps
    }

    /// Dilatational wave speed of the undeformed material, m/s (= mm/ms).
    pub fn wave_speed_m_s(&self) -> f64 {
        wave_speed_m_s(&self.spec.material)
    }
}

/// Every field a case can set, as dotted paths (`tube.thickness_mm`, `label`).
pub fn field_paths() -> Vec<String> {
    // Every optional field filled in, so that the serialized case names it.
    let mut full = CaseSpec {
        label: Some(String::new()),
        ..CaseSpec::default()
    };
    full.loading.crush_distance_mm = Some(0.0);
    full.loading.ramp_mm = Some(0.0);
    full.discretization.shape = Some(ShapeKind::Gimp);
    let Ok(Value::Object(sections)) = serde_json::to_value(&full) else {
        unreachable!("a case serializes to an object")
    };
    let mut paths = Vec::new();
    for (name, value) in sections {
        match value {
            Value::Object(fields) => paths.extend(fields.keys().map(|f| format!("{name}.{f}"))),
            _ => paths.push(name),
        }
    }
    paths
}

/// JSON text → spec, naming the field of a type error, an unknown field or a key given twice.
/// The text must be one JSON object and nothing after it: serde would read a struct from an
/// array (`[]` is then the default case) and stop before trailing text.
pub fn spec_from_json(text: &str) -> Result<CaseSpec, CaseError> {
    spec_from_value(&Value::Object(object_from_json(text)?))
}

/// JSON text → the one object it holds, every key once ([`object_from_str`]), as a case error.
pub fn object_from_json(text: &str) -> Result<serde_json::Map<String, Value>, CaseError> {
    object_from_str(text).map_err(|e| CaseError::Malformed {
        field: e.field,
        message: e.message,
    })
}

/// A JSON value (read strictly, see [`object_from_json`]) → spec, naming the field of a type
/// error or an unknown field; what the message quotes of the client's text is clipped.
pub fn spec_from_value(value: &Value) -> Result<CaseSpec, CaseError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        CaseError::Malformed {
            field: (path != "." && !path.is_empty())
                .then(|| super::input::clip(&path).into_owned()),
            message: clip_quoted(&e.inner().to_string()),
        }
    })
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
    let bar_wave_m_s = (m.youngs_modulus_mpa * 1e6 / m.density_kg_m3).sqrt();
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

/// c = √(E(1−ν) / ((1+ν)(1−2ν)ρ)) in m/s, from E in MPa and ρ in kg/m³.
fn wave_speed_m_s(m: &Material) -> f64 {
    let nu = m.poisson_ratio;
    let modulus_pa = m.youngs_modulus_mpa * 1e6 * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    (modulus_pa / m.density_kg_m3).sqrt()
}

/// Counts particles exactly as the scene lays them out (see `scene.rs`). Only for a case whose
/// [`particles_f64`] is within [`PARTICLE_ID_LIMIT`]: every term then fits a u64.
fn particle_count(spec: &CaseSpec) -> u64 {
    let t = spec.tube.thickness_mm;
    let n = spec.discretization.particles_through_thickness as u64;
    let h = t / n as f64;
    let inner = spec.tube.mean_diameter_mm / 2.0 - t / 2.0;
    let axial = layers_along(spec.tube.length_mm, h);
    let around_all = || {
        (0..n)
            .map(|j| around(inner + (j as f64 + 0.5) * h, h))
            .sum::<u64>()
    };
    match spec.discretization.model {
        Model::ThreeD => around_all() * axial,
        // The (r, z) section: n layers by the layers along.
        Model::Axisymmetric => n * axial,
        // The cross-section: the rings of one layer along.
        Model::PlaneStrain => around_all(),
    }
}

/// The same count in floating point, for any case whose fields passed their own checks: it
/// cannot wrap or saturate (it may be infinite). Exact below 2⁵³, as every term is an integer.
fn particles_f64(spec: &CaseSpec) -> f64 {
    let t = spec.tube.thickness_mm;
    let n = spec.discretization.particles_through_thickness as f64;
    let h = t / n;
    let inner = spec.tube.mean_diameter_mm / 2.0 - t / 2.0;
    let axial = (spec.tube.length_mm / h).round().max(1.0);
    let around_all = || -> f64 {
        (0..spec.discretization.particles_through_thickness)
            .map(|j| {
                let r = inner + (j as f64 + 0.5) * h;
                (2.0 * std::f64::consts::PI * r / h).round().max(8.0)
            })
            .sum()
    };
    match spec.discretization.model {
        Model::ThreeD => around_all() * axial,
        Model::Axisymmetric => n * axial,
        Model::PlaneStrain => around_all(),
    }
}

/// Explicit steps at the initial time step, Δt = α · cell / (c + v), in floating point; at
/// least one per history row.
fn steps_f64(spec: &CaseSpec, crush_mm: f64) -> f64 {
    let d = &spec.discretization;
    let cell =
        spec.tube.thickness_mm / d.particles_through_thickness as f64 * d.cell_to_particle_ratio;
    let speed = spec.loading.plate_speed_m_s;
    let dt_ms = d.cfl * cell / (wave_speed_m_s(&spec.material) + speed);
    let steps = crush_mm / speed / dt_ms;
    // At least one: a crush of 5e-324 mm underflows to no steps at all; and 0 / 0 (the same
    // underflow over a Δt of 0) is too many, not one (both found by tests/case_fuzz.rs).
    if steps.is_nan() {
        f64::INFINITY
    } else {
        // The run ends each history interval on a step of its own.
        steps.ceil().max(spec.output.history_points as f64).max(1.0)
    }
}

/// Fields that set the particle count.
const PARTICLE_FIELDS: &[&str] = &[
    "tube.thickness_mm",
    "tube.mean_diameter_mm",
    "tube.length_mm",
    "discretization.particles_through_thickness",
];

/// Fields that set the step count: the duration crush / v over Δt = α · k · t / n / (c + v),
/// with the wave speed c from E, ν and ρ.
const STEP_FIELDS: &[&str] = &[
    "loading.plate_speed_m_s",
    "loading.crush_distance_mm",
    "discretization.cfl",
    "discretization.cell_to_particle_ratio",
    "discretization.particles_through_thickness",
    "tube.thickness_mm",
    "material.youngs_modulus_mpa",
    "material.poisson_ratio",
    "material.density_kg_m3",
];

/// A count for a message: whole below a billion, else in scientific notation.
fn count(x: f64) -> String {
    if !x.is_finite() {
        "more than 1.8e308".into()
    } else if x < 1e9 {
        format!("{x:.0}")
    } else {
        format!("{x:.2e}")
    }
}

/// Particles around a ring of radius r at spacing h (at least 8).
pub(crate) fn around(r: f64, h: f64) -> u64 {
    ((2.0 * std::f64::consts::PI * r / h).round() as u64).max(8)
}

/// Particle layers along a length at spacing h (at least 1).
pub(crate) fn layers_along(length: f64, h: f64) -> u64 {
    ((length / h).round() as u64).max(1)
}

#[derive(Default)]
struct Checker {
    errors: Vec<FieldError>,
}

impl Checker {
    fn fail(&mut self, field: &str, reason: &str) {
        self.errors.push(FieldError {
            field: field.into(),
            reason: reason.into(),
        });
    }
    fn positive(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(field, "must be a finite number > 0");
        }
    }
    fn range(&mut self, field: &str, v: f64, lo: f64, hi: f64, reason: &str) {
        if !(v.is_finite() && v >= lo && v <= hi) {
            self.fail(field, reason);
        }
    }
    fn fail_all(&mut self, fields: &[&str], reason: &str) {
        for f in fields {
            self.fail(f, reason);
        }
    }

    /// Particles and steps of a case whose fields each passed, or the fields that drive
    /// whichever cost is over its limit, each named with the estimate.
    fn costs(
        &mut self,
        spec: &CaseSpec,
        crush: f64,
        limits: &Limits,
    ) -> (Option<u64>, Option<u64>) {
        let max_particles = limits.max_particles.min(PARTICLE_ID_LIMIT);
        let particles = particles_f64(spec);
        let particles = if particles.is_finite() && particles <= max_particles as f64 {
            Some(particle_count(spec))
        } else {
            self.fail_all(
                PARTICLE_FIELDS,
                &format!(
                    "gives {} particles, more than this runner's limit of {max_particles} \
                     (the count grows as mean_diameter_mm · length_mm · n² / thickness_mm²)",
                    count(particles)
                ),
            );
            None
        };
        let steps = steps_f64(spec, crush);
        let steps = if steps.is_finite() && steps <= limits.max_steps as f64 {
            Some(steps as u64)
        } else {
            self.fail_all(
                STEP_FIELDS,
                &format!(
                    "gives {} time steps, more than this runner's limit of {} (steps = \
                     crush distance / plate speed / Δt, Δt = cfl · cell / (wave speed + plate \
                     speed), cell = k · thickness / n)",
                    count(steps),
                    limits.max_steps
                ),
            );
            None
        };
        if let (Some(p), Some(s)) = (particles, steps) {
            let work = p as f64 * s as f64;
            if work > limits.max_particle_steps as f64 {
                let mut fields: Vec<&str> = PARTICLE_FIELDS.to_vec();
                fields.extend(STEP_FIELDS.iter().filter(|f| !PARTICLE_FIELDS.contains(f)));
                self.fail_all(
                    &fields,
                    &format!(
                        "gives {p} particles × {s} time steps = {} particle-steps, more than \
                         this runner's limit of {}",
                        count(work),
                        limits.max_particle_steps
                    ),
                );
            }
        }
        (particles, steps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tube of wall t and diameter d with the given discretization JSON, checked.
    fn tube_case(t: f64, d: f64, discretization: &str) -> Case {
        let text = format!(
            r#"{{"tube": {{"thickness_mm": {t}, "mean_diameter_mm": {d}, "length_mm": 10}},
                "loading": {{"crush_distance_mm": 5}},
                "discretization": {discretization}}}"#
        );
        Case::from_json(&text, &Limits::default()).unwrap()
    }

    #[test]
    fn the_default_shape_follows_the_wall_in_3d_and_is_gimp_in_the_sections() {
        // The paper's thick tube (d/t 6.9) and the t 1.27, d 10 tube (d/t 7.9): uGIMP.
        for (t, d) in [(3.2, 22.2), (1.27, 10.0)] {
            let case = tube_case(t, d, "{}");
            assert_eq!(case.shape(), ShapeKind::Gimp, "t {t} d {d}");
            let why = case.shape_choice().default_reason.clone().unwrap();
            let d_over_t = format!("{:.1}", d / t);
            assert_eq!(
                why,
                format!("gimp: the default for a wall of d/t = {d_over_t} < 8")
            );
        }
        // The thin tubes (d/t 9.4–26.1) and the threshold itself: linear, with d/t in the
        // reason.
        for (t, d) in [(1.27, 12.0), (1.27, 20.32)] {
            assert_eq!(
                tube_case(t, d, "{}").shape(),
                ShapeKind::Linear,
                "t {t} d {d}"
            );
        }
        let thin = tube_case(0.76, 19.81, "{}");
        assert_eq!(thin.shape(), ShapeKind::Linear);
        assert_eq!(
            thin.shape_choice().default_reason.as_deref(),
            Some(
                "linear: the default for a thin wall (d/t = 26.1 >= 8), \
                 which uGIMP can let tip over"
            )
        );
        let at = tube_case(1.0, LINEAR_FROM_D_OVER_T, "{}");
        assert_eq!(at.shape(), ShapeKind::Linear);
        let below = tube_case(1.0, LINEAR_FROM_D_OVER_T - 0.01, "{}");
        assert_eq!(below.shape(), ShapeKind::Gimp);
        // A reduced model has no global buckling to lose: uGIMP, which converges there.
        let section = tube_case(0.76, 19.81, r#"{"model": "axisymmetric"}"#);
        assert_eq!(section.shape(), ShapeKind::Gimp);
        // A named shape (or null, which is the default) is kept; only the default has a reason.
        for named in [ShapeKind::Gimp, ShapeKind::Linear] {
            let text = format!(r#"{{"shape": "{}"}}"#, named.name());
            for (t, d) in [(3.2, 22.2), (0.76, 19.81)] {
                let case = tube_case(t, d, &text);
                assert_eq!(case.shape(), named);
                assert_eq!(case.shape_choice().default_reason, None);
            }
        }
        assert_eq!(
            tube_case(0.76, 19.81, r#"{"shape": null}"#).shape(),
            ShapeKind::Linear
        );
        // The spec keeps what the user wrote: no shape stays no shape.
        assert!(serde_json::to_value(thin.spec()).unwrap()["discretization"]
            .get("shape")
            .is_none());
    }

    #[test]
    fn empty_object_is_the_pvc_default() {
        let case = Case::from_json("{}", &Limits::default()).unwrap();
        assert_eq!(case.spec().tube.thickness_mm, 3.2);
        assert_eq!(case.crush_distance_mm(), 50.0);
        // 2π·11.1/0.8 etc.: the n = 4 lattice of the design page holds about 35 k particles.
        let n = case.particle_count();
        assert!((33_000..37_000).contains(&n), "{n}");
    }

    #[test]
    fn n6_lattice_matches_the_source_particle_count() {
        let mut spec = CaseSpec::default();
        spec.discretization.particles_through_thickness = 6;
        let n = Case::parse(spec, &Limits::default())
            .unwrap()
            .particle_count();
        // The source reports about 113 k particles at n = 6; within 3 %.
        assert!((n as f64 / 113_000.0 - 1.0).abs() < 0.03, "{n}");
    }

    #[test]
    fn every_bad_field_is_named() {
        let text = r#"{"tube": {"thickness_mm": 12, "mean_diameter_mm": 22.2},
            "material": {"poisson_ratio": 0.5, "density_kg_m3": -1},
            "loading": {"plate_speed_m_s": -3},
            "discretization": {"cfl": 0, "particles_through_thickness": 0},
            "trigger": {"weak_fraction": 0.5},
            "output": {"history_points": 1}}"#;
        let Err(CaseError::Invalid(errors)) = Case::from_json(text, &Limits::default()) else {
            panic!("accepted a bad case")
        };
        let fields: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
        for f in [
            "tube.thickness_mm",
            "material.poisson_ratio",
            "material.density_kg_m3",
            "loading.plate_speed_m_s",
            "discretization.cfl",
            "discretization.particles_through_thickness",
            "trigger.weak_fraction",
            "output.history_points",
        ] {
            assert!(fields.contains(&f), "{f} not named in {fields:?}");
        }
    }

    #[test]
    fn too_many_particles_is_rejected_with_the_count() {
        let text = r#"{"discretization": {"particles_through_thickness": 10}}"#;
        let err = Case::from_json(
            text,
            &Limits {
                max_particles: 100_000,
                ..Limits::default()
            },
        )
        .unwrap_err();
        assert!(
            err.to_string().contains("particles_through_thickness"),
            "{err}"
        );
        assert!(err.to_string().contains("limit of 100000"), "{err}");
    }

    /// The fields a rejection names, or a panic if the case was accepted.
    fn rejected_fields(text: &str, limits: &Limits) -> Vec<FieldError> {
        match Case::from_json(text, limits) {
            Err(CaseError::Invalid(errors)) => errors,
            Err(e) => panic!("{text}: malformed? {e}"),
            Ok(case) => panic!(
                "{text}: accepted with {} particles, {} steps",
                case.particle_count(),
                case.step_count()
            ),
        }
    }

    #[test]
    fn a_wall_of_1e_300_mm_is_refused_not_counted_as_4_particles() {
        // Issue 10: the u64 count saturated and wrapped to 4, the case was accepted and the
        // scene tried to build ~2⁶⁴ particles.
        let errors = rejected_fields(r#"{"tube":{"thickness_mm":1e-300}}"#, &Limits::default());
        let named: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
        assert!(named.contains(&"tube.thickness_mm"), "{errors:?}");
        let reason = &errors[0].reason;
        assert!(
            reason.contains("particles") && reason.contains("5000000"),
            "{reason}"
        );
    }

    #[test]
    fn a_kilometre_tube_is_refused_not_counted_as_0_particles() {
        // Issue 10: 2⁶⁴ particles exactly wrapped to 0.
        let text = r#"{"tube":{"thickness_mm":1,"mean_diameter_mm":1367130551.2,"length_mm":4294967296},"discretization":{"particles_through_thickness":1}}"#;
        let errors = rejected_fields(text, &Limits::unbounded());
        assert!(
            errors.iter().any(|e| e.field == "tube.mean_diameter_mm"
                && e.reason.contains("gives 1.84e19 particles")),
            "{errors:?}"
        );
    }

    #[test]
    fn a_1e300_mm_tube_reports_its_count_without_saturating() {
        // Issue 10: the 422 said "gives 18446744073709551267 particles" (a saturated u64).
        let errors = rejected_fields(r#"{"tube":{"length_mm":1e300}}"#, &Limits::default());
        let reason = &errors
            .iter()
            .find(|e| e.field == "tube.length_mm")
            .unwrap()
            .reason;
        assert!(reason.contains("e30"), "{reason}");
        assert!(!reason.contains("18446744073709551"), "{reason}");
    }

    #[test]
    fn no_limit_admits_more_particles_than_their_u32_ids() {
        // Even unbounded, n = 16 through a 1e-3 mm wall of a 1 m tube is refused.
        let text = r#"{"tube":{"thickness_mm":0.001,"length_mm":1000},"discretization":{"particles_through_thickness":16}}"#;
        let errors = rejected_fields(text, &Limits::unbounded());
        assert!(
            errors[0].reason.contains(&PARTICLE_ID_LIMIT.to_string()),
            "{errors:?}"
        );
    }

    #[test]
    fn a_plate_speed_of_1e_300_is_refused_for_its_steps() {
        // Issue 10: accepted with an estimate of 1.8e19 steps (a saturated u64).
        let errors = rejected_fields(
            r#"{"loading":{"plate_speed_m_s":1e-300}}"#,
            &Limits::default(),
        );
        let named: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
        for f in [
            "loading.plate_speed_m_s",
            "discretization.cfl",
            "loading.crush_distance_mm",
        ] {
            assert!(named.contains(&f), "{f} not in {named:?}");
        }
        assert!(errors[0].reason.contains("time steps"), "{errors:?}");
        // Unbounded steps still refuses what no u64 can count.
        rejected_fields(
            r#"{"loading":{"plate_speed_m_s":1e-300}}"#,
            &Limits::unbounded(),
        );
    }

    #[test]
    fn extreme_material_values_are_refused_for_their_steps() {
        // Issue 10's probe: each of these exceeded 1e8 steps and was accepted.
        for text in [
            r#"{"loading":{"plate_speed_m_s":1e-9}}"#,
            r#"{"discretization":{"cfl":5e-324}}"#,
            r#"{"material":{"youngs_modulus_mpa":1e308}}"#,
            r#"{"material":{"density_kg_m3":1e-308}}"#,
        ] {
            let errors = rejected_fields(text, &Limits::default());
            assert!(
                errors
                    .iter()
                    .all(|e| STEP_FIELDS.contains(&e.field.as_str())),
                "{text}: {errors:?}"
            );
        }
    }

    #[test]
    fn an_infinite_wave_speed_is_refused_not_run_with_a_zero_time_step() {
        // Found by tests/case_fuzz.rs: ρ = 1e-300 gave c = ∞, Δt = 0, and with a crush of
        // 5e-324 mm, 0 / 0 steps, which counted as one: the run would never advance.
        let text =
            r#"{"material":{"density_kg_m3":1e-300},"loading":{"crush_distance_mm":5e-324}}"#;
        let errors = rejected_fields(text, &Limits::unbounded());
        assert!(
            errors.iter().any(|e| e.field == "material.density_kg_m3"),
            "{errors:?}"
        );
    }

    #[test]
    fn a_crush_shorter_than_a_waves_transit_of_one_cell_is_refused_with_the_bound() {
        // The README's 8 mm tube at 20 m/s, n = 1 (cell 6.4 mm, bar wave 1565 m/s): 0.0818 mm.
        let tiny = |crush: &str| {
            format!(
                r#"{{"tube": {{"thickness_mm": 3.2, "mean_diameter_mm": 22.2, "length_mm": 8}},
                    "discretization": {{"particles_through_thickness": 1}},
                    "loading": {{"crush_distance_mm": {crush}, "plate_speed_m_s": 20}},
                    "output": {{"history_points": 20}}}}"#
            )
        };
        // Run anyway: 650 kN, 6.5e102 N and a non-finite load; 5e-324 underflows the steps.
        for crush in ["1e-3", "1e-100", "1e-200", "5e-324", "0.08"] {
            let errors = rejected_fields(&tiny(crush), &Limits::default());
            assert_eq!(errors.len(), 1, "{crush}: {errors:?}");
            assert_eq!(errors[0].field, "loading.crush_distance_mm");
            assert!(
                errors[0].reason.contains("at least 0.0818 mm"),
                "{errors:?}"
            );
        }
        assert!(Case::from_json(&tiny("0.082"), &Limits::default()).is_ok());
        assert!(Case::from_json(&tiny("1"), &Limits::default()).is_ok());
        // The bound follows the cell and the wave speed: n = 4 quarters it, and so does a
        // material with 16 times the stiffness.
        let finer = tiny("0.03").replace(
            r#""particles_through_thickness": 1"#,
            r#""particles_through_thickness": 4"#,
        );
        assert!(Case::from_json(&finer, &Limits::default()).is_ok());
        let stiff = tiny("0.03").replace(
            r#""output""#,
            r#""material": {"youngs_modulus_mpa": 54054.4}, "output""#,
        );
        assert!(Case::from_json(&stiff, &Limits::default()).is_ok());
        // With a field it needs out of range, that field is named alone.
        let errors = rejected_fields(
            r#"{"loading": {"crush_distance_mm": 1e-9}, "material": {"density_kg_m3": -1}}"#,
            &Limits::default(),
        );
        let named: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
        assert_eq!(named, ["material.density_kg_m3"]);
    }

    #[test]
    fn too_much_work_names_every_field_that_drives_it() {
        let limits = Limits {
            max_particle_steps: 1_000_000,
            ..Limits::default()
        };
        let errors = rejected_fields("{}", &limits);
        let named: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
        for f in PARTICLE_FIELDS.iter().chain(STEP_FIELDS) {
            assert!(named.contains(f), "{f} not in {named:?}");
        }
        assert!(errors[0].reason.contains("particle-steps"), "{errors:?}");
    }

    /// A reduced model that does not fit the scene is refused with the field and the reason.
    #[test]
    fn a_reduced_model_must_fit_the_scene() {
        let fields = |text: &str| match Case::from_json(text, &Limits::default()) {
            Err(CaseError::Invalid(errors)) => errors
                .into_iter()
                .map(|e| (e.field, e.reason))
                .collect::<Vec<_>>(),
            other => panic!("{text}: {other:?}"),
        };
        let e = fields(
            r#"{"loading": {"mode": "lateral"}, "discretization": {"model": "axisymmetric"}}"#,
        );
        assert_eq!(e.len(), 1);
        assert_eq!(e[0].0, "discretization.model");
        assert!(e[0].1.contains("not axisymmetric"), "{e:?}");
        let e = fields(r#"{"discretization": {"model": "plane_strain"}}"#);
        assert!(
            e[0].0 == "discretization.model" && e[0].1.contains("lateral"),
            "{e:?}"
        );
        let e = fields(
            r#"{"discretization": {"model": "axisymmetric"}, "trigger": {"weak_fraction": 0.003}}"#,
        );
        let named: Vec<&str> = e.iter().map(|e| e.0.as_str()).collect();
        assert_eq!(named, ["discretization.model", "trigger.weak_fraction"]);
        // 3D stops at n = 16; a section at 64.
        let e = fields(r#"{"discretization": {"particles_through_thickness": 17}}"#);
        assert!(e[0].1.contains("[1, 16]"), "{e:?}");
        let fine =
            r#"{"discretization": {"particles_through_thickness": 64, "model": "axisymmetric"}}"#;
        assert!(Case::from_json(fine, &Limits::default()).is_ok());
        let e = fields(&fine.replace("64", "65"));
        assert!(e[0].1.contains("[1, 64]"), "{e:?}");
    }

    /// A section's particle count: n layers by the layers along (axisymmetric), the rings of
    /// one layer along (plane strain); the scene lays out exactly that many.
    #[test]
    fn a_section_counts_what_its_scene_lays_out() {
        for (text, want) in [
            (
                r#"{"discretization": {"particles_through_thickness": 6, "model": "axisymmetric"}}"#,
                6 * 143,
            ),
            (
                r#"{"loading": {"mode": "lateral"}, "discretization": {"model": "plane_strain"}}"#,
                0,
            ),
        ] {
            let case = Case::from_json(text, &Limits::default()).unwrap();
            let scene = crate::solver::engine::scene::Scene::from_case(&case);
            assert_eq!(
                scene.particles.len() as u64,
                case.particle_count(),
                "{text}"
            );
            if want > 0 {
                assert_eq!(case.particle_count(), want);
            }
            // The section's volumes add up to the tube's, π·d·t·l.
            let vol: f64 = scene.particles.vol.iter().sum();
            let exact = std::f64::consts::PI * 22.2 * 3.2 * 76.2;
            assert!(
                (vol / exact - 1.0).abs() < 1e-12,
                "{text}: {vol} vs {exact}"
            );
        }
    }

    #[test]
    fn every_example_case_fits_the_default_limits_with_room() {
        // The margins stated on `Limits::default`: an example that needs more than a fifth
        // of a limit fails this, so the default cannot drift down to where examples no longer
        // run at their own resolution.
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
        let limits = Limits::default();
        let mut seen = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            let case = Case::from_json(&text, &limits)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let (p, s) = (case.particle_count(), case.step_count());
            let name = path.display();
            assert!(p * 5 <= limits.max_particles, "{name}: {p} particles");
            assert!(s * 5 <= limits.max_steps, "{name}: {s} steps");
            assert!(p * s * 5 <= limits.max_particle_steps, "{name}: {p} × {s}");
            seen += 1;
        }
        assert!(seen >= 7);
    }

    #[test]
    fn type_errors_and_unknown_fields_name_the_field() {
        let Err(CaseError::Malformed { field, .. }) =
            Case::from_json(r#"{"tube": {"thickness_mm": "thick"}}"#, &Limits::default())
        else {
            panic!()
        };
        assert_eq!(field.as_deref(), Some("tube.thickness_mm"));
        let err = Case::from_json(r#"{"tube": {"wall": 1}}"#, &Limits::default()).unwrap_err();
        assert!(err.to_string().contains("wall"), "{err}");
        assert!(Case::from_json("{", &Limits::default()).is_err());
    }

    #[test]
    fn an_array_or_trailing_text_is_not_a_case() {
        // Issue 10: `[]` was read as the default case, and `/v1/estimate` took `{} x` and `{}{}`.
        for text in [
            "[]", "[1]", "3", "\"{}\"", "null", "{} x", "{}{}", "{} {}", "{},",
        ] {
            match Case::from_json(text, &Limits::default()) {
                Err(CaseError::Malformed { .. }) => {}
                other => panic!("{text}: {other:?}"),
            }
        }
        assert!(Case::from_json(" {}\n ", &Limits::default()).is_ok());
    }

    #[test]
    fn whole_numbers_written_with_a_point_are_integers() {
        // schemathesis: `"seed": 7163146938.0` is an integer to JSON Schema, and was a 400.
        let text = r#"{"trigger":{"seed":7163146938.0},"output":{"history_points":1000.0},
            "discretization":{"particles_through_thickness":2.0}}"#;
        let case = Case::from_json(text, &Limits::default()).unwrap();
        assert_eq!(case.spec().trigger.seed, 7_163_146_938);
        assert_eq!(case.spec().output.history_points, 1000);
        for bad in [
            r#"{"output":{"history_points":10.5}}"#,
            r#"{"output":{"history_points":-10}}"#,
            r#"{"output":{"history_points":4294967296}}"#,
            r#"{"trigger":{"seed":1e30}}"#,
            r#"{"output":{"history_points":"10"}}"#,
        ] {
            let Err(CaseError::Malformed { field, .. }) = Case::from_json(bad, &Limits::default())
            else {
                panic!("{bad} accepted")
            };
            assert!(field.is_some(), "{bad}");
        }
    }

    #[test]
    fn the_start_ramp_defaults_within_the_crush_and_goes_no_further() {
        let ramp = |text: &str| Case::from_json(text, &Limits::default()).map(|c| c.ramp_mm());
        assert_eq!(ramp("{}").unwrap(), DEFAULT_RAMP_MM);
        assert_eq!(
            ramp(r#"{"loading": {"crush_distance_mm": 0.4}}"#).unwrap(),
            0.2
        );
        assert_eq!(ramp(r#"{"loading": {"ramp_mm": 0}}"#).unwrap(), 0.0);
        for bad in [
            r#"{"loading": {"crush_distance_mm": 2, "ramp_mm": 3}}"#,
            r#"{"loading": {"ramp_mm": -1}}"#,
        ] {
            let err = ramp(bad).unwrap_err();
            assert!(err.to_string().contains("loading.ramp_mm"), "{err}");
        }
    }

    #[test]
    fn lateral_crush_must_fit_in_the_bore() {
        let text = r#"{"loading": {"mode": "lateral", "crush_distance_mm": 30}}"#;
        let err = Case::from_json(text, &Limits::default()).unwrap_err();
        assert!(
            err.to_string().contains("loading.crush_distance_mm"),
            "{err}"
        );
    }
}
