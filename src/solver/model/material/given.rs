//! The case's `material` section as a user writes it: the elastic constants and density, the
//! yield stress, a hardening law and a strain-rate law, each field optional. A `preset`
//! ([`Preset`]) fills what the section leaves out; without one, the paper's PVC does. Units in
//! the field names: MPa, kg/m³, 1/s.
//!
//! The section is resolved as it is read ([`Material`] is read through [`MaterialInput`]), so
//! the rest of the solver sees one set of values. A section that names its own `hardening`
//! (or `rate`, or an elastic `model`) takes none of the preset's hardening (or rate) constants;
//! one that only changes a constant (`hardening_n`) keeps the preset's law with it. A curve
//! given without a yield stress sets the yield stress to its first stress.

pub use super::flow::Extrapolation;
pub use super::preset_names::Preset;

use super::flow::{Hardening, Rate, Table};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Constitutive model of the wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
pub enum MaterialModel {
    /// von Mises (J2) plasticity, radial return: elastic–perfectly plastic unless the section
    /// names a hardening or a rate law.
    #[default]
    J2,
    /// Linear elastic, never yields (a stability check, not a crash material).
    Elastic,
}

/// The static hardening law: how the flow stress grows with the equivalent plastic strain ε_p.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
pub enum HardeningKind {
    /// None: the flow stress is the yield stress (perfect plasticity).
    #[default]
    None,
    /// `hardening_curve`: true stress against equivalent plastic strain, piecewise linear.
    Table,
    /// Swift: σ = K (ε₀ + ε_p)ⁿ, ε₀ = (σy / K)^(1/n).
    Swift,
    /// Ludwik: σ = σy + K ε_pⁿ.
    Ludwik,
}

/// The strain-rate law: the factor on the static flow stress at the equivalent plastic strain
/// rate ε̇_p.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
pub enum RateKind {
    /// None: rate-independent.
    #[default]
    None,
    /// Cowper–Symonds: 1 + (ε̇_p / D)^(1/q).
    CowperSymonds,
    /// Johnson–Cook's rate term: 1 + C ln(ε̇_p / ε̇₀), and 1 below ε̇₀ (no thermal term).
    JohnsonCook,
}

impl HardeningKind {
    fn is_none(&self) -> bool {
        *self == HardeningKind::None
    }
}

impl RateKind {
    fn is_none(&self) -> bool {
        *self == RateKind::None
    }
}

/// How a tabulated curve goes on past its last point, as a case names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
pub enum CurveExtrapolation {
    /// The last stress (the default: a tensile test's curve ends at necking, well below the
    /// strains of a fold, and a continued slope would guess beyond it).
    #[default]
    Flat,
    /// The last segment's slope, continued.
    LastSlope,
}

/// The material section, resolved: the preset's values where the case gave none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(from = "MaterialInput")]
#[schemars(
    description = "The wall's material. A `preset` fills every field the section leaves out (without one, the paper's PVC: the defaults below). A section that names its own `hardening` (or `rate`, or model `elastic`) takes none of the preset's constants for that law; one that only changes a constant keeps the preset's law. A law's constants are required with it and refused without it (422 naming the field). Presets, their sources and the laws are described in docs/materials.md."
)]
pub struct Material {
    /// The preset the section started from; `None`: the paper's PVC.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<Preset>,
    pub model: MaterialModel,
    pub youngs_modulus_mpa: f64,
    pub poisson_ratio: f64,
    /// The yield stress σy: the flow stress at ε_p = 0 and a static strain rate.
    pub yield_stress_mpa: f64,
    pub density_kg_m3: f64,
    #[serde(skip_serializing_if = "HardeningKind::is_none")]
    pub hardening: HardeningKind,
    /// [ε_p, σ MPa] pairs, the first at ε_p = 0 (hardening `table`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hardening_curve: Option<Vec<[f64; 2]>>,
    /// Past the curve's last point (hardening `table`); `None`: flat.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hardening_extrapolation: Option<CurveExtrapolation>,
    /// K, MPa (hardening `swift` or `ludwik`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hardening_k_mpa: Option<f64>,
    /// n (hardening `swift` or `ludwik`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hardening_n: Option<f64>,
    #[serde(skip_serializing_if = "RateKind::is_none")]
    pub rate: RateKind,
    /// D, 1/s (rate `cowper_symonds`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cowper_symonds_d_per_s: Option<f64>,
    /// q (rate `cowper_symonds`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cowper_symonds_q: Option<f64>,
    /// C (rate `johnson_cook`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub johnson_cook_c: Option<f64>,
    /// ε̇₀, 1/s (rate `johnson_cook`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub johnson_cook_reference_rate_per_s: Option<f64>,
}

impl Default for Material {
    /// The paper's PVC ([`Preset::Pvc`]) with no preset named.
    fn default() -> Self {
        Material {
            preset: None,
            ..Preset::Pvc.material()
        }
    }
}

/// The material section as written: every field optional.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[schemars(rename = "MaterialInput")]
pub struct MaterialInput {
    #[schemars(
        title = "Material preset",
        description = "Fills every material field left out; empty: the paper's PVC. pvc: the paper's PVC. aa6060_t5: EN AW-6060 T5 extrusions (EN 755-2 minimum proof stress 120 MPa), perfectly plastic. aa6061_t6: Johnson & Cook's 6061-T6 (Ludwik hardening 324 + 114 εp^0.42 MPa, rate term C = 0.002). mild_steel: 250 MPa, perfectly plastic, Cowper–Symonds D = 40.4/s, q = 5. stainless_304: AISI 304 annealed, Swift hardening 1400 (ε₀ + εp)^0.44 MPa from 205 MPa, Cowper–Symonds D = 100/s, q = 10. Sources: docs/materials.md."
    )]
    pub preset: Option<Preset>,
    #[schemars(
        title = "Material model",
        description = "j2: von Mises plasticity, perfectly plastic unless a hardening or rate law is set; elastic never yields."
    )]
    pub model: Option<MaterialModel>,
    #[schemars(title = "Young's modulus E", extend("x-unit" = "MPa", "exclusiveMinimum" = 0))]
    pub youngs_modulus_mpa: Option<f64>,
    #[schemars(title = "Poisson's ratio ν", range(min = -0.99, max = 0.4999))]
    pub poisson_ratio: Option<f64>,
    #[schemars(title = "Yield stress σy", description = "The flow stress at zero plastic strain and a static rate. With a hardening curve it must equal the curve's first stress; left out, it is taken from the curve.", extend("x-unit" = "MPa", "exclusiveMinimum" = 0))]
    pub yield_stress_mpa: Option<f64>,
    #[schemars(title = "Density ρ", extend("x-unit" = "kg/m³", "exclusiveMinimum" = 0))]
    pub density_kg_m3: Option<f64>,
    #[schemars(
        title = "Hardening",
        description = "The static hardening law; empty: the preset's (none for PVC). table: the hardening curve; swift: σ = K (ε₀ + εp)ⁿ with ε₀ = (σy / K)^(1/n); ludwik: σ = σy + K εpⁿ."
    )]
    pub hardening: Option<HardeningKind>,
    #[schemars(
        title = "Hardening curve",
        description = "True stress against equivalent plastic strain: [εp, σ MPa] pairs (\"εp σ\" pairs separated by commas in the form), the first at εp = 0 with the yield stress, strains increasing, stresses not decreasing (softening is not modelled), at most 100; piecewise linear.",
        length(min = 1, max = 100)
    )]
    pub hardening_curve: Option<Vec<[f64; 2]>>,
    #[schemars(
        title = "Past the curve's end",
        description = "Past the hardening curve's last point; empty: flat (the last stress)."
    )]
    pub hardening_extrapolation: Option<CurveExtrapolation>,
    #[schemars(title = "Hardening K", description = "K of Swift or Ludwik.", extend("x-unit" = "MPa", "exclusiveMinimum" = 0))]
    pub hardening_k_mpa: Option<f64>,
    #[schemars(title = "Hardening exponent n", description = "n of Swift or Ludwik.", extend("exclusiveMinimum" = 0, "maximum" = 1))]
    pub hardening_n: Option<f64>,
    #[schemars(
        title = "Strain-rate law",
        description = "The strain-rate law on the equivalent plastic strain rate; empty: the preset's (none for PVC). cowper_symonds: σ × (1 + (ε̇p/D)^(1/q)); johnson_cook: σ × (1 + C ln(ε̇p/ε̇₀)) above ε̇₀, σ below (no thermal term)."
    )]
    pub rate: Option<RateKind>,
    #[schemars(title = "Cowper–Symonds D", extend("x-unit" = "1/s", "exclusiveMinimum" = 0))]
    pub cowper_symonds_d_per_s: Option<f64>,
    #[schemars(title = "Cowper–Symonds q", range(min = 1, max = 100))]
    pub cowper_symonds_q: Option<f64>,
    #[schemars(title = "Johnson–Cook C", range(min = 0, max = 1))]
    pub johnson_cook_c: Option<f64>,
    #[schemars(title = "Johnson–Cook ε̇₀", description = "The reference (quasi-static) rate.", extend("x-unit" = "1/s", "exclusiveMinimum" = 0))]
    pub johnson_cook_reference_rate_per_s: Option<f64>,
}

impl From<MaterialInput> for Material {
    fn from(i: MaterialInput) -> Material {
        let base = i.preset.unwrap_or(Preset::Pvc).material();
        let elastic = i.model == Some(MaterialModel::Elastic);
        // The preset's constants of a law only where the section keeps the preset's law.
        let keeps_hardening = i.hardening.is_none() && !elastic;
        let keeps_rate = i.rate.is_none() && !elastic;
        let hardening_from = |own: Option<f64>, preset: Option<f64>| {
            own.or(if keeps_hardening { preset } else { None })
        };
        let rate_from =
            |own: Option<f64>, preset: Option<f64>| own.or(if keeps_rate { preset } else { None });
        let curve_yield = i
            .hardening_curve
            .as_ref()
            .and_then(|c| c.first())
            .map(|p| p[1]);
        Material {
            preset: i.preset,
            model: i.model.unwrap_or(base.model),
            youngs_modulus_mpa: i.youngs_modulus_mpa.unwrap_or(base.youngs_modulus_mpa),
            poisson_ratio: i.poisson_ratio.unwrap_or(base.poisson_ratio),
            yield_stress_mpa: i
                .yield_stress_mpa
                .or(curve_yield)
                .unwrap_or(base.yield_stress_mpa),
            density_kg_m3: i.density_kg_m3.unwrap_or(base.density_kg_m3),
            hardening: match (i.hardening, keeps_hardening) {
                (Some(h), _) => h,
                (None, true) => base.hardening,
                (None, false) => HardeningKind::None,
            },
            hardening_curve: i.hardening_curve.or(if keeps_hardening {
                base.hardening_curve
            } else {
                None
            }),
            hardening_extrapolation: i.hardening_extrapolation.or(if keeps_hardening {
                base.hardening_extrapolation
            } else {
                None
            }),
            hardening_k_mpa: hardening_from(i.hardening_k_mpa, base.hardening_k_mpa),
            hardening_n: hardening_from(i.hardening_n, base.hardening_n),
            rate: match (i.rate, keeps_rate) {
                (Some(r), _) => r,
                (None, true) => base.rate,
                (None, false) => RateKind::None,
            },
            cowper_symonds_d_per_s: rate_from(
                i.cowper_symonds_d_per_s,
                base.cowper_symonds_d_per_s,
            ),
            cowper_symonds_q: rate_from(i.cowper_symonds_q, base.cowper_symonds_q),
            johnson_cook_c: rate_from(i.johnson_cook_c, base.johnson_cook_c),
            johnson_cook_reference_rate_per_s: rate_from(
                i.johnson_cook_reference_rate_per_s,
                base.johnson_cook_reference_rate_per_s,
            ),
        }
    }
}

/// A wall's yield stress σy and engineering ultimate stress σu (σy for a perfectly plastic
/// wall), MPa.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowStresses {
    pub yield_stress: f64,
    pub ultimate: f64,
}

impl FlowStresses {
    /// The flow stress σ0 the closed forms take: (σy + σu)/2, the usual choice for a hardening
    /// wall in the crush literature; σy for a perfectly plastic one.
    pub fn flow(&self) -> f64 {
        0.5 * (self.yield_stress + self.ultimate)
    }
}

impl Material {
    /// The static hardening law of a checked section (a constant yield stress for `none`).
    pub fn hardening_law(&self) -> Hardening {
        let sy = self.yield_stress_mpa;
        let k = self.hardening_k_mpa.unwrap_or(0.0);
        let n = self.hardening_n.unwrap_or(1.0);
        match self.hardening {
            HardeningKind::None => Hardening::Table(Table::new(&[[0.0, sy]], Extrapolation::Flat)),
            HardeningKind::Table => {
                let points = self.hardening_curve.as_deref().unwrap_or(&[]);
                let extrapolation = match self.hardening_extrapolation.unwrap_or_default() {
                    CurveExtrapolation::Flat => Extrapolation::Flat,
                    CurveExtrapolation::LastSlope => Extrapolation::LastSlope,
                };
                Hardening::Table(Table::new(points, extrapolation))
            }
            HardeningKind::Swift => Hardening::swift(sy, k, n),
            HardeningKind::Ludwik => Hardening::Ludwik {
                yield_stress: sy,
                k,
                n,
            },
        }
    }

    /// The rate law of a checked section.
    pub fn rate_law(&self) -> Rate {
        match self.rate {
            RateKind::None => Rate::None,
            RateKind::CowperSymonds => Rate::cowper_symonds(
                self.cowper_symonds_d_per_s.unwrap_or(1.0),
                self.cowper_symonds_q.unwrap_or(1.0),
            ),
            RateKind::JohnsonCook => Rate::johnson_cook(
                self.johnson_cook_c.unwrap_or(0.0),
                self.johnson_cook_reference_rate_per_s.unwrap_or(1.0),
            ),
        }
    }

    /// The static flow stress at equivalent plastic strain `strain`, MPa.
    pub fn static_flow_stress(&self, strain: f64) -> f64 {
        self.hardening_law().at(strain).0
    }

    /// The yield stress and the engineering ultimate stress of the static curve (where a bar
    /// of it necks: [`Hardening::ultimate_tensile_stress`]), from which the closed forms take
    /// their flow stress.
    pub fn flow_stresses(&self) -> FlowStresses {
        FlowStresses {
            yield_stress: self.yield_stress_mpa,
            ultimate: self.hardening_law().ultimate_tensile_stress(),
        }
    }

    /// The rate factor R ≥ 1 at the equivalent plastic strain rate `rate_per_s` (1/s).
    pub fn rate_factor(&self, rate_per_s: f64) -> f64 {
        self.rate_law().at(rate_per_s * 1e-3).0
    }
}
