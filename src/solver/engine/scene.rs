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
use crate::solver::model::case::{around, layers_along, Case, LoadingMode, MaterialModel, Model};
use crate::solver::model::material::Elastoplastic;
use crate::solver::Real;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// A rigid plate normal to z, of infinite mass, moving at a prescribed velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plate {
    /// z of the surface, mm.
    pub z: Real,
    /// +1 when the tube lies below the plate (the top plate), −1 when above (the bottom plate):
    /// the z component of the normal pointing out of the tube towards the plate.
    pub side: Real,
    /// z velocity now, mm/ms (below `full_velocity` while the plate comes up to speed).
    pub velocity: Real,
    /// z velocity once up to speed, mm/ms.
    pub full_velocity: Real,
}

/// How the moving plate comes up to speed: its velocity rises linearly in time from 0 to full
/// over `ms`, in which it travels `ms`·speed/2; then it stays. A plate that starts at full speed
/// against a tube at rest is an impact: it sends a stress wave ρ·c·v into the wall (about
/// 400 MPa for steel at 10 m/s, above yield) that no quasi-static test has.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Ramp {
    /// Duration of the ramp, ms; 0 for a plate that starts at full speed.
    pub ms: Real,
}

impl Ramp {
    /// The ramp over which a plate at `speed` (mm/ms) travels `mm`.
    pub fn over(mm: Real, speed: Real) -> Ramp {
        Ramp {
            ms: if mm > 0.0 { 2.0 * mm / speed } else { 0.0 },
        }
    }

    /// ∫₀ᵗ velocity / full velocity: the time at full speed that gives the same travel, ms.
    pub fn full_speed_time(&self, t: Real) -> Real {
        if t < self.ms {
            t * t / (2.0 * self.ms)
        } else {
            t - 0.5 * self.ms
        }
    }

    /// The time at which the travel equals that of `tau` ms at full speed (the inverse of
    /// [`Ramp::full_speed_time`]), ms.
    pub fn time_at(&self, tau: Real) -> Real {
        if tau < 0.5 * self.ms {
            (2.0 * self.ms * tau).sqrt()
        } else {
            tau + 0.5 * self.ms
        }
    }
}

/// Everything the engine needs; tests build their own.
#[derive(Debug, Clone)]
pub struct Scene {
    pub particles: Particles,
    pub material: Elastoplastic,
    /// Density of the undeformed material, g/mm³ (for the wave speed).
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

/// Index of the top (moving) plate and the bottom (fixed) plate in `Scene::plates`.
pub const TOP: usize = 0;
pub const BOTTOM: usize = 1;

impl Scene {
    /// The tube and plates a case describes, with the trigger's weak particles.
    pub fn from_case(case: &Case) -> Scene {
        let spec = case.spec();
        let (t, d, l) = (
            spec.tube.thickness_mm,
            spec.tube.mean_diameter_mm,
            spec.tube.length_mm,
        );
        let h = case.spacing_mm();
        let rho = spec.material.density_kg_m3 * 1e-6;
        let n = spec.discretization.particles_through_thickness;
        let model = spec.discretization.model;
        let particles = match model {
            Model::ThreeD => tube_lattice(t, d, l, n, rho, spec.loading.mode),
            Model::Axisymmetric | Model::PlaneStrain => section_lattice(t, d, l, n, rho, model),
        };
        let m = &spec.material;
        let yield_stress = match m.model {
            MaterialModel::J2 => m.yield_stress_mpa,
            MaterialModel::Elastic => Real::INFINITY,
        };
        let speed = spec.loading.plate_speed_m_s;
        let outer = (d + t) / 2.0;
        let (top, bottom) = match spec.loading.mode {
            LoadingMode::Axial => (l, 0.0),
            LoadingMode::Lateral => (outer, -outer),
        };
        let reach = outer + l;
        let cell = case.cell_mm();
        let margin = 3.0 * cell;
        let domain = match (model, spec.loading.mode) {
            (Model::ThreeD, LoadingMode::Axial) => {
                [[-reach, -reach, -margin], [reach, reach, l + margin]]
            }
            (Model::ThreeD, LoadingMode::Lateral) => [
                [-reach, -reach, -outer - margin],
                [l + reach, reach, outer + margin],
            ],
            // A particle reaching the axis would divide by r = 0 in its hoop strain rate.
            (_, LoadingMode::Axial) => [[0.0, 0.0, -margin], [reach, 0.0, l + margin]],
            (_, LoadingMode::Lateral) => {
                [[-reach, 0.0, -outer - margin], [reach, 0.0, outer + margin]]
            }
        };
        let mut scene = Scene {
            particles,
            material: Elastoplastic::new(m.youngs_modulus_mpa, m.poisson_ratio, yield_stress),
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
            cfl: spec.discretization.cfl,
            average_volumetric: spec.discretization.volumetric_averaging,
            domain,
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

/// The tube's particle positions before the crush, mm, in the case's particle order (the order
/// of [`crate::solver::Snapshot`]).
pub fn lattice_positions(case: &Case) -> Vec<[Real; 3]> {
    let spec = case.spec();
    // Only the positions: the full particle set is hundreds of bytes a particle, and this is
    // what every state download rebuilds (tests/api_download.rs).
    let (t, d, l) = (
        spec.tube.thickness_mm,
        spec.tube.mean_diameter_mm,
        spec.tube.length_mm,
    );
    let n = spec.discretization.particles_through_thickness;
    let model = spec.discretization.model;
    if model != Model::ThreeD {
        return section_points(t, d, l, n, model)
            .iter()
            .map(|(x, _)| reported(model, l, x))
            .collect();
    }
    let lattice = Lattice::new(t, d, l, n);
    let mut x = Vec::with_capacity(lattice.len());
    x.extend(
        lattice
            .points(spec.loading.mode)
            .map(|(x, _)| [x.x, x.y, x.z]),
    );
    x
}

/// The particle lattice of a tube wall: `n` layers through the thickness at spacing h = t/n;
/// each layer at mid-radius r holds round(2πr/h) particles around and round(l/h) along. Each
/// particle's volume is its exact annular sector, so the volumes add up to π d t l.
struct Lattice {
    /// Per layer: mid-radius (mm), particles around, volume of each (mm³).
    rings: Vec<(Real, usize, Real)>,
    along: usize,
    dz: Real,
}

impl Lattice {
    fn new(t: Real, d: Real, l: Real, n: u32) -> Lattice {
        let h = t / n as Real;
        let inner = d / 2.0 - t / 2.0;
        let along = layers_along(l, h) as usize;
        let dz = l / along as Real;
        let rings = (0..n)
            .map(|j| {
                let (r0, r1) = (inner + j as Real * h, inner + (j + 1) as Real * h);
                let r = 0.5 * (r0 + r1);
                let count = around(r, h) as usize;
                (
                    r,
                    count,
                    0.5 * (r1 * r1 - r0 * r0) * (2.0 * PI / count as Real) * dz,
                )
            })
            .collect();
        Lattice { rings, along, dz }
    }

    fn len(&self) -> usize {
        self.rings.iter().map(|r| r.1).sum::<usize>() * self.along
    }

    /// Each particle's centre and volume, axial position outermost, then angle, then radius:
    /// neighbours in space stay near in memory.
    fn points(&self, mode: LoadingMode) -> impl Iterator<Item = (Vector3<Real>, Real)> + '_ {
        (0..self.along).flat_map(move |k| {
            let s = (k as Real + 0.5) * self.dz;
            self.rings.iter().flat_map(move |&(r, count, vol)| {
                (0..count).map(move |i| {
                    let th = (i as Real + 0.5) * 2.0 * PI / count as Real;
                    let (c, sn) = (r * th.cos(), r * th.sin());
                    let x = match mode {
                        LoadingMode::Axial => Vector3::new(c, sn, s),
                        LoadingMode::Lateral => Vector3::new(s, c, sn),
                    };
                    (x, vol)
                })
            })
        })
    }
}

/// The section a reduced model runs, as the engine holds it: per particle its centre in the
/// x–z plane and the volume it stands for (see the module's note), mm and mm³. Axisymmetric:
/// n layers through the wall by round(l/h) along, each the annulus π(r₁² − r₀²)·dz. Plane
/// strain: the rings of [`Lattice`] in the y–z cross-section (y as x), each sector times l,
/// ordered by angle.
fn section_points(t: Real, d: Real, l: Real, n: u32, model: Model) -> Vec<(Vector3<Real>, Real)> {
    let lattice = Lattice::new(t, d, l, n);
    let h = t / n as Real;
    let inner = d / 2.0 - t / 2.0;
    match model {
        Model::Axisymmetric => (0..lattice.along)
            .flat_map(|k| {
                let z = (k as Real + 0.5) * lattice.dz;
                (0..n).map(move |j| {
                    let (r0, r1) = (inner + j as Real * h, inner + (j + 1) as Real * h);
                    let vol = PI * (r1 * r1 - r0 * r0) * lattice.dz;
                    (Vector3::new(0.5 * (r0 + r1), 0.0, z), vol)
                })
            })
            .collect(),
        Model::PlaneStrain | Model::ThreeD => {
            let mut points: Vec<(Real, Vector3<Real>, Real)> = lattice
                .rings
                .iter()
                .flat_map(|&(r, count, vol)| {
                    (0..count).map(move |i| {
                        let th = (i as Real + 0.5) * 2.0 * PI / count as Real;
                        let x = Vector3::new(r * th.cos(), 0.0, r * th.sin());
                        (th, x, vol / lattice.dz * l)
                    })
                })
                .collect();
            // Around the ring, then out through the wall: a run of particles is an arc, and
            // the scatter's patch over it small.
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            points.into_iter().map(|(_, x, vol)| (x, vol)).collect()
        }
    }
}

/// Particles of a reduced model's section (see [`section_points`]), of density `rho`.
pub fn section_lattice(t: Real, d: Real, l: Real, n: u32, rho: Real, model: Model) -> Particles {
    let mut p = Particles::default();
    for (x, vol) in section_points(t, d, l, n, model) {
        p.push(x, rho * vol, vol);
    }
    p
}

/// Where outputs put an engine position: the 3D scene's coordinates. Axisymmetric: (r, 0, z),
/// the section at angle 0. Plane strain: the cross-section at mid-length, (l/2, x, z).
pub fn reported(model: Model, length: Real, x: &Vector3<Real>) -> [Real; 3] {
    match model {
        Model::ThreeD | Model::Axisymmetric => [x.x, x.y, x.z],
        Model::PlaneStrain => [0.5 * length, x.x, x.z],
    }
}

/// What the points of a reduced model's outputs are, for a reader of the files: None for 3D.
pub fn symmetry_note(case: &Case) -> Option<&'static str> {
    match case.spec().discretization.model {
        Model::ThreeD => None,
        Model::Axisymmetric => Some(
            "axisymmetric model: the points are the (r, z) section at angle 0 (x = r, y = 0); \
             each stands for its ring about the z axis, and the tube is this section revolved",
        ),
        Model::PlaneStrain => Some(
            "plane-strain model: the points are the cross-section at mid-length (x = l/2); each \
             stands for a line of material along the tube axis x, and the tube is this section \
             extruded over its length",
        ),
    }
}

/// Particles of a tube wall laid out as [`Lattice`] says, of density `rho`.
pub fn tube_lattice(t: Real, d: Real, l: Real, n: u32, rho: Real, mode: LoadingMode) -> Particles {
    let lattice = Lattice::new(t, d, l, n);
    let mut p = Particles::default();
    p.x.reserve_exact(lattice.len());
    for (x, vol) in lattice.points(mode) {
        p.push(x, rho * vol, vol);
    }
    p
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
    fn lattice_volumes_add_up_to_the_wall() {
        let (t, d, l) = (3.2, 22.2, 76.2);
        for mode in [LoadingMode::Axial, LoadingMode::Lateral] {
            let p = tube_lattice(t, d, l, 4, 1.38e-3, mode);
            let vol: Real = p.vol.iter().sum();
            let exact = PI * d * t * l;
            assert!((vol / exact - 1.0).abs() < 1e-12, "{vol} vs {exact}");
        }
    }

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
