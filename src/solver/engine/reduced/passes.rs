//! The passes of a reduced model's step (units: mm, ms, g, N, MPa, mJ): the scatters, the two
//! node passes with the plates, the two gathers and the stress update. Particle passes that
//! write only their own particle run in parallel; the scatters run in bands of particles, each
//! into a patch of its own, added onto the grid in a fixed order (so the bits do not depend on
//! the thread count); the node passes, over a few thousand nodes, run on one thread.

use super::grid::PlaneStencil;
use super::patch::Patch;
use super::Reduced;
use crate::solver::engine::grid::Transfer;
use crate::solver::engine::kernel::SolveError;
use crate::solver::engine::shape::Stencil;
use crate::solver::engine::stress::{close_books, update_particles, Books, Deformation};
use crate::solver::model::contact::{self, ContactSums, CONTACT_TOLERANCE};
use crate::solver::Real;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

/// Particles per parallel work item.
const CHUNK: usize = 512;

/// Particles per scatter run (see [`Reduced::scatter`]).
const SCATTER_CHUNK: usize = 256;

impl<S: Stencil> Reduced<S> {
    /// Particle → grid. `Full`: mass, momentum, internal force (with the hoop term) and plate
    /// touch, and each particle's cell; `Remap`: momentum only, onto the masses of the full one.
    ///
    /// Each run of [`SCATTER_CHUNK`] particles scatters in parallel into a patch of its own,
    /// over the nodes its stencils reach (the particles keep their lattice order, so a run is a
    /// band of the wall); the patches are then added onto the grid in run order. The number of
    /// runs depends on the particle count alone, so the sums, and their bits, do not depend on
    /// the thread count.
    pub(super) fn scatter_particles<T: Transfer>(&mut self, lp: Real) {
        let g = &self.grid;
        let p = &self.state.scene.particles;
        let (plates, half) = (&self.state.scene.plates, self.state.scene.half_size);
        let tolerance = CONTACT_TOLERANCE * half;
        let symmetry = self.symmetry;
        let inv = g.inv_cell;
        let s = &mut self.scratch;
        s.patches
            .resize_with(p.len().div_ceil(SCATTER_CHUNK), Patch::default);
        (
            s.patches.par_iter_mut(),
            s.cell_of.par_chunks_mut(SCATTER_CHUNK),
        )
            .into_par_iter()
            .enumerate()
            .for_each(|(c, (patch, cells))| {
                let run = c * SCATTER_CHUNK..(c * SCATTER_CHUNK + cells.len());
                patch.fit(g, &p.x[run.clone()], lp);
                for (j, q) in run.enumerate() {
                    let x = &p.x[q];
                    let PlaneStencil { start: o, w, g: d } = g.stencil(x, lp);
                    let o = [o[0] - patch.origin[0], o[1] - patch.origin[1]];
                    let (m, v) = (p.mass[q], p.v[q]);
                    if !T::FULL {
                        for i in 0..S::N {
                            for k in 0..S::N {
                                let at = patch.index(o[0] + i, o[1] + k);
                                let n = &mut patch.nodes[at];
                                let wm = w[0][i] * w[1][k] * m;
                                n[1] += wm * v.x;
                                n[2] += wm * v.z;
                            }
                        }
                        continue;
                    }
                    let (cx, cz) = (
                        (x.x * inv).floor() as i32 - g.origin[0],
                        (x.z * inv).floor() as i32 - g.origin[1],
                    );
                    cells[j] = g.index(cx as usize, cz as usize) as u32;
                    let touch = m * contact::touching(plates, x.z, half, tolerance);
                    let st = &p.stress[q];
                    let vol = p.vol[q];
                    // f_x = −V(σxx ∂x + σxz ∂z + hoop·σyy·N/r), f_z = −V(σxz ∂x + σzz ∂z).
                    let hoop_stress = symmetry.hoop_term(st[1], x.x);
                    for i in 0..S::N {
                        for k in 0..S::N {
                            let at = patch.index(o[0] + i, o[1] + k);
                            let n = &mut patch.nodes[at];
                            let wn = w[0][i] * w[1][k];
                            let (dx, dz) = (d[0][i] * w[1][k] * inv, w[0][i] * d[1][k] * inv);
                            n[0] += wn * m;
                            n[1] += wn * m * v.x;
                            n[2] += wn * m * v.z;
                            n[3] -= vol * (st[0] * dx + st[4] * dz + hoop_stress * wn);
                            n[4] -= vol * (st[4] * dx + st[2] * dz);
                            n[5] += wn * touch;
                        }
                    }
                }
            });
        let g = &mut self.grid;
        if !T::FULL {
            g.momentum.fill([0.0; 2]);
        }
        for patch in &s.patches {
            for i in 0..patch.dims[0] {
                let row = g.index(patch.origin[0] + i, patch.origin[1]);
                let nodes = &patch.nodes[i * patch.dims[1]..(i + 1) * patch.dims[1]];
                for (k, n) in nodes.iter().enumerate() {
                    let at = row + k;
                    g.momentum[at][0] += n[1];
                    g.momentum[at][1] += n[2];
                    if T::FULL {
                        g.mass[at] += n[0];
                        g.force[at][0] += n[3];
                        g.force[at][1] += n[4];
                        g.touch[at] += n[5];
                    }
                }
            }
        }
    }

    /// Nodes after the full scatter: momentum → velocity, add force·dt, apply the plates
    /// (booked). Returns the contact sums.
    pub(super) fn update_nodes(&mut self, dt: Real) -> ContactSums {
        let (plates, mu) = (&self.state.scene.plates, self.state.scene.friction);
        let g = &mut self.grid;
        let mut sums = ContactSums::default();
        for n in 0..g.len() {
            let m = g.mass[n];
            if m <= self.state.mass_floor {
                g.velocity[n] = [0.0; 2];
                g.change[n] = [0.0; 2];
                g.slip[n] = 0.0;
                continue;
            }
            let (p, f) = (g.momentum[n], g.force[n]);
            let old = Vector3::new(p[0] / m, 0.0, p[1] / m);
            let mut v = old + Vector3::new(f[0], 0.0, f[1]) * (dt / m);
            g.slip[n] = match contact::plate_of(plates, g.touch[n]) {
                Some(k) => {
                    contact::apply_slip_deferred(k, &plates[k], mu, m, &old, &mut v, &mut sums)[0]
                }
                None => 0.0,
            };
            g.velocity[n] = [v.x, v.z];
            g.change[n] = [v.x - old.x, v.z - old.z];
        }
        sums
    }

    /// Nodes after the remap scatter: velocity with the plates applied again, the plates'
    /// change of it left in `change` for the particles, and booked (see the 3D
    /// `Simulation::remap_nodes`). Returns the contact sums of the catch.
    pub(super) fn remap_nodes(&mut self) -> ContactSums {
        let (plates, mu) = (&self.state.scene.plates, self.state.scene.friction);
        let g = &mut self.grid;
        let mut sums = ContactSums::default();
        for n in 0..g.len() {
            let m = g.mass[n];
            if m <= self.state.mass_floor {
                g.velocity[n] = [0.0; 2];
                g.change[n] = [0.0; 2];
                continue;
            }
            let p = g.momentum[n];
            let before = Vector3::new(p[0] / m, 0.0, p[1] / m);
            if g.slip[n] != 0.0 {
                contact::book_slip_end([g.slip[n], 0.0], &before, &mut sums);
            }
            let mut v = before;
            if let Some(k) = contact::plate_of(plates, g.touch[n]) {
                contact::apply(k, &plates[k], mu, m, &before, &mut v, &mut sums);
            }
            g.velocity[n] = [v.x, v.z];
            g.change[n] = [v.x - before.x, v.z - before.z];
        }
        sums
    }

    /// Grid → particle velocity: add the interpolated velocity change of the nodes to the
    /// particles for which `near(z)` holds, z their height (mm): FLIP after the grid update
    /// (every particle), the plates' catch after the remap (those that can reach a contact
    /// node).
    pub(super) fn gather_change(&mut self, lp: Real, near: impl Fn(Real) -> bool + Sync) {
        let g = &self.grid;
        let p = &mut self.state.scene.particles;
        let x = &p.x;
        p.v.par_chunks_mut(CHUNK).enumerate().for_each(|(c, vs)| {
            for (j, v) in vs.iter_mut().enumerate() {
                let x = &x[c * CHUNK + j];
                if !near(x.z) {
                    continue;
                }
                let PlaneStencil { start: o, w, .. } = g.stencil(x, lp);
                for i in 0..S::N {
                    for k in 0..S::N {
                        let dv = g.change[g.index(o[0] + i, o[1] + k)];
                        let wn = w[0][i] * w[1][k];
                        v.x += wn * dv[0];
                        v.z += wn * dv[1];
                    }
                }
            }
        });
    }

    /// Grid → particle kinematics from the remapped velocities: the velocity gradient in the
    /// 3D layout (with the hoop rate v_r / r), and the position.
    pub(super) fn gather_kinematics(&mut self, lp: Real, dt: Real) {
        let g = &self.grid;
        let symmetry = self.symmetry;
        let inv = g.inv_cell;
        let xs = &mut self.state.scene.particles.x;
        let grads = &mut self.scratch.gradient;
        (xs.par_chunks_mut(CHUNK), grads.par_chunks_mut(CHUNK))
            .into_par_iter()
            .for_each(|(xs, ls)| {
                for (x, l) in xs.iter_mut().zip(ls.iter_mut()) {
                    let PlaneStencil { start: o, w, g: d } = g.stencil(x, lp);
                    let (mut vel, mut grad) = ([0.0; 2], [[0.0; 2]; 2]);
                    for i in 0..S::N {
                        for k in 0..S::N {
                            let vn = g.velocity[g.index(o[0] + i, o[1] + k)];
                            let wn = w[0][i] * w[1][k];
                            let (dx, dz) = (d[0][i] * w[1][k] * inv, w[0][i] * d[1][k] * inv);
                            for a in 0..2 {
                                vel[a] += wn * vn[a];
                                grad[a][0] += vn[a] * dx;
                                grad[a][1] += vn[a] * dz;
                            }
                        }
                    }
                    *l = Matrix3::new(
                        grad[0][0],
                        0.0,
                        grad[0][1],
                        0.0,
                        symmetry.hoop_term(vel[0], x.x),
                        0.0,
                        grad[1][0],
                        0.0,
                        grad[1][1],
                    );
                    x.x += vel[0] * dt;
                    x.z += vel[1] * dt;
                }
            });
    }

    /// Stress, volume and energy update, with the cell-averaged dilation rate and pressure when
    /// the scene asks for them; the next step's signal speed; the check for a particle gone
    /// bad. Returns the kinetic energy, mJ.
    pub(super) fn stress_update(&mut self, dt: Real) -> Result<Real, SolveError> {
        let cells = self.grid.len();
        let books = Books::of(&self.state.scene, dt);
        let material = self.state.scene.material;
        let p = &mut self.state.scene.particles;
        let s = &mut self.scratch;
        if let Some(avg) = &mut s.averages {
            avg.clear();
            avg.resize(cells, [0.0; 3]);
            for q in 0..p.len() {
                let (c, st, vol) = (s.cell_of[q] as usize, &p.stress[q], p.vol[q]);
                avg[c][0] += vol;
                avg[c][1] += vol * s.gradient[q].trace();
                avg[c][2] += vol * (st[0] + st[1] + st[2]) / 3.0;
            }
            for a in avg.iter_mut().filter(|a| a[0] > 0.0) {
                a[1] /= a[0];
                a[2] /= a[0];
            }
        }
        let plane = Plane {
            grads: &s.gradient,
            cell_of: &s.cell_of,
            averages: s.averages.as_deref(),
        };
        update_particles(p, (&material, &books), (CHUNK, &mut s.chunk_sums), &plane);
        let (xs, ids) = (&p.x, &p.id);
        let (kinetic, signal) = close_books(
            &s.chunk_sums,
            &mut self.state.energy,
            (self.state.steps + 1, self.state.time + dt),
            |q| {
                let x = xs[q];
                format!(
                    "particle {} at ({:.4}, {:.4}, {:.4}) mm of the section",
                    ids[q], x.x, x.y, x.z
                )
            },
        )?;
        self.state.signal = signal;
        Ok(kinetic)
    }
}

/// A reduced model's [`Deformation`]: gradients in the 3D layout, averages per grid cell.
struct Plane<'a> {
    grads: &'a [Matrix3<Real>],
    cell_of: &'a [u32],
    averages: Option<&'a [[Real; 3]]>,
}

impl Deformation for Plane<'_> {
    #[inline(always)]
    fn gradient(&self, q: usize) -> (Matrix3<Real>, Option<(Real, Real)>) {
        let cell = self.averages.map(|a| a[self.cell_of[q] as usize]);
        (
            self.grads[q],
            cell.map(|[_, dilation, pressure]| (dilation, pressure)),
        )
    }
    /// det(I + L·dt) of the section's gradient [[a, 0, b], [0, c, 0], [d, 0, e]]: the hoop
    /// factor times the in-plane determinant.
    #[inline(always)]
    fn volume_factor(&self, l: &Matrix3<Real>, dt: Real) -> Real {
        let (a, e) = (1.0 + l[(0, 0)] * dt, 1.0 + l[(2, 2)] * dt);
        let hoop = 1.0 + l[(1, 1)] * dt;
        hoop * (a * e - l[(0, 2)] * l[(2, 0)] * dt * dt)
    }
}
