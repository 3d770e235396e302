//! Material presets: a case names one (`material.preset`) and may override any field. Each
//! preset's values are those of the source named beside it (docs/materials.md gives the same
//! table with the sources in full); none is fitted here. The enum and its names are in
//! `preset_names.rs`; this file gives each preset its values and their source.

use super::given::{HardeningKind, Material, MaterialModel, RateKind};

pub use super::preset_names::Preset;

impl Preset {
    /// Where the preset's values come from, in a line.
    pub fn source(self) -> &'static str {
        match self {
            Preset::Pvc => {
                "the paper's PVC (E, ν, σy); density 1380 kg/m³ assumed (rigid PVC: 1300–1450)"
            }
            Preset::Aa6060T5 => {
                "EN 755-2 / EN 1999-1-1 Table 3.2b, EN AW-6060 T5 extrusions t ≤ 5 mm: \
                 f0 = 120 MPa (fu = 160 MPa); E, ν, ρ of EN 1999-1-1 §3.2.5"
            }
            Preset::Aa6061T6 => {
                "Lesuer, Kay & LeBlanc (2001, LLNL UCRL-JC-134118), Johnson–Cook fit: A = 324 MPa, B = 114 MPa, n = 0.42, C = 0.002 at \
                 ε̇₀ = 1/s (no thermal term); E, ν, ρ of MatWeb's 6061-T6"
            }
            Preset::MildSteel => {
                "σy = 250 MPa, E = 210 GPa, ν = 0.3, ρ = 7850 kg/m³; Cowper–Symonds D = 40.4/s, \
                 q = 5 (Jones, Structural Impact, 1989)"
            }
            Preset::Stainless304 => {
                "AISI 304 annealed: σy = 205 MPa (ASTM A240 minimum), Swift K = 1400 MPa, \
                 n = 0.44 (Callister, Fundamentals of Materials Science and Engineering, 2nd \
                 ed., 2005, p. 199), E = 193 GPa, ν = 0.29, ρ = 8000 kg/m³; Cowper–Symonds \
                 D = 100/s, q = 10 (Jones, Structural Impact, 1989, for stainless steel 304)"
            }
        }
    }

    /// The preset's material section, every law constant filled in.
    pub fn material(self) -> Material {
        let plain = Material {
            preset: Some(self),
            model: MaterialModel::J2,
            youngs_modulus_mpa: 0.0,
            poisson_ratio: 0.0,
            yield_stress_mpa: 0.0,
            density_kg_m3: 0.0,
            hardening: HardeningKind::None,
            hardening_curve: None,
            hardening_extrapolation: None,
            hardening_k_mpa: None,
            hardening_n: None,
            rate: RateKind::None,
            cowper_symonds_d_per_s: None,
            cowper_symonds_q: None,
            johnson_cook_c: None,
            johnson_cook_reference_rate_per_s: None,
        };
        match self {
            Preset::Pvc => Material {
                youngs_modulus_mpa: 3378.4,
                poisson_ratio: 0.42,
                yield_stress_mpa: 65.5,
                density_kg_m3: 1380.0,
                ..plain
            },
            Preset::Aa6060T5 => Material {
                youngs_modulus_mpa: 70_000.0,
                poisson_ratio: 0.3,
                yield_stress_mpa: 120.0,
                density_kg_m3: 2700.0,
                ..plain
            },
            Preset::Aa6061T6 => Material {
                youngs_modulus_mpa: 68_900.0,
                poisson_ratio: 0.33,
                yield_stress_mpa: 324.0,
                density_kg_m3: 2700.0,
                hardening: HardeningKind::Ludwik,
                hardening_k_mpa: Some(114.0),
                hardening_n: Some(0.42),
                rate: RateKind::JohnsonCook,
                johnson_cook_c: Some(0.002),
                johnson_cook_reference_rate_per_s: Some(1.0),
                ..plain
            },
            Preset::MildSteel => Material {
                youngs_modulus_mpa: 210_000.0,
                poisson_ratio: 0.3,
                yield_stress_mpa: 250.0,
                density_kg_m3: 7850.0,
                rate: RateKind::CowperSymonds,
                cowper_symonds_d_per_s: Some(40.4),
                cowper_symonds_q: Some(5.0),
                ..plain
            },
            Preset::Stainless304 => Material {
                youngs_modulus_mpa: 193_000.0,
                poisson_ratio: 0.29,
                yield_stress_mpa: 205.0,
                density_kg_m3: 8000.0,
                hardening: HardeningKind::Swift,
                hardening_k_mpa: Some(1400.0),
                hardening_n: Some(0.44),
                rate: RateKind::CowperSymonds,
                cowper_symonds_d_per_s: Some(100.0),
                cowper_symonds_q: Some(10.0),
                ..plain
            },
        }
    }
}
