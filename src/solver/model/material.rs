//! Elastic–perfectly plastic J2 material with a Jaumann (objective) stress rate and radial
//! return. Stress in MPa, time in ms, velocity gradient in 1/ms.

use crate::solver::Real;
use nalgebra::Matrix3;
use std::ops::{Add, Div, Mul, Sub};
use wide::f64x4;

/// Symmetric stress in Voigt order xx, yy, zz, yz, xz, xy (MPa).
pub type Sym = [Real; 6];

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

/// Elastic constants and yield stress.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastoplastic {
    /// Lamé's first parameter, MPa.
    pub lambda: Real,
    /// Shear modulus, MPa.
    pub shear: Real,
    /// Yield stress, MPa; infinite for a material that never yields.
    pub yield_stress: Real,
}

/// What one stress update did to a particle (or, with `T = f64x4`, to four).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Increment<T = Real> {
    /// Equivalent plastic strain increment.
    pub plastic_strain: T,
    /// Stress power density σ:D over the step, trapezoidal, MPa/ms.
    pub stress_power: T,
}

impl Elastoplastic {
    pub fn new(youngs: Real, poisson: Real, yield_stress: Real) -> Self {
        let lambda = youngs * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
        let shear = youngs / (2.0 * (1.0 + poisson));
        Elastoplastic {
            lambda,
            shear,
            yield_stress,
        }
    }

    /// The yield stress for the plastic-work books, MPa: 0 for a material that never yields, so
    /// that its zero plastic strain books zero work (∞ · 0 would book NaN).
    pub fn finite_yield_stress(&self) -> Real {
        if self.yield_stress.is_finite() {
            self.yield_stress
        } else {
            0.0
        }
    }

    /// P-wave (constrained) modulus λ + 2G, MPa: c² = M / ρ.
    pub fn p_wave_modulus(&self) -> Real {
        self.lambda + 2.0 * self.shear
    }

    /// Advances `stress` by one step under velocity gradient `l` over `dt`, with the yield stress
    /// scaled by `yield_scale` (weak trigger particles have < 1): the Jaumann rate of the
    /// elastic trial stress, then the radial return to the von Mises surface. One particle;
    /// [`Elastoplastic::update_lanes`] is the same update on any [`Lanes`].
    #[inline]
    pub fn update(
        &self,
        stress: &mut Sym,
        l: &Matrix3<Real>,
        dt: Real,
        yield_scale: Real,
    ) -> Increment {
        let l = [0, 1, 2].map(|i| [0, 1, 2].map(|j| l[(i, j)]));
        self.update_lanes(stress, &l, dt, yield_scale)
    }

    /// The update on lanes `T`: `f64` for one particle, `f64x4` for four at once. Every
    /// operation is IEEE lane by lane and written in one order, so four particles at once give
    /// the bits each gives alone (a unit test checks).
    ///
    /// Written on the six components of the symmetric tensors (`Sym` order xx, yy, zz, yz, xz,
    /// xy): with W the spin and σ symmetric, W·σ − σ·W = A + Aᵀ for A = W·σ, so only its six
    /// distinct entries are formed: the same algebra as the 3×3 form, with no 3×3 products (the
    /// matrix form was 29 % of a linear-shape step in `perf record`).
    #[inline(always)]
    pub fn update_lanes<T: Lanes>(
        &self,
        stress: &mut [T; 6],
        l: &[[T; 3]; 3],
        dt: Real,
        yield_scale: T,
    ) -> Increment<T> {
        let c = T::splat;
        let half = c(0.5);
        // Rate of deformation D (Sym order) and spin W = [[0, a, b], [−a, 0, c], [−b, −c, 0]].
        let d = [
            l[0][0],
            l[1][1],
            l[2][2],
            half * (l[1][2] + l[2][1]),
            half * (l[0][2] + l[2][0]),
            half * (l[0][1] + l[1][0]),
        ];
        let (a, b, w) = (
            half * (l[0][1] - l[1][0]),
            half * (l[0][2] - l[2][0]),
            half * (l[1][2] - l[2][1]),
        );
        let old = *stress;
        let [xx, yy, zz, yz, xz, xy] = old;
        let two = c(2.0);
        let spin = [
            two * (a * xy + b * xz),
            two * (w * yz - a * xy),
            c(-2.0) * (b * xz + w * yz),
            w * zz - w * yy - a * xz - b * xy,
            a * yz + b * zz - b * xx - w * xy,
            a * yy + b * yz - a * xx + w * xz,
        ];
        let (dt, two_g) = (c(dt), c(2.0 * self.shear * dt));
        let lam = c(self.lambda) * (d[0] + d[1] + d[2]) * dt;
        let mut s = [c(0.0); 6];
        for k in 0..6 {
            s[k] = old[k] + spin[k] * dt + d[k] * two_g;
        }
        for v in &mut s[..3] {
            *v = *v + lam;
        }
        let p = (s[0] + s[1] + s[2]) / c(3.0);
        for v in &mut s[..3] {
            *v = *v - p;
        }
        let norm2 = s[0] * s[0]
            + s[1] * s[1]
            + s[2] * s[2]
            + two * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]);
        let q = (c(1.5) * norm2).sqrt();
        // Radial return without a branch: the scale is 1 inside the surface (also for q = 0
        // and an infinite yield stress, where the quotient is infinite), and particles
        // of a crush cross the surface both ways from step to step.
        let yield_stress = c(self.yield_stress) * yield_scale;
        let scale = (yield_stress / q).min(c(1.0));
        s.iter_mut().for_each(|v| *v = *v * scale);
        let plastic_strain = ((q - yield_stress) / c(3.0 * self.shear)).max(c(0.0));
        for v in &mut s[..3] {
            *v = *v + p;
        }
        let power = |k: usize| (old[k] + s[k]) * d[k];
        let stress_power =
            half * (power(0) + power(1) + power(2) + two * (power(3) + power(4) + power(5)));
        *stress = s;
        Increment {
            plastic_strain,
            stress_power,
        }
    }
}

impl Elastoplastic {
    /// [`Elastoplastic::update_lanes`] on four particles at once, one per lane of `f64x4`:
    /// their stresses, velocity gradients (1/ms) and yield scales in, the increments out. The
    /// same bits as four scalar updates; a lane of zero stress and gradient stays zero (callers
    /// fill short groups so).
    #[inline(always)]
    pub fn update_four(
        &self,
        stress: &mut [Sym; 4],
        l: &[Matrix3<Real>; 4],
        dt: Real,
        yield_scale: [Real; 4],
    ) -> [Increment; 4] {
        // Plain loops: closures over arrays here were measured not inlined in one build (the
        // stress phase 40 % slower).
        let mut lv = [[f64x4::splat(0.0); 3]; 3];
        for r in 0..3 {
            for k in 0..3 {
                lv[r][k] = f64x4::new([l[0][(r, k)], l[1][(r, k)], l[2][(r, k)], l[3][(r, k)]]);
            }
        }
        let mut sv = [f64x4::splat(0.0); 6];
        for (k, v) in sv.iter_mut().enumerate() {
            *v = f64x4::new([stress[0][k], stress[1][k], stress[2][k], stress[3][k]]);
        }
        let inc = self.update_lanes(&mut sv, &lv, dt, f64x4::new(yield_scale));
        let (plastic, power) = (inc.plastic_strain.to_array(), inc.stress_power.to_array());
        for (k, v) in sv.iter().enumerate() {
            let a = v.to_array();
            for j in 0..4 {
                stress[j][k] = a[j];
            }
        }
        [0, 1, 2, 3].map(|j| Increment {
            plastic_strain: plastic[j],
            stress_power: power[j],
        })
    }
}

/// The arithmetic of the stress update, for one particle (`f64`) or four (`f64x4`, one per
/// lane): IEEE-exact operations, so that the lanes agree bit for bit with the scalar form.
pub trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    fn splat(x: Real) -> Self;
    fn sqrt(self) -> Self;
    /// The smaller; the other one where one is NaN (as `f64::min`).
    fn min(self, other: Self) -> Self;
    /// The larger; the other one where one is NaN (as `f64::max`).
    fn max(self, other: Self) -> Self;
}

impl Lanes for Real {
    #[inline(always)]
    fn splat(x: Real) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Real::sqrt(self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Real::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Real::max(self, other)
    }
}

impl Lanes for f64x4 {
    #[inline(always)]
    fn splat(x: Real) -> Self {
        f64x4::splat(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64x4::sqrt(self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f64x4::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64x4::max(self, other)
    }
}

/// von Mises equivalent stress, MPa.
pub fn von_mises(s: &Sym) -> Real {
    let p = (s[0] + s[1] + s[2]) / 3.0;
    let (a, b, c) = (s[0] - p, s[1] - p, s[2] - p);
    (1.5 * (a * a + b * b + c * c + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    const E: Real = 3378.4;
    const NU: Real = 0.42;
    const SY: Real = 65.5;

    /// Uniaxial stress: strain along x, lateral faces free (the lateral strain found by
    /// iterating to σyy = σzz = 0). Elastic slope E until σy; then σxx stays at σy exactly
    /// (perfect plasticity, radial return is exact for proportional loading).
    /// The 3×3 form the six-component update replaced: σ + (W·σ − σ·W + 2G·D + λ·tr D·I)·dt,
    /// then the radial return.
    fn update_as_matrices(
        m: &Elastoplastic,
        stress: &mut Sym,
        l: &Matrix3<Real>,
        dt: Real,
    ) -> Increment {
        let d = 0.5 * (l + l.transpose());
        let w = 0.5 * (l - l.transpose());
        let old = to_matrix(stress);
        let mut trial = old + (w * old - old * w) * dt + d * (2.0 * m.shear * dt);
        for i in 0..3 {
            trial[(i, i)] += m.lambda * d.trace() * dt;
        }
        let p = trial.trace() / 3.0;
        let mut s = trial;
        for i in 0..3 {
            s[(i, i)] -= p;
        }
        let q = (1.5 * s.norm_squared()).sqrt();
        let mut plastic_strain = 0.0;
        if q > m.yield_stress {
            s *= m.yield_stress / q;
            plastic_strain = (q - m.yield_stress) / (3.0 * m.shear);
        }
        for i in 0..3 {
            s[(i, i)] += p;
        }
        let stress_power = 0.5 * (old + s).component_mul(&d).sum();
        *stress = from_matrix(&s);
        Increment {
            plastic_strain,
            stress_power,
        }
    }

    /// The six-component update is the 3×3 algebra: same stress, plastic strain and stress
    /// power to round-off (1e-12 of the yield stress), elastic and plastic, with spin.
    #[test]
    fn the_six_component_update_agrees_with_the_matrix_form() {
        let m = Elastoplastic::new(E, NU, SY);
        for k in 0..200 {
            let f = |j: usize| ((k * 7 + j * 13) as Real * 0.618).sin();
            let scale = if k % 2 == 0 { 1e-3 } else { 3e-2 };
            let l = Matrix3::from_fn(|i, j| scale * f(3 * i + j));
            let start: Sym = std::array::from_fn(|j| 30.0 * f(20 + j));
            let (mut a, mut b) = (start, start);
            let ia = m.update(&mut a, &l, 1.0, 1.0);
            let ib = update_as_matrices(&m, &mut b, &l, 1.0);
            for j in 0..6 {
                assert!((a[j] - b[j]).abs() < 1e-12 * SY, "{k}: {a:?} vs {b:?}");
            }
            assert!((ia.plastic_strain - ib.plastic_strain).abs() < 1e-15);
            assert!((ia.stress_power - ib.stress_power).abs() < 1e-12 * SY * scale * 10.0);
        }
    }

    /// Four particles at once (`f64x4`) give each particle's bits from the scalar update:
    /// elastic and plastic lanes mixed, weak (scaled) lanes, a zero lane.
    #[test]
    fn four_lanes_give_the_scalar_bits() {
        let m = Elastoplastic::new(E, NU, SY);
        for k in 0..100 {
            let f = |j: usize| ((k * 11 + j * 5) as Real * 0.377).sin();
            let ls: [Matrix3<Real>; 4] = std::array::from_fn(|lane| {
                let scale = [1e-3, 3e-2, 1e-4, 0.0][(lane + k) % 4];
                Matrix3::from_fn(|i, j| scale * f(3 * i + j + 9 * lane))
            });
            let starts: [Sym; 4] =
                std::array::from_fn(|lane| std::array::from_fn(|j| 40.0 * f(50 + j + 6 * lane)));
            let scales = [1.0, 0.01, 1.0, 0.5];
            let mut lanes: [f64x4; 6] = std::array::from_fn(|j| f64x4::new(starts.map(|s| s[j])));
            let lv: [[f64x4; 3]; 3] =
                std::array::from_fn(|r| std::array::from_fn(|c| f64x4::new(ls.map(|l| l[(r, c)]))));
            let inc = m.update_lanes(&mut lanes, &lv, 1.0, f64x4::new(scales));
            for lane in 0..4 {
                let mut s = starts[lane];
                let one = m.update(&mut s, &ls[lane], 1.0, scales[lane]);
                for j in 0..6 {
                    assert_eq!(s[j].to_bits(), lanes[j].to_array()[lane].to_bits());
                }
                assert_eq!(
                    one.plastic_strain.to_bits(),
                    inc.plastic_strain.to_array()[lane].to_bits()
                );
                assert_eq!(
                    one.stress_power.to_bits(),
                    inc.stress_power.to_array()[lane].to_bits()
                );
            }
        }
    }

    #[test]
    fn uniaxial_stress_yields_at_sigma_y_and_stays_there() {
        let m = Elastoplastic::new(E, NU, SY);
        let mut s = [0.0; 6];
        let dt = 1.0;
        let rate = 1e-5; // strain per step
        let mut strain = 0.0;
        for _ in 0..4000 {
            // lateral rate that keeps lateral stress zero: solve with a few fixed-point passes
            let mut lat = -NU * rate;
            for _ in 0..50 {
                let mut trial = s;
                let l = Matrix3::from_diagonal(&nalgebra::Vector3::new(rate, lat, lat));
                m.update(&mut trial, &l, dt, 1.0);
                // dσyy/dε_lat ≈ λ + 2G
                lat -= trial[1] / m.p_wave_modulus() * 0.9;
            }
            let l = Matrix3::from_diagonal(&nalgebra::Vector3::new(rate, lat, lat));
            m.update(&mut s, &l, dt, 1.0);
            strain += rate;
            let elastic = E * strain;
            if elastic < 0.99 * SY {
                // Hypoelastic update with small steps: within 0.5 % of Hooke's law.
                assert!(
                    (s[0] - elastic).abs() < 5e-3 * elastic,
                    "{} vs {}",
                    s[0],
                    elastic
                );
            }
            assert!(s[0] <= SY * (1.0 + 1e-9), "overshoot {}", s[0]);
            assert!(s[1].abs() < 1e-6 * SY && s[2].abs() < 1e-6 * SY);
        }
        assert!(strain > 2.0 * SY / E);
        assert!((s[0] - SY).abs() < 1e-9 * SY, "flow stress {}", s[0]);
        assert!((von_mises(&s) - SY).abs() < 1e-9 * SY);
    }

    /// A spin alone (L skew) must rotate a stress state without changing it otherwise:
    /// after a rotation by angle θ about z, σ = R σ0 Rᵀ; the Jaumann update is first-order
    /// accurate, so with 10⁴ steps for θ = 0.5 the error is of order θ²/10⁴ relative.
    #[test]
    fn spin_rotates_stress_objectively() {
        let m = Elastoplastic::new(E, NU, 1e30);
        let s0 = [30.0, -10.0, 5.0, 0.0, 0.0, 0.0];
        let mut s = s0;
        let theta: Real = 0.5;
        let steps = 10_000;
        let omega = theta / steps as Real;
        let l = Matrix3::new(0.0, -omega, 0.0, omega, 0.0, 0.0, 0.0, 0.0, 0.0);
        for _ in 0..steps {
            m.update(&mut s, &l, 1.0, 1.0);
        }
        let r = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::z_axis(), theta);
        let expected = r.matrix() * to_matrix(&s0) * r.matrix().transpose();
        let err = (to_matrix(&s) - expected).norm() / to_matrix(&s0).norm();
        assert!(err < 1e-3, "relative error {err}");
        // the explicit spin update changes invariants by O(θ ω) = 2.5e-5 relative
        assert!((von_mises(&s) - von_mises(&s0)).abs() < 1e-4 * von_mises(&s0));
    }

    #[test]
    fn zero_gradient_leaves_stress_unchanged() {
        let m = Elastoplastic::new(E, NU, SY);
        let mut s = [1.0, 2.0, 3.0, 0.5, 0.25, 0.125];
        let before = s;
        let inc = m.update(&mut s, &Matrix3::zeros(), 1.0, 1.0);
        assert_eq!(s, before);
        assert_eq!(inc.plastic_strain, 0.0);
    }
}
