//! A valid case → the scene the engine runs: tube particles on a cylindrical lattice with exact
//! volumes, two rigid plates normal to z, and the numerical settings. Units: mm, ms, g, MPa.
//!
//! Axial loading: tube axis z, bottom plate at z = 0 (fixed), top plate at z = l moving down.
//! Lateral loading: tube axis x over 0..l, centred on y = z = 0, plates at z = ∓(d + t)/2.
//!
//! The reduced models lay out the section in the engine's x–z plane (y is the direction the
//! symmetry removes, and stays 0): axisymmetric, x is the radius r and z the axis, each
//! particle standing for its whole ring (volume 2π·r·area); plane strain, x and z are the
//! cross-section's y and z of the lateral scene, each particle standing for the tube's length
//! (volume area·l). Loads and energies are then those of the whole tube.

use crate::solver::engine::particles::Particles;
use crate::solver::model::case::Case;
pub use crate::solver::model::contact::{Plate, Ramp, BOTTOM, TOP};
use crate::solver::model::material::MaterialLaw;
use crate::solver::Real;

/// Everything the engine needs; tests build their own.
#[derive(Debug, Clone)]
pub struct Scene {
    pub particles: Particles,
    pub material: MaterialLaw,
    /// Density of the undeformed material in the equations of motion, g/mm³ (for the wave
    /// speed): the material's times the case's mass scaling.
    pub density: Real,
    pub plates: Vec<Plate>,
    pub friction: Real,
    /// Background cell size, mm.
    pub cell: Real,
    /// Half the particle spacing, mm (uGIMP particle half-width).
    pub half_size: Real,
    pub cfl: Real,
    /// Cell-averaged dilation and pressure (see `Discretization::volumetric_averaging`).
    pub average_volumetric: bool,
    /// Particles must stay inside this box (mm); leaving it is reported as an instability.
    pub domain: [[Real; 3]; 2],
    /// How the plates come up to speed.
    pub ramp: Ramp,
}

impl Scene {
    /// The tube and plates a case describes, with the trigger's weak particles.
    pub fn from_case(case: &Case) -> Scene {
        let spec = case.spec();
        let geometry = case.geometry();
        let h = case.spacing_mm();
        let rho = spec.material.density_kg_m3 * 1e-6 * spec.discretization.mass_scaling;
        let mut particles = Particles::default();
        particles.reserve_exact(case.particle_count() as usize);
        geometry.each_point(|x, vol| particles.push(x, rho * vol, vol));
        let speed = spec.loading.plate_speed_m_s;
        let (top, bottom) = geometry.plates_z();
        let cell = case.cell_mm();
        let mut scene = Scene {
            particles,
            material: MaterialLaw::of(&spec.material).at_rates_scaled(spec.loading.rate_scale()),
            density: rho,
            plates: vec![
                Plate {
                    z: top,
                    side: 1.0,
                    velocity: 0.0,
                    full_velocity: -speed,
                },
                Plate {
                    z: bottom,
                    side: -1.0,
                    velocity: 0.0,
                    full_velocity: 0.0,
                },
            ],
            friction: spec.contact.friction,
            cell,
            half_size: 0.5 * h,
            cfl: case.cfl(),
            average_volumetric: spec.discretization.volumetric_averaging,
            domain: geometry.domain(cell),
            ramp: Ramp::over(case.ramp_mm(), speed),
        };
        let trigger = &spec.trigger;
        let weak = (trigger.weak_fraction * scene.particles.len() as Real).round() as usize;
        if weak > 0 {
            let mut scale = vec![1.0; scene.particles.len()];
            for p in choose(scene.particles.len(), weak, trigger.seed) {
                scale[p] = trigger.strength_ratio;
            }
            scene.particles.yield_scale = scale;
        }
        scene
    }

    /// Sets each plate's velocity for a step of `dt` from `time` (ms): its mean over the step,
    /// so that its travel in the step is exact on the ramp.
    pub fn set_plate_velocities(&mut self, time: Real, dt: Real) {
        let ramp = self.ramp;
        let share = (ramp.full_speed_time(time + dt) - ramp.full_speed_time(time)) / dt;
        for plate in &mut self.plates {
            plate.velocity = plate.full_velocity * share;
        }
    }

    /// Moves each plate over a step of `dt` ms at the velocity the step used.
    pub fn move_plates(&mut self, dt: Real) {
        for plate in &mut self.plates {
            plate.z += plate.velocity * dt;
        }
    }

    /// Dilatational wave speed of the undeformed material, mm/ms.
    pub fn wave_speed(&self) -> Real {
        (self.material.p_wave_modulus() / self.density).sqrt()
    }
}

/// `k` distinct indices below `n`, drawn by a seeded partial Fisher–Yates shuffle. The generator
/// is SplitMix64, written out so that a seed means the same particles in every build.
fn choose(n: usize, k: usize, seed: u64) -> Vec<usize> {
    let mut state = seed;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    let mut idx: Vec<usize> = (0..n).collect();
    for i in 0..k.min(n) {
        let j = i + (next() % (n - i) as u64) as usize;
        idx.swap(i, j);
    }
    idx.truncate(k.min(n));
    idx
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::model::case::Limits;

    #[test]
    fn scene_counts_what_the_case_promised() {
        let case =
            Case::from_json(r#"{"loading": {"mode": "lateral"}}"#, &Limits::default()).unwrap();
        let scene = Scene::from_case(&case);
        assert_eq!(scene.particles.len() as u64, case.particle_count());
        // Lateral: every particle between the plates, axis along x.
        let zmax = scene
            .particles
            .x
            .iter()
            .map(|x| x.z)
            .fold(Real::MIN, Real::max);
        assert!(zmax < scene.plates[TOP].z && zmax > scene.plates[TOP].z - case.spacing_mm());
    }

    #[test]
    fn a_ramp_travels_its_distance_and_inverts() {
        // 0.5 mm at 10 mm/ms: 0.1 ms, at the end of which the plate has travelled 0.05 ms at
        // full speed; after it, a plate that started at full speed leads by 0.05 ms.
        let r = Ramp::over(0.5, 10.0);
        assert!((r.ms - 0.1).abs() < 1e-15);
        assert!((10.0 * r.full_speed_time(0.1) - 0.5).abs() < 1e-12);
        assert!((r.full_speed_time(0.3) - 0.25).abs() < 1e-15);
        // Half way through the ramp: a quarter of the ramp's travel (v rises linearly).
        assert!((10.0 * r.full_speed_time(0.05) - 0.125).abs() < 1e-12);
        for t in [0.0, 0.01, 0.05, 0.1, 0.2, 3.0] {
            assert!((r.time_at(r.full_speed_time(t)) - t).abs() < 1e-12, "{t}");
        }
        // No ramp: time is time.
        let none = Ramp::over(0.0, 10.0);
        assert_eq!((none.full_speed_time(0.7), none.time_at(0.7)), (0.7, 0.7));
    }

    #[test]
    fn trigger_is_reproducible_and_of_the_right_size() {
        let text = r#"{"trigger": {"weak_fraction": 0.003, "seed": 7}, "discretization": {"particles_through_thickness": 2}}"#;
        let case = Case::from_json(text, &Limits::default()).unwrap();
        let a = Scene::from_case(&case);
        let b = Scene::from_case(&case);
        assert_eq!(a.particles.yield_scale, b.particles.yield_scale);
        let weak = a.particles.yield_scale.iter().filter(|&&s| s < 1.0).count();
        assert_eq!(weak, (0.003 * a.particles.len() as f64).round() as usize);
        let other = Case::from_json(&text.replace("7", "8"), &Limits::default()).unwrap();
        assert_ne!(
            Scene::from_case(&other).particles.yield_scale,
            a.particles.yield_scale
        );
    }
}
