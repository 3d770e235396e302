//! J2 (von Mises) plasticity with isotropic hardening and strain-rate dependence: a metal. The
//! flow stress is σ_f = s · σ_s(ε_p) · R(ε̇_p) ([`super::flow`]), s the trigger's factor.
//!
//! The return is implicit in both: the step's plastic strain increment Δ solves
//! q_trial − 3G Δ = s σ_s(ε_p + Δ) R(Δ / Δt), the stress at the end of the step on the surface
//! of the hardened strain and of the step's own plastic strain rate. Taking the rate of the
//! previous step instead would be explicit in a stiff term: with Cowper–Symonds' small
//! exponents 1/q the factor changes steeply at low rates, and a lagged rate can swing from step
//! to step; the implicit one cannot, at any step size. Δ is found per particle by Newton's
//! method kept inside a bracket ([`Metal::plastic_increment`]); the bracket is [0, f(0) / 3G],
//! since the flow stress never falls below its value at the start of the step (stresses of a
//! curve do not decrease and R ≥ 1).

use super::flow::{Hardening, Rate};
use super::law::{lame, trial, Increment, Lanes, Law, Point};
use crate::solver::Real;

/// Newton steps at most in one return (each halves the bracket at worst; the step ends when
/// the residual is below [`RESIDUAL`] of the trial stress).
const MAX_ITERATIONS: usize = 60;

/// The return's residual |f(Δ)| / q_trial at which it stops.
const RESIDUAL: Real = 1e-12;

/// A hardening, rate-sensitive metal: Lamé's λ and the shear modulus G (MPa), its static
/// hardening curve and its rate factor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metal {
    pub lambda: Real,
    pub shear: Real,
    pub hardening: Hardening,
    pub rate: Rate,
}

impl Metal {
    /// Of Young's modulus E, Poisson's ratio ν (MPa), the hardening curve and the rate factor.
    pub fn new(youngs: Real, poisson: Real, hardening: Hardening, rate: Rate) -> Metal {
        let (lambda, shear) = lame(youngs, poisson);
        Metal {
            lambda,
            shear,
            hardening,
            rate,
        }
    }

    /// The flow stress s σ_s(ε) R(ε̇) (MPa) and its derivative in Δ, with ε = `strain` + Δ
    /// and ε̇ = Δ / `dt`.
    #[inline]
    fn flow(&self, strain: Real, increment: Real, dt: Real, scale: Real) -> (Real, Real) {
        let (static_stress, slope) = self.hardening.at(strain + increment);
        let (factor, factor_slope) = self.rate.at(increment / dt);
        let value = scale * static_stress * factor;
        // d/dΔ [σ_s(ε_p + Δ) R(Δ/dt)]; a zero factor slope times an infinite one is no term.
        let rate_term = if factor_slope == 0.0 {
            0.0
        } else {
            static_stress * factor_slope / dt
        };
        (value, scale * (slope * factor + rate_term))
    }

    /// The plastic strain increment Δ ≥ 0 of a step whose trial von Mises stress is `q` (MPa),
    /// from the accumulated plastic strain `strain`, over `dt` ms, for a particle of strength
    /// factor `scale`: 0 inside the surface, else the root of
    /// f(Δ) = q − 3G Δ − s σ_s(ε_p + Δ) R(Δ/dt), which decreases in Δ. Newton's step where it
    /// stays inside the bracket that holds the root, the bracket's middle where it does not.
    pub fn plastic_increment(&self, q: Real, strain: Real, dt: Real, scale: Real) -> Real {
        if let Rate::CowperSymonds { d, inverse_q } = self.rate {
            return self.plastic_increment_cowper_symonds(q, strain, dt, scale, d, inverse_q);
        }
        let three_g = 3.0 * self.shear;
        let start = q - self.flow(strain, 0.0, dt, scale).0;
        // Inside the surface (or a NaN trial, which must not flow).
        if start.is_nan() || start <= 0.0 {
            return 0.0;
        }
        let (mut lo, mut hi) = (0.0, start / three_g);
        let mut x = hi;
        for _ in 0..MAX_ITERATIONS {
            let (flow, flow_slope) = self.flow(strain, x, dt, scale);
            let f = q - three_g * x - flow;
            if f.abs() <= RESIDUAL * q {
                return x;
            }
            if f > 0.0 {
                lo = x;
            } else {
                hi = x;
            }
            let newton = x + f / (three_g + flow_slope);
            x = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if hi - lo <= Real::EPSILON * hi {
                break;
            }
        }
        x
    }
}

impl Metal {
    /// [`Metal::plastic_increment`] under Cowper–Symonds, solved for y = (ε̇_p / D)^(1/q)
    /// instead of Δ = Δt D y^q: the rate factor 1 + y is steep in Δ near zero rate (its slope
    /// is infinite there) but a line in y, so the residual
    /// f(y) = q − 3G Δ(y) − s σ_s(ε_p + Δ(y)) (1 + y) is smooth and Newton's method converges
    /// in a few steps. The same bracket and the same stopping rule.
    fn plastic_increment_cowper_symonds(
        &self,
        q: Real,
        strain: Real,
        dt: Real,
        scale: Real,
        d: Real,
        inverse_q: Real,
    ) -> Real {
        let three_g = 3.0 * self.shear;
        let start = q - scale * self.hardening.at(strain).0;
        if start.is_nan() || start <= 0.0 {
            return 0.0;
        }
        let exponent = 1.0 / inverse_q;
        let per_y = dt * d;
        let increment = |y: Real| per_y * y.powf(exponent);
        let (mut lo, mut hi) = (0.0, (start / three_g / per_y).powf(inverse_q));
        let mut y = 0.0;
        for _ in 0..MAX_ITERATIONS {
            let x = increment(y);
            let (static_stress, slope) = self.hardening.at(strain + x);
            let f = q - three_g * x - scale * static_stress * (1.0 + y);
            if f.abs() <= RESIDUAL * q {
                return x;
            }
            if f > 0.0 {
                lo = y;
            } else {
                hi = y;
            }
            // dΔ/dy = Δt D q y^(q−1), 0 at y = 0 for q > 1.
            let dx = if y > 0.0 { exponent * x / y } else { 0.0 };
            let slope_y = (three_g + scale * slope * (1.0 + y)) * dx + scale * static_stress;
            let newton = y + f / slope_y;
            y = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if hi - lo <= Real::EPSILON * hi {
                break;
            }
        }
        increment(y)
    }
}

impl Law for Metal {
    fn p_wave_modulus(&self) -> Real {
        self.lambda + 2.0 * self.shear
    }

    /// The elastic trial, then the implicit return of its deviator: scaled by
    /// (q − 3G Δ) / q, so that its von Mises stress is the flow stress at the end of the step;
    /// the plastic work is that stress times Δ. The return is scalar code, run lane by lane.
    #[inline(always)]
    fn update_lanes<T: Lanes>(
        &self,
        stress: &mut [T; 6],
        l: &[[T; 3]; 3],
        dt: Real,
        at: Point<T>,
    ) -> Increment<T> {
        let c = T::splat;
        let trial = trial((self.lambda, self.shear), stress, l, dt);
        let q = trial.von_mises();
        let mut s = trial.deviator;
        let plastic_strain = T::each([q, at.plastic_strain, at.strength_scale], |[q, e, s]| {
            self.plastic_increment(q, e, dt, s)
        });
        let flow_stress = q - c(3.0 * self.shear) * plastic_strain;
        // 1 where nothing flowed (also at q = 0, where Δ = 0 and the quotient is 0 / tiny).
        let scale = flow_stress / q.max(c(Real::MIN_POSITIVE));
        let scale = scale.min(c(1.0)).max(c(0.0));
        s.iter_mut().for_each(|v| *v = *v * scale);
        let stress_power = trial.finish(s, stress);
        Increment {
            plastic_strain,
            stress_power,
            plastic_work: flow_stress * plastic_strain,
        }
    }
}
