//! Physics of the engine against closed forms and conservation laws. Each test states its
//! tolerance and why. Scenes are small so that the suite stays fast in CI.

use crush::solver::engine::grid::{Full, Remap};
use crush::solver::engine::kernel::{Clock, Phases};
use crush::solver::engine::particles::Particles;
use crush::solver::engine::scene::{Plate, Ramp, Scene};
use crush::solver::engine::shape::{Bspline, Gimp, Linear, Stencil};
use crush::solver::engine::solid::Simulation;
use crush::solver::model::material::{von_mises, Elastic, MaterialLaw, J2};
use nalgebra::Vector3;

const RHO: f64 = 1.38e-3; // g/mm³ (PVC)

/// A box of nx × ny × nz particles at spacing h (mm), cell 2h, no plates.
fn block(n: [usize; 3], h: f64, material: MaterialLaw) -> Scene {
    let mut p = Particles::default();
    for i in 0..n[0] {
        for j in 0..n[1] {
            for k in 0..n[2] {
                let x = Vector3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * h;
                p.push(
                    x + Vector3::new(0.13, 0.29, 0.07),
                    RHO * h * h * h,
                    h * h * h,
                );
            }
        }
    }
    Scene {
        particles: p,
        material,
        density: RHO,
        plates: vec![],
        friction: 0.0,
        cell: 2.0 * h,
        half_size: 0.5 * h,
        cfl: 0.5,
        average_volumetric: true,
        domain: [[-1e3; 3], [1e3; 3]],
        ramp: Ramp::default(),
    }
}

fn pvc() -> MaterialLaw {
    MaterialLaw::J2(J2::new(3378.4, 0.42, 65.5))
}

fn max_stress<S: Stencil>(sim: &Simulation<S>) -> f64 {
    sim.state
        .scene
        .particles
        .stress
        .iter()
        .flat_map(|s| s.iter())
        .fold(0.0f64, |a, &b| a.max(b.abs()))
}

/// Runs the block once per shape function, with `S` its type and `shape` its name.
macro_rules! each_shape {
    (|$S:ident, $shape:ident| $body:block) => {{
        {
            type $S = Linear;
            let $shape = "linear";
            $body
        }
        {
            type $S = Gimp;
            let $shape = "gimp";
            $body
        }
        {
            type $S = Bspline;
            let $shape = "bspline";
            $body
        }
    }};
}

/// A uniform velocity has zero gradient: Σ_i v ⊗ ∇N_i = v ⊗ Σ_i ∇N_i = 0 to round-off, so no
/// stress may appear. Round-off after 300 steps: ~1e-13 · E · (v dt / cell) · steps ≪ 1e-9 MPa.
#[test]
fn rigid_translation_gives_zero_stress() {
    each_shape!(|S, shape| {
        let mut scene = block([6, 5, 4], 0.5, pvc());
        let v = Vector3::new(3.0, -2.0, 1.0);
        scene.particles.v.iter_mut().for_each(|p| *p = v);
        let x0 = scene.particles.x.clone();
        let mut sim = Simulation::<S>::new(scene);
        for _ in 0..300 {
            sim.step(1.0).unwrap();
        }
        assert!(
            max_stress(&sim) < 1e-9,
            "{shape:?}: stress {}",
            max_stress(&sim)
        );
        // The step reorders particles (by block, and by reach within one): `id` is each one's
        // place in the scene as built.
        let p = &sim.state.scene.particles;
        for (b, &id) in p.x.iter().zip(&p.id) {
            let a = x0[id as usize];
            assert!(
                (b - a - v * sim.state.time).norm() < 1e-9,
                "{shape:?}: drifted"
            );
        }
    });
}

/// A rigid spin by 0.2 rad must leave the block essentially unstressed. With an objective
/// (Jaumann) rate and D = 0 the exact answer is zero; a missing or wrong rotation term would
/// strain the material by O(θ) and put it at yield (σ ≈ σy). FLIP–MUSL is not exact at a
/// free surface (the node velocity there is ω × the particles' centroid, not ω × the node), so
/// the surface rings elastically: we measured 0.8–2.4 MPa for θ from 0.02 to 0.2 rad with
/// linear shapes and uGIMP, and 3.5 MPa at 0.2 rad with B-splines, whose stencil reaches a
/// node further past the surface. The bound is 5 % of σy, 8 % for B-splines: a missing rotation
/// term is ten times either.
#[test]
fn rigid_rotation_gives_no_stress() {
    each_shape!(|S, shape| {
        let mut scene = block([12, 12, 4], 0.5, pvc());
        let centre = Vector3::new(3.0 + 0.13, 3.0 + 0.29, 1.0 + 0.07);
        let omega = Vector3::new(0.0, 0.0, 0.5); // rad/ms
        let p = &mut scene.particles;
        for q in 0..p.len() {
            p.v[q] = omega.cross(&(p.x[q] - centre));
        }
        let start = p.x.clone();
        let mut sim = Simulation::<S>::new(scene);
        while sim.state.time * omega.z < 0.2 {
            sim.step(1.0).unwrap();
        }
        let p = &sim.state.scene.particles;
        let worst = p.stress.iter().map(von_mises).fold(0.0, f64::max);
        let bound = if shape == "bspline" { 0.08 } else { 0.05 };
        assert!(
            worst < bound * 65.5,
            "{shape:?}: von Mises {worst} MPa after a rigid spin"
        );
        // and the body did turn: a particle's angle about the centre advanced by 0.2 rad
        let (r0, r1) = (start[0] - centre, p.x[0] - centre);
        let turned = r1.y.atan2(r1.x) - r0.y.atan2(r0.x);
        assert!(turned > 0.15, "turned only {turned} rad");
    });
}

/// Free–free bar, ν = 0 so the bar speed is exactly √(E/ρ). Started in its first mode,
/// v = v0 cos(πx/L), its kinetic energy first vanishes at a quarter period T/4 = L/(2c). The
/// minimum is located by a parabola through the three samples around it; the leapfrog
/// velocities belong to the middle of their step, hence the −dt/2. Tolerance 1 %: lumped-mass
/// linear elements at 40 cells per half wavelength are off by (kΔx)²/24 ≈ 0.03 %, and the
/// particle quadrature adds a few tenths of a percent.
#[test]
fn elastic_wave_speed_in_a_bar() {
    each_shape!(|S, shape| {
        let (h, n) = (0.5, 80);
        let e = 3378.4;
        let mut scene = block([n, 2, 2], h, MaterialLaw::Elastic(Elastic::new(e, 0.0)));
        let len = n as f64 * h;
        let (x0, k) = (0.13, std::f64::consts::PI / len);
        for (v, x) in scene.particles.v.iter_mut().zip(&scene.particles.x) {
            v.x = 0.01 * (k * (x.x - x0)).cos();
        }
        let mut sim = Simulation::<S>::new(scene);
        let quarter = len / (2.0 * (e / RHO).sqrt());
        let mut samples: Vec<(f64, f64)> = vec![];
        let found = loop {
            let info = sim.step(1.0).unwrap();
            samples.push((sim.state.time - 0.5 * info.dt, info.kinetic));
            let m = samples.len();
            if m >= 3 && samples[m - 1].1 > samples[m - 2].1 {
                let ((t0, k0), (t1, k1), (t2, k2)) =
                    (samples[m - 3], samples[m - 2], samples[m - 1]);
                let num = (t1 - t0).powi(2) * (k1 - k2) - (t1 - t2).powi(2) * (k1 - k0);
                let den = (t1 - t0) * (k1 - k2) - (t1 - t2) * (k1 - k0);
                break t1 - 0.5 * num / den;
            }
            assert!(sim.state.time < 2.0 * quarter, "no minimum found");
        };
        let err = (found / quarter - 1.0).abs();
        assert!(err < 0.01, "{shape:?}: T/4 {found} vs {quarter} ({err:.4})");
    });
}

/// Momentum: particle→grid and grid→particle transfers conserve it and internal forces sum
/// to zero (Σ_i ∇N_i = 0), so without plates total momentum is constant to round-off
/// (1e-10 relative) even while the pre-stressed block rings and yields.
#[test]
fn momentum_is_conserved_without_plates() {
    each_shape!(|S, shape| {
        let mut scene = block([7, 5, 6], 0.5, pvc());
        let p = &mut scene.particles;
        for q in 0..p.len() {
            let s = (q as f64 * 0.7).sin();
            p.v[q] = Vector3::new(5.0 * s, 3.0 * (q as f64).cos(), -2.0 + s);
            p.stress[q] = [40.0 * s, -30.0, 10.0, 20.0 * s, 0.0, 5.0];
        }
        let before = p.momentum();
        let mut sim = Simulation::<S>::new(scene);
        for _ in 0..200 {
            sim.step(1.0).unwrap();
        }
        let after = sim.state.scene.particles.momentum();
        assert!(
            (after - before).norm() < 1e-10 * before.norm(),
            "{shape:?}: {before} → {after}"
        );
        assert!(
            sim.state
                .scene
                .particles
                .plastic_strain
                .iter()
                .any(|&e| e > 0.0),
            "test should reach yield"
        );
    });
}

/// A block squeezed between frictionless plates past three times its yield strain at 0.2 m/s:
/// the load over each 500 steps once past twice the yield strain, over σy times the current
/// area (total volume over plate gap). No particle may ever lie outside the yield surface.
/// Returns those ratios. `h` is the particle spacing (cell 2h); the block is 6 × 6 × 12 mm
/// times h/0.5.
fn squeeze<S: Stencil>(h: f64) -> Vec<f64> {
    let k = (0.5 / h).round() as usize;
    let mut scene = block([6 * k, 6 * k, 12 * k], h, pvc());
    let top = 12.0 * k as f64 * h + 0.07;
    scene.plates = vec![
        Plate {
            z: top,
            side: 1.0,
            velocity: -0.2,
            full_velocity: -0.2,
        },
        Plate {
            z: 0.07,
            side: -1.0,
            velocity: 0.0,
            full_velocity: 0.0,
        },
    ];
    let mut sim = Simulation::<S>::new(scene);
    let yield_strain = 65.5 / 3378.4;
    let (mut impulse, mut span) = (0.0, 0.0);
    let mut ratios = vec![];
    while sim.state.time * 0.2 < 3.0 * yield_strain * top {
        let info = sim.step(1.0).unwrap();
        impulse += info.contact.impulse[0];
        span += info.dt;
        if sim.state.steps.is_multiple_of(500 * k as u64) {
            let p = &sim.state.scene.particles;
            assert!(p.stress.iter().all(|s| von_mises(s) <= 65.5 * (1.0 + 1e-9)));
            let height = sim.state.scene.plates[0].z - sim.state.scene.plates[1].z;
            let area = p.vol.iter().sum::<f64>() / height;
            if sim.state.time * 0.2 > 2.0 * yield_strain * top {
                ratios.push(impulse / span / area / 65.5);
            }
            impulse = 0.0;
            span = 0.0;
        }
    }
    assert!(ratios.len() >= 3);
    ratios
}

/// A block (3 × 3 × 6 mm, two particles a cell) squeezed between frictionless plates is in
/// uniaxial stress once it yields: the load must settle at σy times the current area, within
/// 5 % (1 % for the stress wave ρcv ≈ 0.7 MPa at 0.2 m/s, 4 % for the area, estimated as total
/// volume over plate gap). Measured: uGIMP 0.96–1.02, B-splines 1.00–1.02. Linear shapes carry
/// less: a particle touching a plate gives mass to the node plane a cell inside the block as
/// well, so the plate holds a cell of the block at each end. Measured 0.90–0.92 here and
/// 0.93–0.94 at half the spacing
/// (with the remap's catch kept from the particles' velocities, a projection for the strain
/// only: 0.95–0.97 and 0.94); so for them 0.88–1.05, and the shortfall must shrink with the
/// spacing.
#[test]
fn uniaxial_compression_yields_at_sigma_y_and_stays_there() {
    each_shape!(|S, shape| {
        let low = if shape == "linear" { 0.88 } else { 0.95 };
        for r in squeeze::<S>(0.5) {
            assert!((low..1.05).contains(&r), "{shape:?}: load / (σy A) = {r}");
        }
    });
    let mean = |r: Vec<f64>| r.iter().sum::<f64>() / r.len() as f64;
    let (coarse, fine) = (mean(squeeze::<Linear>(0.5)), mean(squeeze::<Linear>(0.25)));
    assert!(
        coarse < fine && fine < 1.05,
        "linear: load / (σy A) {coarse} at h 0.5 mm, {fine} at 0.25 mm"
    );
}

/// A block resting on the bottom plate with the top plate two cells above it, coming down:
/// the nodes above the block are nearer the top plate, but only particles touching the bottom
/// plate reach them. What broke: the law was applied with the plate nearest the node, so the
/// top plate dragged those nodes down at its own speed before it touched anything.
#[test]
fn a_node_obeys_the_plate_its_particles_touch_not_the_nearest() {
    let h = 0.5;
    let mut scene = block([8, 8, 1], h, pvc());
    // The layer's centres at z = 0.25 (edges 0..0.5) resting on the bottom plate at z = 0; the
    // top plate at 1.9 (cell 1.0): the node plane z = 1 is 0.9 from it and 1.0 from the bottom.
    for x in &mut scene.particles.x {
        x.z = 0.25;
    }
    scene.plates = vec![
        Plate {
            z: 1.9,
            side: 1.0,
            velocity: -1.0,
            full_velocity: -1.0,
        },
        Plate {
            z: 0.0,
            side: -1.0,
            velocity: 0.0,
            full_velocity: 0.0,
        },
    ];
    let mut sim = Simulation::<Gimp>::new(scene);
    let info = sim.step(1.0).unwrap();
    assert_eq!(info.contact.impulse[0], 0.0, "{:?}", info.contact);
    assert_eq!(info.contact.work, [0.0, 0.0]);
    let fastest = sim
        .state
        .scene
        .particles
        .v
        .iter()
        .map(|v| v.norm())
        .fold(0.0, f64::max);
    assert!(
        fastest < 1e-12,
        "a particle at rest moved at {fastest} mm/ms"
    );
}

/// Total mass of a scene's particles, g.
fn mass(scene: &Scene) -> f64 {
    scene.particles.mass.iter().sum()
}

/// A plate meets a block at rest: in the first step's grid update it catches the nodes its
/// touching particles reach, a perfectly inelastic collision of that mass m_c at the plate
/// speed V. Closed form: normal impulse J = m_c·V, plate work J·V = m_c·V², kinetic energy of
/// the caught nodes ½·m_c·V², so the catch dissipates ½·m_c·V² = ½·J·V, half the work. (No
/// internal force acts in the first step: the block is unstressed.) Round-off only: 1e-12.
/// The remap then finds the caught nodes short of the plate (FLIP gave their particles
/// between 0 and V: they weigh uncaught nodes too) and catches them again from their remapped
/// velocity b: a loss of ½·m·(V − b)² for work m·(V − b)·V, more than nothing and at most half
/// of it. The step's books are the two catches'.
#[test]
fn a_plate_catching_a_block_books_half_its_work_as_the_inelastic_loss() {
    each_shape!(|S, shape| {
        let (h, speed) = (0.5, 2.0);
        let scene = || {
            let mut scene = block([6, 6, 4], h, pvc());
            scene.plates = vec![Plate {
                z: 4.0 * h + 0.07,
                side: 1.0,
                velocity: -speed,
                full_velocity: -speed,
            }];
            scene
        };
        let mut sim = Simulation::<S>::new(scene());
        let lp = sim.state.scene.half_size / sim.state.scene.cell;
        let dt = sim.state.stable_dt();
        let mut clock = Clock::start();
        sim.bin(lp);
        sim.scatter::<Full>(lp, &mut clock);
        let c = sim.grid_update(dt);
        let j = c.impulse[0];
        assert!(j > 0.0);
        assert!(
            (c.work[0] - j * speed).abs() < 1e-12 * c.work[0],
            "{shape:?}: {c:?}"
        );
        assert!(
            (c.catch - 0.5 * j * speed).abs() < 1e-12 * c.catch,
            "{shape:?}: {c:?}"
        );
        // The caught mass J/V is the top layer's share of the nodal mass: less than the block.
        assert!(j / speed < mass(&sim.state.scene), "{shape:?}");
        sim.g2p_velocity(lp);
        sim.scatter::<Remap>(lp, &mut clock);
        let r = sim.remap();
        assert!(r.impulse[0] > 0.0 && r.impulse[0] < j, "{shape:?}: {r:?}");
        assert!(
            (r.work[0] - r.impulse[0] * speed).abs() < 1e-12 * r.work[0],
            "{shape:?}: {r:?}"
        );
        assert!(
            r.catch > 0.0 && r.catch <= 0.5 * r.work[0] * (1.0 + 1e-12),
            "{shape:?}: {r:?}"
        );
        // The same first step through `step`: its books are the two catches'.
        let mut stepped = Simulation::<S>::new(scene());
        let both = stepped.step(1.0).unwrap().contact;
        let mut sum = c;
        sum.add(&r);
        assert_eq!(both, sum, "{shape:?}");
        assert_eq!(
            (stepped.state.energy.work[0], stepped.state.energy.catch),
            (both.work[0], both.catch)
        );
    });
}

/// A block sliding at u along a fixed plate while it is pressed on it (it arrives with a small
/// normal velocity w and bounces back): Coulomb friction takes μ·N of tangential force, so over
/// the contact the friction work is μ·∫N·u dt = μ·J_n·ū (J_n the total normal impulse, ū the
/// block's mean sliding speed, which falls by μ·J_n/M). Measured 0.16 % off, against 1 % allowed:
/// the slip of the contact nodes is the block's u up to the elastic shear of the contact layer.
/// The tangential momentum lost is μ·J_n while every contact node slides (u ≫ μ·w); a few light
/// nodes, whose normal velocity jump is large, stick: measured 7e-5 below, 1e-3 allowed. The
/// books close: the block's kinetic energy went to kinetic, internal, catch and friction energy
/// (measured 0.05 % off, 0.5 % allowed).
#[test]
fn a_block_sliding_under_friction_does_mu_n_s_of_friction_work() {
    let (h, mu, u, w) = (0.5, 0.2, 5.0, 0.5);
    let mut scene = block(
        [6, 6, 4],
        h,
        MaterialLaw::Elastic(Elastic::new(3378.4, 0.42)),
    );
    scene
        .particles
        .v
        .iter_mut()
        .for_each(|v| *v = Vector3::new(u, 0.0, -w));
    scene.friction = mu;
    // The plate just under the block's lowest particle edge (centres from 0.07 + 0.25).
    scene.plates = vec![Plate {
        z: 0.07 - 0.01,
        side: -1.0,
        velocity: 0.0,
        full_velocity: 0.0,
    }];
    let m = mass(&scene);
    let kinetic0 = 0.5 * m * (u * u + w * w);
    let p0 = scene.particles.momentum();
    let mut sim = Simulation::<Gimp>::new(scene);
    let (mut jn, mut kinetic) = (0.0, 0.0);
    // 0.3 ms: the block (6 particles high, c ≈ 2.5 mm/ms) rings a few times against the plate.
    while sim.state.time < 0.3 {
        let info = sim.step(1.0).unwrap();
        jn += info.contact.impulse[0];
        kinetic = info.kinetic;
    }
    let p1 = sim.state.scene.particles.momentum();
    assert!(jn > 0.0);
    let lost = p0.x - p1.x;
    assert!(
        (lost / (mu * jn) - 1.0).abs() < 1e-3,
        "{lost} vs μ·J_n = {}",
        mu * jn
    );
    let mean_u = 0.5 * (p0.x + p1.x) / m;
    let friction = sim.state.energy.friction;
    let expect = mu * jn * mean_u;
    assert!(
        (friction / expect - 1.0).abs() < 0.01,
        "friction {friction} vs μ·J_n·ū {expect}"
    );
    let e = sim.state.energy;
    let booked = kinetic + e.internal + e.catch + e.friction;
    assert!(
        (booked / kinetic0 - 1.0).abs() < 0.005,
        "{kinetic0} mJ became {booked} (kinetic {kinetic}, internal {}, catch {}, friction {})",
        e.internal,
        e.catch,
        e.friction
    );
}

/// Between a fixed and a moving plate (μ 0.3) a block whose particles move every which way is
/// squeezed for 300 steps: the plates' impulses, of both the grid update and the remap (whose
/// catch goes to the particles near the plates too), are all the momentum the particles gain
/// along z (Σ_i ∇N_i = 0: the internal forces add no momentum; Σ_p m_p·N_ip = m_i: what a
/// node's change gives its particles is m_i times it). Round-off only: 1e-10 of the impulse. A
/// remap that booked a catch and did not give it to every particle its node reaches (or gave
/// it and did not book it) would miss by the remap's share of the impulse.
#[test]
fn the_plates_impulse_is_the_momentum_the_particles_gain() {
    each_shape!(|S, shape| {
        let h = 0.5;
        let mut scene = block([6, 6, 8], h, pvc());
        let p = &mut scene.particles;
        for q in 0..p.len() {
            let s = (q as f64 * 0.7).sin();
            p.v[q] = Vector3::new(3.0 * s, 2.0 * (q as f64).cos(), -1.0 + s);
        }
        scene.friction = 0.3;
        // The block's particle edges span z from 0.07 to 4.07 mm.
        scene.plates = vec![
            Plate {
                z: 8.0 * h + 0.07 + 0.01,
                side: 1.0,
                velocity: -2.0,
                full_velocity: -2.0,
            },
            Plate {
                z: 0.07 - 0.01,
                side: -1.0,
                velocity: 0.0,
                full_velocity: 0.0,
            },
        ];
        let before = scene.particles.momentum();
        let mut sim = Simulation::<S>::new(scene);
        let mut impulse = [0.0; 2];
        for _ in 0..300 {
            let c = sim.step(1.0).unwrap().contact;
            impulse[0] += c.impulse[0];
            impulse[1] += c.impulse[1];
        }
        let gained = sim.state.scene.particles.momentum().z - before.z;
        let given = impulse[1] - impulse[0];
        assert!(
            impulse[0] > 0.0 && impulse[1] > 0.0,
            "{shape:?}: {impulse:?}"
        );
        assert!(
            (gained - given).abs() < 1e-10 * (impulse[0] + impulse[1]),
            "{shape:?}: the particles gained {gained}, the plates gave {given} ({impulse:?})"
        );
    });
}

/// A block of `law` strikes a fixed plate at 40 m/s and rings against it for 0.02 ms. Returns
/// its kinetic energy at the start and what the books hold at the end (kinetic, internal,
/// catch, friction), mJ, and the plastic work.
fn strike(law: MaterialLaw) -> (f64, f64, f64) {
    let (h, v) = (0.5, 40.0);
    let mut scene = block([6, 6, 6], h, law);
    scene
        .particles
        .v
        .iter_mut()
        .for_each(|u| *u = Vector3::new(0.0, 0.0, -v));
    scene.plates = vec![Plate {
        z: 0.07 - 0.01,
        side: -1.0,
        velocity: 0.0,
        full_velocity: 0.0,
    }];
    let kinetic0 = 0.5 * mass(&scene) * v * v;
    let mut sim = Simulation::<Gimp>::new(scene);
    let mut kinetic = kinetic0;
    while sim.state.time < 0.02 {
        kinetic = sim.step(1.0).unwrap().kinetic;
    }
    let e = sim.state.energy;
    (
        kinetic0,
        kinetic + e.internal + e.catch + e.friction,
        e.plastic,
    )
}

/// A block of a hardening, rate-sensitive metal (Swift σy 100 MPa, K 300 MPa, n 0.2, with and
/// without Cowper–Symonds D 6500 /s, q 4) strikes a fixed plate at 40 m/s, well past its yield
/// velocity σy/(ρc) ≈ 9 m/s: its kinetic energy goes to kinetic, internal (elastic + the
/// hardened, rate-scaled plastic work the law books), catch and friction energy. What is left
/// is the engine's, not the law's: the same strike of an elastic block (no plastic work at all)
/// leaves more. Measured: elastic +2.2 %, Swift −0.83 %, Swift with Cowper–Symonds +0.33 %
/// (with the remap's catch kept from the particles: +3.1, +0.34 and +1.1 %); 1.5 % allowed,
/// and no more than the elastic block's.
#[test]
fn a_hardening_metal_block_striking_a_plate_closes_its_books() {
    use crush::solver::model::material::flow::{Hardening, Rate};
    use crush::solver::model::material::Metal;
    let swift = Hardening::swift(100.0, 300.0, 0.2);
    let (k0, elastic, _) = strike(MaterialLaw::Elastic(Elastic::new(70_000.0, 0.3)));
    let engine = (elastic / k0 - 1.0).abs();
    for rate in [Rate::None, Rate::cowper_symonds(6500.0, 4.0)] {
        let (k0, booked, plastic) =
            strike(MaterialLaw::Metal(Metal::new(70_000.0, 0.3, swift, rate)));
        assert!(plastic > 0.2 * k0, "{rate:?}: plastic {plastic} of {k0}");
        let error = (booked / k0 - 1.0).abs();
        assert!(
            error < 0.015 && error <= engine,
            "{rate:?}: {k0} mJ became {booked} ({error}; elastic block {engine})"
        );
    }
}
