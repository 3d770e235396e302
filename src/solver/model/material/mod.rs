//! The material laws of the wall: a [`Law`] turns a particle's velocity gradient over a step
//! into its new stress, its equivalent plastic strain increment, its stress power and the
//! plastic work it dissipated, so the energy books never assume a law. Stress in MPa, time in
//! ms, velocity gradient in 1/ms, work densities in MPa (= mJ/mm³).
//!
//! Every law shares the Jaumann (objective) stress rate of the elastic trial ([`trial`]); a law
//! differs in what it does to the trial's deviator ([`elastic::Elastic`]: nothing;
//! [`j2::J2`]: the radial return to the von Mises surface of a constant yield stress, the
//! paper's model; [`metal::Metal`]: the implicit return to the surface of a hardening,
//! rate-sensitive flow stress, [`flow`]). The case's material section, its presets and how they
//! become a law are in [`given`] and [`preset`]. A law is chosen once per run
//! ([`MaterialLaw`]), so the stress loop over the particles stays monomorphic, and it runs on
//! lanes ([`Lanes`]): `f64` for one particle, `f64x4` for four at once, with the same bits. The
//! state a law reads besides the stress is the particle's own ([`Point`]): its trigger factor
//! and its accumulated equivalent plastic strain, which the particles carry and the increment
//! advances. What every law shares (the trait, the lanes, the trial) is in [`law`], which the
//! laws import and this file re-exports; this file chooses the law.

pub(super) mod checks;
pub mod elastic;
pub mod flow;
pub mod given;
pub mod j2;
pub mod law;
pub mod metal;
pub mod preset;
pub mod preset_names;

use crate::solver::Real;
use given::{HardeningKind, Material, MaterialModel, RateKind};
use nalgebra::Matrix3;

pub use elastic::Elastic;
pub use j2::J2;
pub use law::{lame, trial, Increment, Lanes, Law, Point, Sym, Trial};
pub use metal::Metal;

pub fn to_matrix(s: &Sym) -> Matrix3<Real> {
    Matrix3::new(s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2])
}

pub fn from_matrix(m: &Matrix3<Real>) -> Sym {
    [
        m[(0, 0)],
        m[(1, 1)],
        m[(2, 2)],
        m[(1, 2)],
        m[(0, 2)],
        m[(0, 1)],
    ]
}

/// The law a case's material names, chosen once per run.
// A metal carries its hardening table by value ([`flow::Hardening`]); the law is chosen once a
// run and dispatched once a step, so the size difference costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MaterialLaw {
    Elastic(Elastic),
    J2(J2),
    Metal(Metal),
}

impl MaterialLaw {
    /// The law of a case's `material` section (checked): J2 with a constant yield stress where
    /// the section names neither hardening nor a rate law (the paper's PVC runs exactly the law
    /// it always ran), the metal's law where it names either.
    pub fn of(m: &Material) -> MaterialLaw {
        let (e, nu) = (m.youngs_modulus_mpa, m.poisson_ratio);
        match m.model {
            MaterialModel::Elastic => MaterialLaw::Elastic(Elastic::new(e, nu)),
            MaterialModel::J2 if m.hardening == HardeningKind::None && m.rate == RateKind::None => {
                MaterialLaw::J2(J2::new(e, nu, m.yield_stress_mpa))
            }
            MaterialModel::J2 => {
                MaterialLaw::Metal(Metal::new(e, nu, m.hardening_law(), m.rate_law()))
            }
        }
    }

    /// The law with its rate law read at every strain rate times `scale`
    /// ([`Rate::at_rates_scaled`]): a case run faster than its test sees the test's rates.
    pub fn at_rates_scaled(self, scale: Real) -> MaterialLaw {
        match self {
            MaterialLaw::Metal(mut metal) => {
                metal.rate = metal.rate.at_rates_scaled(scale);
                MaterialLaw::Metal(metal)
            }
            law => law,
        }
    }

    /// P-wave (constrained) modulus λ + 2G, MPa.
    pub fn p_wave_modulus(&self) -> Real {
        struct Modulus;
        impl WithLaw for Modulus {
            type Output = Real;
            fn with<L: Law>(self, law: &L) -> Real {
                law.p_wave_modulus()
            }
        }
        self.with(Modulus)
    }

    /// `task` run with the law as a type: the one place where the case's choice of law becomes
    /// one, so that a loop over the particles inside `task` is monomorphic.
    pub fn with<W: WithLaw>(&self, task: W) -> W::Output {
        match self {
            MaterialLaw::Elastic(law) => task.with(law),
            MaterialLaw::J2(law) => task.with(law),
            MaterialLaw::Metal(law) => task.with(law),
        }
    }
}

/// Work to do with a law once its kind is a type ([`MaterialLaw::with`]).
pub trait WithLaw {
    type Output;
    fn with<L: Law>(self, law: &L) -> Self::Output;
}

/// von Mises equivalent stress, MPa.
pub fn von_mises(s: &Sym) -> Real {
    let p = (s[0] + s[1] + s[2]) / 3.0;
    let (a, b, c) = (s[0] - p, s[1] - p, s[2] - p);
    (1.5 * (a * a + b * b + c * c + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))).sqrt()
}

#[cfg(test)]
mod given_tests;
#[cfg(test)]
mod metal_tests;
#[cfg(test)]
mod tests;
