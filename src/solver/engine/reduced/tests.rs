//! The hoop and plane-strain terms one at a time, on the paper's tube section.

use super::*;
use crate::solver::engine::grid::{Full, Remap};
use crate::solver::engine::shape::{Gimp, Linear};
use crate::solver::model::case::{Case, Limits};
use crate::solver::model::material::{Law, MaterialLaw, Point};
use grid::PlaneStencil;
use nalgebra::Vector3;

fn reduced<S: Stencil>(model: &str) -> Reduced<S> {
    let mode = if model == "axisymmetric" {
        "axial"
    } else {
        "lateral"
    };
    let text = format!(
        r#"{{"discretization": {{"particles_through_thickness": 3, "model": "{model}"}},
            "loading": {{"mode": "{mode}"}}}}"#
    );
    let case = Case::from_json(&text, &Limits::default()).unwrap();
    let mut scene = Scene::from_case(&case);
    // Plates far away: these checks are about the section's own terms.
    scene.plates[0].z += 100.0;
    scene.plates[1].z -= 100.0;
    let sym = Symmetry::of(case.spec().discretization.model).unwrap();
    Reduced::new(scene, sym)
}

/// The step's transfers with a step of zero: the particles' velocities onto the grid and back
/// as velocity gradients (in the scratch), nothing moved, no stress changed.
fn kinematics_at_rest<S: Stencil>(sim: &mut Reduced<S>) {
    let lp = sim.state.scene.half_size / sim.state.scene.cell;
    sim.grid.fit(&sim.state.scene.particles.x, lp);
    sim.scatter_particles::<Full>(lp);
    sim.update_nodes(0.0);
    sim.scatter_particles::<Remap>(lp);
    sim.remap_nodes();
    sim.gather_kinematics(lp, 0.0);
}

/// The velocity field v = (v_r, 0, 0) everywhere: the nodes carry it exactly (a partition of
/// unity of equal velocities), so every particle's hoop rate is v_r / r, and every in-plane
/// gradient is zero (Σ ∇N = 0).
fn check_hoop_rate<S: Stencil>() {
    let vr = 2.5;
    let mut sim = reduced::<S>("axisymmetric");
    for v in &mut sim.state.scene.particles.v {
        *v = Vector3::new(vr, 0.0, 0.0);
    }
    let before = sim.state.scene.particles.x.clone();
    kinematics_at_rest(&mut sim);
    for (l, x) in sim.scratch.gradient.iter().zip(&before) {
        let want = vr / x.x;
        assert!(
            (l[(1, 1)] / want - 1.0).abs() < 1e-12,
            "{} vs {want}",
            l[(1, 1)]
        );
        for (a, b) in [(0, 0), (0, 2), (2, 0), (2, 2)] {
            assert!(l[(a, b)].abs() < 1e-9 * want, "L{a}{b} = {}", l[(a, b)]);
        }
    }
}

#[test]
fn a_uniform_radial_velocity_gives_the_hoop_rate_v_over_r() {
    check_hoop_rate::<Linear>();
    check_hoop_rate::<Gimp>();
}

/// A uniform hoop stress σ and nothing else: each particle pushes its nodes inward by
/// V·σ·N / r (a ring in tension pulls towards the axis), so the nodes' radial forces add up to
/// −Σ V σ / r and their axial forces to zero.
fn check_hoop_force<S: Stencil>(model: &str, hoop: Real) {
    let sigma = 40.0;
    let mut sim = reduced::<S>(model);
    for s in &mut sim.state.scene.particles.stress {
        *s = [0.0, sigma, 0.0, 0.0, 0.0, 0.0];
    }
    let lp = sim.state.scene.half_size / sim.state.scene.cell;
    sim.grid.fit(&sim.state.scene.particles.x, lp);
    sim.scatter_particles::<Full>(lp);
    let p = &sim.state.scene.particles;
    let want: Real = (0..p.len())
        .map(|q| -hoop * p.vol[q] * sigma / p.x[q].x)
        .sum();
    let total = sim
        .grid
        .force
        .iter()
        .fold([0.0; 2], |a, f| [a[0] + f[0], a[1] + f[1]]);
    let scale = p.vol.iter().sum::<Real>() * sigma;
    assert!(
        (total[0] - want).abs() < 1e-12 * scale,
        "{} vs {want}",
        total[0]
    );
    assert!(total[1].abs() < 1e-12 * scale, "axial {}", total[1]);
    if hoop > 0.0 {
        assert!(want < 0.0);
        // Node by node: −Σ V σ N / r over the particles that reach it.
        let n = sim.grid.force.len() / 2;
        let node = (0..sim.grid.force.len()).find(|&i| sim.grid.mass[i] > 0.0 && i >= n);
        let node = node.unwrap();
        let mut expect = 0.0;
        for q in 0..p.len() {
            let PlaneStencil { start: o, w, .. } = sim.grid.stencil(&p.x[q], lp);
            for i in 0..S::N {
                for k in 0..S::N {
                    if sim.grid.index(o[0] + i, o[1] + k) == node {
                        expect -= p.vol[q] * sigma * w[0][i] * w[1][k] / p.x[q].x;
                    }
                }
            }
        }
        let got = sim.grid.force[node][0];
        assert!(
            (got - expect).abs() < 1e-9 * expect.abs().max(1e-12),
            "{got} vs {expect}"
        );
    }
}

#[test]
fn a_uniform_hoop_stress_pulls_the_nodes_inward_by_v_sigma_over_r() {
    check_hoop_force::<Linear>("axisymmetric", 1.0);
    check_hoop_force::<Gimp>("axisymmetric", 1.0);
}

/// In plane strain σ_yy is the stress along the tube: it acts on no node of the section.
#[test]
fn plane_strain_stress_along_the_tube_exerts_no_force() {
    check_hoop_force::<Linear>("plane_strain", 0.0);
    check_hoop_force::<Gimp>("plane_strain", 0.0);
}

/// Plane strain: a uniform in-plane dilation rate gives no strain rate along the tube, and the
/// stress update then builds σ_yy = λ·(ε_xx + ε_zz) (no strain along y, the plane-strain law).
#[test]
fn plane_strain_keeps_the_axial_strain_rate_zero() {
    let mut sim = reduced::<Linear>("plane_strain");
    let rate = 1e-3;
    for (v, x) in sim
        .state
        .scene
        .particles
        .v
        .iter_mut()
        .zip(&sim.state.scene.particles.x)
    {
        *v = Vector3::new(rate * x.x, 0.0, rate * x.z);
    }
    kinematics_at_rest(&mut sim);
    let mut dilating = 0;
    for l in &sim.scratch.gradient {
        assert_eq!(l[(1, 1)], 0.0);
        assert_eq!([l[(0, 1)], l[(1, 0)], l[(1, 2)], l[(2, 1)]], [0.0; 4]);
        dilating += usize::from(l.trace() > 0.5 * rate);
    }
    // The in-plane field reaches the particles (all but the edge ones see 2·rate).
    assert!(dilating > sim.state.scene.particles.len() / 2, "{dilating}");
    let MaterialLaw::J2(m) = sim.state.scene.material else {
        panic!("the paper's wall is J2")
    };
    let mut s = [0.0; 6];
    let l = Matrix3::new(rate, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, rate);
    m.update(&mut s, &l, 1.0, Point::FRESH);
    assert!((s[1] - m.lambda * 2.0 * rate).abs() < 1e-12 * m.lambda);
}

/// A plane-strain particle exactly on x = 0 (the middle of a rectangular tube's face, where the
/// lattice puts one when a layer holds 4k + 2 particles) once made its hoop terms 0 · (0 / 0):
/// NaN forces on its nodes and a run that stopped unstable at its first step.
#[test]
fn a_plane_strain_particle_on_x_0_has_finite_forces_and_gradients() {
    let case = Case::from_json(
        r#"{"tube": {"section": "rectangular", "thickness_mm": 1.5, "side_a_mm": 40,
                     "corner_radius_mm": 3, "length_mm": 80},
            "loading": {"mode": "lateral", "crush_distance_mm": 20},
            "discretization": {"model": "plane_strain", "particles_through_thickness": 4}}"#,
        &Limits::default(),
    )
    .unwrap();
    let mut scene = Scene::from_case(&case);
    assert!(
        scene.particles.x.iter().any(|x| x.x == 0.0),
        "the lattice has a particle on x = 0"
    );
    for s in &mut scene.particles.stress {
        s[1] = 10.0;
    }
    for v in &mut scene.particles.v {
        v.x = 1e-3;
    }
    let mut sim = Reduced::<Gimp>::new(scene, Symmetry::PlaneStrain);
    kinematics_at_rest(&mut sim);
    assert!(sim.grid.force.iter().flatten().all(|f| f.is_finite()));
    assert!(sim
        .scratch
        .gradient
        .iter()
        .all(|l| l.iter().all(|v| v.is_finite())));
}
