//! What every material law shares: the [`Law`] trait a law implements, the stress layout
//! ([`Sym`], MPa), what an update reads ([`Point`]) and returns ([`Increment`]), the lane
//! arithmetic ([`Lanes`]), Lamé's constants and the elastic trial with its Jaumann rate
//! ([`trial`]). Stress in MPa, time in ms, velocity gradient in 1/ms. Imports nothing of the
//! material folder; `mod.rs` (which re-exports it) and each law (`elastic.rs`, `j2.rs`,
//! `metal.rs`) import it.

use crate::solver::Real;
use nalgebra::Matrix3;
use std::ops::{Add, Div, Mul, Sub};
use wide::f64x4;

/// Symmetric stress in Voigt order xx, yy, zz, yz, xz, xy (MPa).
pub type Sym = [Real; 6];

/// What one stress update did to a particle (or, with `T = f64x4`, to four).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Increment<T = Real> {
    /// Equivalent plastic strain increment.
    pub plastic_strain: T,
    /// Stress power density σ:D over the step, trapezoidal, MPa/ms.
    pub stress_power: T,
    /// Plastic work dissipated per unit volume over the step, MPa (= mJ/mm³): the flow stress
    /// times the plastic strain increment.
    pub plastic_work: T,
}

/// What a particle carries that its law reads besides its stress.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point<T = Real> {
    /// The trigger's factor on the particle's strength (< 1 for a weak particle, else 1).
    pub strength_scale: T,
    /// Equivalent plastic strain so far.
    pub plastic_strain: T,
}

impl Point<Real> {
    /// A particle of full strength that has not yielded.
    pub const FRESH: Point<Real> = Point {
        strength_scale: 1.0,
        plastic_strain: 0.0,
    };
}

/// A constitutive law of the wall.
pub trait Law: Copy + Send + Sync + 'static {
    /// P-wave (constrained) modulus λ + 2G, MPa: c² = M / ρ, for the time step.
    fn p_wave_modulus(&self) -> Real;

    /// Advances `stress` by one step under velocity gradient `l` over `dt` ms, for a particle
    /// (or four, one per lane) in the state `at`. Every operation is IEEE lane by lane and
    /// written in one order, so four particles at once give the bits each gives alone.
    fn update_lanes<T: Lanes>(
        &self,
        stress: &mut [T; 6],
        l: &[[T; 3]; 3],
        dt: Real,
        at: Point<T>,
    ) -> Increment<T>;

    /// [`Law::update_lanes`] for one particle.
    #[inline]
    fn update(&self, stress: &mut Sym, l: &Matrix3<Real>, dt: Real, at: Point) -> Increment {
        let l = [0, 1, 2].map(|i| [0, 1, 2].map(|j| l[(i, j)]));
        self.update_lanes(stress, &l, dt, at)
    }

    /// [`Law::update_lanes`] on four particles at once, one per lane of `f64x4`: their
    /// stresses, velocity gradients (1/ms) and states in, the increments out. The same bits as
    /// four scalar updates; a lane of zero stress and gradient stays zero (callers fill short
    /// groups so).
    #[inline(always)]
    fn update_four(
        &self,
        stress: &mut [Sym; 4],
        l: &[Matrix3<Real>; 4],
        dt: Real,
        at: [Point; 4],
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
        let point = Point {
            strength_scale: f64x4::new(at.map(|p| p.strength_scale)),
            plastic_strain: f64x4::new(at.map(|p| p.plastic_strain)),
        };
        let inc = self.update_lanes(&mut sv, &lv, dt, point);
        let (plastic, power, work) = (
            inc.plastic_strain.to_array(),
            inc.stress_power.to_array(),
            inc.plastic_work.to_array(),
        );
        for (k, v) in sv.iter().enumerate() {
            let a = v.to_array();
            for j in 0..4 {
                stress[j][k] = a[j];
            }
        }
        [0, 1, 2, 3].map(|j| Increment {
            plastic_strain: plastic[j],
            stress_power: power[j],
            plastic_work: work[j],
        })
    }
}

/// Lamé's first parameter λ and the shear modulus G (MPa) of Young's modulus E (MPa) and
/// Poisson's ratio ν.
pub fn lame(youngs: Real, poisson: Real) -> (Real, Real) {
    let lambda = youngs * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    let shear = youngs / (2.0 * (1.0 + poisson));
    (lambda, shear)
}

/// The elastic trial of a step, split for a law's return: the deviator of the trial stress,
/// its pressure, and what the stress power needs (the old stress and the rate of deformation).
pub struct Trial<T> {
    /// Deviatoric trial stress (Sym order), MPa.
    pub deviator: [T; 6],
    /// Mean trial stress, MPa.
    pub pressure: T,
    /// The stress before the step, MPa.
    pub old: [T; 6],
    /// Rate of deformation D (Sym order), 1/ms.
    pub rate: [T; 6],
}

/// The Jaumann rate of the elastic trial stress under `l` over `dt` (elastic constants λ and
/// G, MPa), written on the six components of the symmetric tensors: with W the spin and σ
/// symmetric, W·σ − σ·W = A + Aᵀ for A = W·σ, so only its six distinct entries are formed —
/// the same algebra as the 3×3 form, with no 3×3 products (the matrix form was 29 % of a
/// linear-shape step in `perf record`).
#[inline(always)]
pub fn trial<T: Lanes>(
    (lambda, shear): (Real, Real),
    stress: &[T; 6],
    l: &[[T; 3]; 3],
    dt: Real,
) -> Trial<T> {
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
    let (dt, two_g) = (c(dt), c(2.0 * shear * dt));
    let lam = c(lambda) * (d[0] + d[1] + d[2]) * dt;
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
    Trial {
        deviator: s,
        pressure: p,
        old,
        rate: d,
    }
}

impl<T: Lanes> Trial<T> {
    /// The von Mises stress of the deviatoric trial, q = √(3/2 s:s), MPa.
    #[inline(always)]
    pub fn von_mises(&self) -> T {
        let c = T::splat;
        let s = &self.deviator;
        let norm2 = s[0] * s[0]
            + s[1] * s[1]
            + s[2] * s[2]
            + c(2.0) * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]);
        (c(1.5) * norm2).sqrt()
    }

    /// The stress of the returned `deviator` (the trial's pressure added back) into `stress`,
    /// and the step's trapezoidal stress power density, MPa/ms.
    #[inline(always)]
    pub fn finish(self, mut deviator: [T; 6], stress: &mut [T; 6]) -> T {
        let (half, two) = (T::splat(0.5), T::splat(2.0));
        for v in &mut deviator[..3] {
            *v = *v + self.pressure;
        }
        let (old, d) = (self.old, self.rate);
        let power = |k: usize| (old[k] + deviator[k]) * d[k];
        let stress_power =
            half * (power(0) + power(1) + power(2) + two * (power(3) + power(4) + power(5)));
        *stress = deviator;
        stress_power
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
    /// `f` of each lane's values of `args`, lane by lane: the scalar code of a law that has no
    /// lane-wise form (a power, a table lookup, a Newton solve), so that four lanes give the
    /// bits of one by construction.
    fn each<const K: usize>(args: [Self; K], f: impl Fn([Real; K]) -> Real) -> Self;
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
    #[inline(always)]
    fn each<const K: usize>(args: [Self; K], f: impl Fn([Real; K]) -> Real) -> Self {
        f(args)
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
    #[inline(always)]
    fn each<const K: usize>(args: [Self; K], f: impl Fn([Real; K]) -> Real) -> Self {
        let lanes = args.map(|a| a.to_array());
        f64x4::new([0, 1, 2, 3].map(|j| f(lanes.map(|l| l[j]))))
    }
}
