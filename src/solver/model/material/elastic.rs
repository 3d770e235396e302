//! Linear elasticity (hypoelastic, with the Jaumann rate): the wall never yields, and no step
//! books plastic strain or plastic work.

use super::law::{lame, trial, Increment, Lanes, Law, Point};
use crate::solver::Real;

/// An elastic material: Lamé's λ and the shear modulus G, MPa.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastic {
    pub lambda: Real,
    pub shear: Real,
}

impl Elastic {
    /// Of Young's modulus E (MPa) and Poisson's ratio ν.
    pub fn new(youngs: Real, poisson: Real) -> Elastic {
        let (lambda, shear) = lame(youngs, poisson);
        Elastic { lambda, shear }
    }
}

impl Law for Elastic {
    fn p_wave_modulus(&self) -> Real {
        self.lambda + 2.0 * self.shear
    }

    #[inline(always)]
    fn update_lanes<T: Lanes>(
        &self,
        stress: &mut [T; 6],
        l: &[[T; 3]; 3],
        dt: Real,
        _at: Point<T>,
    ) -> Increment<T> {
        let trial = trial((self.lambda, self.shear), stress, l, dt);
        let deviator = trial.deviator;
        let stress_power = trial.finish(deviator, stress);
        Increment {
            plastic_strain: T::splat(0.0),
            stress_power,
            plastic_work: T::splat(0.0),
        }
    }
}
