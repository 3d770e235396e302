//! Elastic–perfectly plastic J2 (von Mises) plasticity with radial return: the paper's model.
//! The flow stress is the yield stress σy, scaled per particle by the trigger's factor.

use super::law::{lame, trial, Increment, Lanes, Law, Point};
use crate::solver::Real;

/// An elastic–perfectly plastic material: Lamé's λ, the shear modulus G and the yield stress
/// σy, MPa.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct J2 {
    pub lambda: Real,
    pub shear: Real,
    pub yield_stress: Real,
}

impl J2 {
    /// Of Young's modulus E, Poisson's ratio ν and the yield stress σy (MPa).
    pub fn new(youngs: Real, poisson: Real, yield_stress: Real) -> J2 {
        let (lambda, shear) = lame(youngs, poisson);
        J2 {
            lambda,
            shear,
            yield_stress,
        }
    }
}

impl Law for J2 {
    fn p_wave_modulus(&self) -> Real {
        self.lambda + 2.0 * self.shear
    }

    /// The elastic trial, then the radial return of its deviator to the von Mises surface of
    /// the particle's flow stress σy·s; the plastic work is that flow stress times the plastic
    /// strain increment.
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
        // Radial return without a branch: the scale is 1 inside the surface (also for q = 0,
        // where the quotient is infinite), and particles of a crush cross the surface both ways
        // from step to step.
        let flow_stress = c(self.yield_stress) * at.strength_scale;
        let scale = (flow_stress / q).min(c(1.0));
        s.iter_mut().for_each(|v| *v = *v * scale);
        let plastic_strain = ((q - flow_stress) / c(3.0 * self.shear)).max(c(0.0));
        let stress_power = trial.finish(s, stress);
        Increment {
            plastic_strain,
            stress_power,
            plastic_work: flow_stress * plastic_strain,
        }
    }
}
