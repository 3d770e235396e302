//! The case as a user writes it: the JSON types (serde; units in the field names: mm, MPa,
//! kg/m³, m/s), their defaults, and the reading of a case's text into them. Nothing here is
//! checked beyond types: [`super::case::Case::parse`] does that.
//!
//! Omitted fields take the PVC defaults of the design page (a round tube, t = 3.2 mm,
//! d = 22.2 mm, l = 76.2 mm, E = 3378.4 MPa, ν = 0.42, σy = 65.5 MPa, ρ = 1380 kg/m³ — the
//! density is our assumption, the source gives none; rigid PVC lies between 1300 and
//! 1450 kg/m³). The material section's own types, its presets and how a preset fills it are
//! in [`super::material::given`].

use super::input::{clip, object, object_from_str, user_message};
use super::limits::CaseError;
pub use super::material::given::{
    CurveExtrapolation, HardeningKind, Material, MaterialModel, Preset, RateKind,
};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Whole case as written by a user. Every section and field may be omitted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[schemars(
    rename = "Case",
    description = "A crush case. Every section and field may be omitted (PVC defaults); unknown fields are rejected. The bounds here are those the server enforces on each field alone (`GET /v1/case/fields` serves the same table, derived from this schema). Checks that tie fields together (a wall thinner than half the diameter, a crush shorter than the tube, a plate slower than half the wave speed, and the server's particle, step and particle-step limits) are answered with 422 naming the fields."
)]
pub struct CaseSpec {
    /// Free text carried along with the case (not used by the physics).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(
        title = "Label",
        description = "Free text, at most 200 characters, kept with the job; the job list filters on it.",
        length(max = 200)
    )]
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

/// The shape of the tube's cross-section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case")]
// `Section` in the API's schemas.
#[schemars(rename = "Section", transform = super::schema::choices)]
pub enum SectionShape {
    /// A circle of mean diameter d.
    #[default]
    Round,
    /// A rectangle of sides a × b with rounded corners (a square when a = b).
    Rectangular,
    /// A regular hexagon of side s with rounded corners.
    Hexagonal,
}

impl SectionShape {
    /// Every shape, in the schema's order.
    pub const ALL: [SectionShape; 3] = [
        SectionShape::Round,
        SectionShape::Rectangular,
        SectionShape::Hexagonal,
    ];

    /// The name a case uses.
    pub fn name(self) -> &'static str {
        match self {
            SectionShape::Round => "round",
            SectionShape::Rectangular => "rectangular",
            SectionShape::Hexagonal => "hexagonal",
        }
    }
}

/// The default mean diameter of a round tube, mm.
pub const DEFAULT_MEAN_DIAMETER_MM: f64 = 22.2;

/// The tube. Lengths of the cross-section are measured at the wall's mid-surface. A round tube
/// has a mean diameter; a rectangular one sides a and b and a corner radius, and no diameter; a
/// hexagonal one a side and a corner radius.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Tube {
    /// The cross-section's shape.
    #[schemars(
        title = "Cross-section",
        description = "round: a circle of mean diameter d. rectangular: sides a × b with rounded corners (a square when b is empty). hexagonal: a regular hexagon of side s with rounded corners, two flats facing the plates of a lateral crush."
    )]
    pub section: SectionShape,
    /// Wall thickness t.
    #[schemars(title = "Wall thickness t", description = "Less than half the mean diameter (round), less than the corner radius's double and the smaller side's half (rectangular), less than the corner radius's double and half the width across the flats (hexagonal).", extend("x-unit" = "mm", "exclusiveMinimum" = 0))]
    pub thickness_mm: f64,
    /// Round: mean diameter d, at the wall's mid-surface. Omitted: [`DEFAULT_MEAN_DIAMETER_MM`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(title = "Mean diameter d", description = "Round tubes: measured at the wall's mid-surface. Empty: 22.2 mm.", extend("x-unit" = "mm", "exclusiveMinimum" = 0))]
    pub mean_diameter_mm: Option<f64>,
    /// Length l along the tube axis.
    #[schemars(title = "Length l", description = "Along the tube axis.", extend("x-unit" = "mm", "exclusiveMinimum" = 0))]
    pub length_mm: f64,
    /// Rectangular: side a, along x in an axial crush and along y (beside the plates) in a
    /// lateral one. Required for a rectangular section.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(title = "Side a", description = "Rectangular tubes: the side along x, at the wall's mid-surface; required for them.", extend("x-unit" = "mm", "exclusiveMinimum" = 0))]
    pub side_a_mm: Option<f64>,
    /// Rectangular: side b, along y in an axial crush and between the plates (along z) in a
    /// lateral one. Omitted: a, a square tube.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(title = "Side b", description = "Rectangular tubes: the side along y (between the plates in a lateral crush), at the wall's mid-surface. Empty: side a, a square tube.", extend("x-unit" = "mm", "exclusiveMinimum" = 0))]
    pub side_b_mm: Option<f64>,
    /// Rectangular and hexagonal: radius r of the corners of the wall's mid-line, from t/2 (a
    /// sharp inner corner) to half the smaller side (rectangular) or half the width across the
    /// flats (hexagonal). Omitted: t.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(title = "Corner radius r", description = "Rectangular and hexagonal tubes: the radius of the corners of the wall's mid-line, from t/2 (a sharp inner corner) to half the smaller side (rectangular) or half the width across the flats, side · √3 / 2 (hexagonal). Empty: t.", extend("x-unit" = "mm", "exclusiveMinimum" = 0))]
    pub corner_radius_mm: Option<f64>,
    /// Hexagonal: side s of the wall's mid-line hexagon, corner to corner with the corners
    /// sharp. Required for a hexagonal section.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(title = "Hexagon side s", description = "Hexagonal tubes: the side of the wall's mid-line hexagon, corner to corner as if the corners were sharp; the width across the flats is s · √3. Required for them.", extend("x-unit" = "mm", "exclusiveMinimum" = 0))]
    pub side_mm: Option<f64>,
}

impl Tube {
    /// The lengths that belong to one shape of section or another, by field, as given (`None`
    /// where omitted): the checks refuse those of another shape than the tube's.
    pub fn section_lengths(&self) -> [(&'static str, Option<f64>); 5] {
        [
            ("tube.mean_diameter_mm", self.mean_diameter_mm),
            ("tube.side_a_mm", self.side_a_mm),
            ("tube.side_b_mm", self.side_b_mm),
            ("tube.corner_radius_mm", self.corner_radius_mm),
            ("tube.side_mm", self.side_mm),
        ]
    }
}

impl Default for Tube {
    fn default() -> Self {
        Tube {
            section: SectionShape::Round,
            thickness_mm: 3.2,
            mean_diameter_mm: Some(DEFAULT_MEAN_DIAMETER_MM),
            length_mm: 76.2,
            side_a_mm: None,
            side_b_mm: None,
            corner_radius_mm: None,
            side_mm: None,
        }
    }
}

/// How the plates meet the tube.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = super::schema::choices)]
pub enum LoadingMode {
    /// Plates normal to the tube axis.
    #[default]
    Axial,
    /// Tube lying between the plates, flattened across a diameter.
    Lateral,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Loading {
    #[schemars(
        title = "Loading",
        description = "axial: plates normal to the axis. lateral: the tube lies between the plates."
    )]
    pub mode: LoadingMode,
    /// Constant speed of the moving (top) plate; the bottom plate is fixed.
    #[schemars(title = "Plate speed", description = "Below half the material's wave speed.", extend("x-unit" = "m/s", "exclusiveMinimum" = 0))]
    pub plate_speed_m_s: f64,
    /// How far the top plate travels. Omitted: 50 mm axial, 12.5 mm lateral.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(title = "Crush distance", description = "Empty: 50 mm axial, 12.5 mm lateral. Less than 95 % of the length (axial) or of the bore (lateral), and at least the plate's travel while a stress wave crosses one grid cell, plate_speed_m_s × cell / sqrt(E / density) with cell = cell_to_particle_ratio × thickness_mm / particles_through_thickness (a shorter crush is over before the grid can carry the wave).", extend("x-unit" = "mm", "exclusiveMinimum" = 0))]
    pub crush_distance_mm: Option<f64>,
    /// Travel over which the top plate comes up to speed (its velocity rising linearly in
    /// time), mm; 0 starts it at full speed, an impact. Part of the crush distance, at most
    /// all of it. Omitted: [`DEFAULT_RAMP_MM`], or half the crush distance if that is less.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(title = "Start ramp", description = "Travel over which the plate comes up to speed (velocity rising linearly in time); 0 starts it at full speed, an impact. Empty: 0.5 mm, or half the crush distance if less. At most the crush distance.", range(min = 0), extend("x-unit" = "mm"))]
    pub ramp_mm: Option<f64>,
    /// The speed of the test the case stands for, when the plate runs faster than it to save
    /// steps, m/s: a rate law then reads every strain rate scaled by test / plate speed, the
    /// rate the test's wall saw. Omitted: the plate's speed.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(title = "Test speed", description = "The speed of the test this case stands for, when the plate runs faster than it to save steps (a quasi-static test run at 10 m/s): a strain-rate law then reads each strain rate times test / plate speed, the rate the test saw, and the verdict holds kinetic energy to 1 % of the internal. At most the plate speed. Empty: the plate's speed.", extend("x-unit" = "m/s", "exclusiveMinimum" = 0))]
    pub test_speed_m_s: Option<f64>,
}

/// The default plate-speed ramp, mm: the shortest of those measured that brings the start
/// peak of a mild-steel tube within 2.5 % of a ramp twice as long (`docs/studies.md` §6).
pub const DEFAULT_RAMP_MM: f64 = 0.5;

impl Loading {
    /// The start ramp's travel, or the default for a crush of `crush_mm` when the case names
    /// none, mm: [`DEFAULT_RAMP_MM`], or half the crush if that is less.
    pub fn ramp_or_default_mm(&self, crush_mm: f64) -> f64 {
        self.ramp_mm.unwrap_or(DEFAULT_RAMP_MM.min(0.5 * crush_mm))
    }

    /// The speed whose strain rates the material sees, m/s: the test's where the case gives
    /// one, else the plate's.
    pub fn material_speed_m_s(&self) -> f64 {
        self.test_speed_m_s.unwrap_or(self.plate_speed_m_s)
    }

    /// The factor a rate law's strain rates are read at: test / plate speed, 1 without a test
    /// speed.
    pub fn rate_scale(&self) -> f64 {
        self.test_speed_m_s
            .map_or(1.0, |test| test / self.plate_speed_m_s)
    }

    /// The crush distance, or the mode's default when the case names none, mm: 50 axial,
    /// 12.5 lateral.
    pub fn crush_distance_or_default(&self) -> f64 {
        self.crush_distance_mm.unwrap_or(match self.mode {
            LoadingMode::Axial => 50.0,
            LoadingMode::Lateral => 12.5,
        })
    }
}

impl Default for Loading {
    fn default() -> Self {
        Loading {
            mode: LoadingMode::Axial,
            plate_speed_m_s: 10.0,
            crush_distance_mm: None,
            ramp_mm: None,
            test_speed_m_s: None,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Contact {
    /// Coulomb friction coefficient μ between tube and plates. The default, 0.02, is the
    /// source's near-frictionless plates, on which the paper's tube and the error tables of
    /// docs/trust.md were measured; a steel platen on a polymer or metal tube is nearer 0.3,
    /// which the thin-tube examples use: on near-frictionless plates a slender tube's ends slide
    /// until it tips over, and a diamond tube's far end splays (docs/folding.md §2–3).
    #[schemars(
        title = "Plate friction μ",
        description = "Coulomb friction between tube and plates: 0.02 is the source's near-frictionless plates, 0.3 a steel platen's, which holds a thin tube's ends.",
        range(min = 0, max = 2)
    )]
    pub friction: f64,
}

impl Default for Contact {
    fn default() -> Self {
        Contact { friction: 0.02 }
    }
}

/// Shape functions of the background grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = super::schema::choices)]
pub enum ShapeKind {
    /// Trilinear hat functions (standard MPM).
    Linear,
    /// Uniform GIMP: the particle is a box of side h that never changes.
    Gimp,
    /// Quadratic B-splines: no cell-crossing error, three nodes per axis.
    Bspline,
}

impl ShapeKind {
    /// The name a case uses.
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Linear => "linear",
            ShapeKind::Gimp => "gimp",
            ShapeKind::Bspline => "bspline",
        }
    }
}

/// Which kinematics the solver models. The reduced models run the tube's section (the same
/// particles, grid, shape functions, contact and material as 3D, on two axes) and report
/// whole-tube loads and energies; they show only what their symmetry allows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, JsonSchema)]
#[schemars(transform = super::schema::choices)]
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

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Discretization {
    /// n: particles through the wall; the particle spacing is h = t / n in every direction.
    #[serde(deserialize_with = "whole::<_, u32>")]
    #[schemars(
        title = "Particles through the wall n",
        description = "Spacing h = t / n. At most 16 in 3D (cost about n⁴), 64 in the reduced models (cost about n³).",
        range(min = 1, max = 64)
    )]
    pub particles_through_thickness: u32,
    /// k: background cell size = k · h.
    #[schemars(
        title = "Cell size / spacing k",
        description = "Background cell size = k × h.",
        range(min = 1, max = 4)
    )]
    pub cell_to_particle_ratio: f64,
    /// α in Δt = α · cell / max(c + |v|). Omitted: chosen by the wall, the model and the shape
    /// functions ([`super::step_policy::default_cfl`]); [`super::case::Case::cfl`] is the one
    /// that runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(title = "CFL number α", description = "Δt = α · cell / max(c + |v|). Empty (auto): 0.8 for a thin wall (d/t >= 8) crushed axially in 3D on bspline shapes, 0.5 otherwise; the estimate says which runs and why.", extend("exclusiveMinimum" = 0, "maximum" = 1))]
    pub cfl: Option<f64>,
    /// Omitted: chosen by the wall and the model ([`ShapeKind::default_for`]);
    /// [`super::case::Case::shape`] is the one that runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(
        title = "Shape functions",
        description = "gimp: uniform GIMP; linear: trilinear hats; bspline: quadratic B-splines. Empty (auto): for a thin wall (d/t >= 8) in 3D, linear on near-frictionless plates (μ < 0.2) and bspline on plates that hold its ends (μ >= 0.2); else gimp; the estimate and the summary say which ran and why."
    )]
    pub shape: Option<ShapeKind>,
    /// Share one volumetric strain rate and one pressure among the particles of each grid cell
    /// (as in a Q1–P0 element), against volumetric locking of the incompressible plastic flow.
    #[schemars(
        title = "Volumetric averaging",
        description = "One volumetric strain rate and one pressure per grid cell, against volumetric locking."
    )]
    pub volumetric_averaging: bool,
    /// 3D, or a reduced model for a scene with a symmetry (see [`Model`]).
    #[schemars(
        title = "Model",
        description = "3d: the whole tube. axisymmetric (axial, no trigger): the (r, z) section, ring folding only, seconds instead of minutes. plane_strain (lateral, no trigger): the cross-section, no end effects. Loads and energies are always the whole tube's."
    )]
    pub model: Model,
    /// f: the tube's density times f in the equations of motion only (its mass, specific
    /// energy and strain rates stay the real ones); the time step grows as √f. 1: none.
    #[serde(skip_serializing_if = "is_one")]
    #[schemars(
        title = "Mass scaling f",
        description = "Multiplies the tube's density by f in the equations of motion only, as LS-DYNA's DT2MS does for a uniform mesh: the time step grows as √f, so the run takes 1/√f of the steps, and inertia grows f times. For a rate-independent material it is the same crush as the plate √f times faster; a rate law still sees the plate's real speed. The summary reports the added mass, and the verdict holds kinetic energy to 1 % of the internal. 1: none.",
        range(min = 1, max = 100)
    )]
    pub mass_scaling: f64,
}

fn is_one(f: &f64) -> bool {
    *f == 1.0
}

impl Default for Discretization {
    fn default() -> Self {
        Discretization {
            particles_through_thickness: 4,
            cell_to_particle_ratio: 2.0,
            cfl: None,
            shape: None,
            volumetric_averaging: true,
            model: Model::ThreeD,
            mass_scaling: 1.0,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Trigger {
    /// Fraction of tube particles made weak (0.003 in the source); 0 disables the trigger.
    #[schemars(
        title = "Weak-particle fraction",
        description = "Fraction of the wall's particles made weak, at random (0.003 in the source); 0 disables the trigger.",
        range(min = 0, max = 0.1)
    )]
    pub weak_fraction: f64,
    /// Yield stress of a weak particle divided by σy.
    #[schemars(title = "Weak-particle strength ratio", description = "Yield stress of a weak particle over σy.", extend("exclusiveMinimum" = 0, "maximum" = 1))]
    pub strength_ratio: f64,
    /// Seed of the random choice of weak particles.
    #[serde(deserialize_with = "whole::<_, u64>")]
    #[schemars(
        title = "Trigger seed",
        description = "Seed of the random choice of weak particles.",
        extend("maximum" = u64::MAX)
    )]
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

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Output {
    /// Number of history rows, at equal plate-displacement intervals.
    #[serde(deserialize_with = "whole::<_, u32>")]
    #[schemars(
        title = "History points",
        description = "Rows of the load history, at equal plate travel.",
        range(min = 10, max = 100000)
    )]
    pub history_points: u32,
    /// Keep the final particle state (positions and plastic strain, 16 bytes a particle) for
    /// the deformed-tube picture and the VTU download. A sweep that needs only the numbers can
    /// leave it out.
    #[schemars(
        title = "Keep the final state",
        description = "Needed for the deformed-tube picture and the VTU file; 16 bytes a particle."
    )]
    pub final_state: bool,
    /// After the run, price the error bar of the mean load and the first collapse peak by
    /// running the tube's section at three resolutions (`analysis::error_bar`), whatever it
    /// costs. Left false, the run prices it anyway where that costs at most a quarter of the
    /// run (`analysis::estimate::UNASKED_ERROR_BAR_FRACTION`: a 3D run from about n = 8), and
    /// otherwise its summary says why not (the ladder costs 2.5 times a 3D run at n = 4, half
    /// at n = 6, a seventh at n = 8).
    #[schemars(
        title = "Error bar",
        description = "Price the discretization error of the mean load and the first collapse peak after the run, with the tube's section at three resolutions (n or 8, 1.5x, 2x), whatever it costs. Left off, it is priced anyway where it costs at most a quarter of the run (3D from about n = 8), else the summary says why not. Uniform GIMP and ring or flattening collapses only; costs 2.5x a 3D run at n = 4, 1/7 at n = 8. Asked for, a 3D run its section cannot price (a diamond, a global buckle, a tipped tube, a rectangular tube crushed axially, or B-spline shapes; n >= 3) climbs the same case in 3D at n - 2 and n - 1 instead (21 % of the run at n = 3, 68 % at n = 6). Linear shapes have none."
    )]
    pub error_bar: bool,
    /// Particle states kept as a time series for ParaView, at equal plate-travel intervals from
    /// the start to the end of the crush (56 bytes a particle a frame); 0 keeps none. The run
    /// is the same with or without. Left out of the case's JSON when 0, so a case without a
    /// series reads as it always has.
    #[serde(deserialize_with = "whole::<_, u32>", skip_serializing_if = "is_zero")]
    #[schemars(
        title = "Time-series frames",
        description = "0: none. 2 to 50: particle states for ParaView (series.pvd, series.tar) at equal plate travel, start to end, with stress, velocity and volume; 56 bytes a particle a frame, frames × particles at most 10 million.",
        range(max = 50),
        extend("default" = 0)
    )]
    pub frames: u32,
}

/// Most frames in a series: a ParaView animation of a crush reads well at 50 (one every 2 % of
/// the travel), and each frame costs a full particle state.
pub const MAX_FRAMES: u32 = 50;

/// Most particle states (frames × particles) in a series: at 56 bytes stored and about 120 bytes
/// of VTU each, 10 million is 560 MB in the store and 1.2 GB of download, as much as 35 final
/// states at the 5-million-particle default limit. The costliest example (525 310 particles)
/// may keep 19 frames; a 100 000-particle case all 50.
pub const MAX_SERIES_PARTICLES: u64 = 10_000_000;

fn is_zero(n: &u32) -> bool {
    *n == 0
}

impl Default for Output {
    fn default() -> Self {
        Output {
            history_points: 500,
            final_state: true,
            error_bar: false,
            frames: 0,
        }
    }
}

/// An integer field read from any JSON number with no fractional part: JSON (and the contract's
/// JSON Schema `integer`) counts `500.0` as the integer 500, so the parser does too.
pub fn whole<'de, D, T>(de: D) -> Result<T, D::Error>
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

/// Every field a case can set, as dotted paths (`tube.thickness_mm`, `label`), in name order.
pub fn field_paths() -> Vec<String> {
    let Ok(Value::Object(sections)) = serde_json::to_value(full_case()) else {
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

/// A case with every optional field filled in, so that its serialization names every field
/// (in the order the types declare them).
pub fn full_case() -> CaseSpec {
    let mut full = CaseSpec {
        label: Some(String::new()),
        ..CaseSpec::default()
    };
    full.loading.crush_distance_mm = Some(0.0);
    full.loading.ramp_mm = Some(0.0);
    full.loading.test_speed_m_s = Some(0.0);
    full.discretization.cfl = Some(0.0);
    full.discretization.shape = Some(ShapeKind::Gimp);
    full.discretization.mass_scaling = 2.0;
    full.output.frames = 2;
    full.tube.side_a_mm = Some(0.0);
    full.tube.side_b_mm = Some(0.0);
    full.tube.corner_radius_mm = Some(0.0);
    full.tube.side_mm = Some(0.0);
    full.material = Material {
        preset: Some(Preset::Pvc),
        hardening: HardeningKind::Table,
        hardening_curve: Some(vec![[0.0, 65.5]]),
        hardening_extrapolation: Some(CurveExtrapolation::Flat),
        hardening_k_mpa: Some(0.0),
        hardening_n: Some(0.0),
        rate: RateKind::CowperSymonds,
        cowper_symonds_d_per_s: Some(0.0),
        cowper_symonds_q: Some(0.0),
        johnson_cook_c: Some(0.0),
        johnson_cook_reference_rate_per_s: Some(0.0),
        ..Material::default()
    };
    full
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
/// error or an unknown field; what the message quotes of the client's text is clipped. Only an
/// object is a case: serde would read one from an array by position.
pub fn spec_from_value(value: &Value) -> Result<CaseSpec, CaseError> {
    if !value.is_object() {
        return Err(CaseError::Malformed {
            field: None,
            message: "must be a JSON object".into(),
        });
    }
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        CaseError::Malformed {
            field: (path != "." && !path.is_empty()).then(|| clip(&path).into_owned()),
            message: user_message(&e.inner().to_string()),
        }
    })
}

/// The dilatational wave speed the run's time step follows, m/s: the material's, slowed by
/// the mass scaling f to c / √f.
pub(crate) fn run_wave_speed_m_s(spec: &CaseSpec) -> f64 {
    wave_speed_m_s(&spec.material) / spec.discretization.mass_scaling.sqrt()
}

/// c = √(E(1−ν) / ((1+ν)(1−2ν)ρ)) in m/s, from E in MPa and ρ in kg/m³.
pub(crate) fn wave_speed_m_s(m: &Material) -> f64 {
    let nu = m.poisson_ratio;
    let modulus_pa = m.youngs_modulus_mpa * 1e6 * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    (modulus_pa / m.density_kg_m3).sqrt()
}
