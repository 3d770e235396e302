//! One explicit MUSL step, a function per phase:
//! bin → p2g (mass, momentum, force) → reduce → grid update with plate contact → broadcast →
//! g2p (velocity) → p2g (momentum again: MUSL remap) → reduce → remap with contact → broadcast →
//! g2p (velocity gradient, position) with the stress update. Units: mm, ms, g, N, MPa, mJ.
//!
//! The velocity gradient always comes from the remapped grid velocities: a node that a particle
//! barely touches gets a huge velocity from f/m in the grid update, and with linear shape
//! functions its gradient weight does not vanish, so a gradient taken from those velocities
//! (USL) blows up at cell crossings. (We tried an APIC transfer without the remap: it blew up
//! exactly so with linear shapes, and with GIMP it was unstable once the material yielded.)
//!
//! Node accumulators (`grid::Node`, lanes of two vectors) by phase: after the first p2g,
//! `a` = momentum and `b` = force; after the grid update, `a` = new velocity and `b` = velocity
//! change; after the remap, `a` = remapped velocity. Particles are reordered by grid block every
//! `RESORT_EVERY` steps; `Particles::id` keeps their original order for the outputs.

use super::contact::{self, ContactSums};
use super::grid::{padded_index, Grid, Node, OWNED};
use super::material::to_matrix;
use super::scene::Scene;
use super::shape::{Gimp, Linear, Stencil};
use super::{case::ShapeKind, Real, SolveError};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use wide::f64x4;

/// Particles per parallel work item in particle-order passes.
const CHUNK: usize = 1024;

/// Every this many steps the particles are reordered block by block, so that the particles a
/// block scatters are neighbours in memory too (measured: without it the time per
/// particle-step grew by half from 110 k to 520 k particles). Particles move a small fraction
/// of a block in this many steps.
const RESORT_EVERY: u64 = 100;

/// A particle touches a plate when its edge is within this share of its half-size of the
/// surface: far more than the few micrometres it moves in a step, far less than its size.
const CONTACT_TOLERANCE: Real = 0.05;

/// Energy integrals since the start, mJ. What the plates put in (`work`) goes to kinetic energy,
/// `internal` energy, the projection's `catch` and `friction`; what is left is numerical.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    /// ∫ σ:D dV dt: elastic energy plus plastic work.
    pub internal: Real,
    pub plastic: Real,
    /// Work of each plate (top, bottom) on the tube.
    pub work: [Real; 2],
    /// Dissipated by the normal part of the contact projection (nodes caught by a plate).
    pub catch: Real,
    /// Dissipated by friction at the plates.
    pub friction: Real,
}

impl Energies {
    /// Work of both plates on the tube, mJ.
    pub fn external(&self) -> Real {
        self.work[0] + self.work[1]
    }
}

/// What the last step did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepInfo {
    /// The step taken, ms.
    pub dt: Real,
    /// The step the CFL condition allowed (larger than `dt` when a history row was due), ms.
    pub stable_dt: Real,
    pub contact: ContactSums,
    /// Kinetic energy after the step, mJ.
    pub kinetic: Real,
}

#[derive(Debug, Clone, Copy, Default)]
struct ChunkSums {
    work: Real,
    plastic: Real,
    kinetic: Real,
    signal: Real,
    bad: Option<(usize, &'static str)>,
}

/// Wall time spent in each phase since the start, s.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PhaseTimes {
    /// Binning particles into blocks and building the sparse grid.
    pub bin: f64,
    /// Particle → grid transfers (both).
    pub p2g: f64,
    /// Reductions, grid updates with contact, broadcasts.
    pub grid: f64,
    /// Grid → particle transfers (velocity; gradient and position).
    pub g2p: f64,
    /// Cell averages and the stress update.
    pub stress: f64,
}

struct Clock(std::time::Instant);

impl Clock {
    fn start() -> Clock {
        Clock(std::time::Instant::now())
    }
    fn lap(&mut self, into: &mut f64) {
        let now = std::time::Instant::now();
        *into += (now - self.0).as_secs_f64();
        self.0 = now;
    }
}

/// A scene advancing in time.
pub struct Simulation {
    pub scene: Scene,
    pub grid: Grid,
    /// Simulated time, ms.
    pub time: Real,
    pub steps: u64,
    pub energy: Energies,
    pub phases: PhaseTimes,
    /// Largest c + |v| over the particles after the last step, mm/ms.
    signal: Real,
    /// Nodes lighter than this carry no velocity (guards divisions by tiny masses), g.
    mass_floor: Real,
    chunk_sums: Vec<ChunkSums>,
    block_sums: Vec<ContactSums>,
    /// Scratch of the particle reordering.
    seen: Vec<bool>,
}

impl Simulation {
    pub fn new(scene: Scene) -> Simulation {
        let n = scene.particles.len();
        let mut scene = scene;
        scene.particles.grad.resize(n, Matrix3::zeros());
        let mean_mass = scene.particles.mass.iter().sum::<Real>() / n.max(1) as Real;
        let c = scene.wave_speed();
        let vmax = scene
            .particles
            .v
            .iter()
            .map(|v| v.norm())
            .fold(0.0, Real::max);
        let grid = match scene.shape {
            ShapeKind::Linear => Grid::new::<Linear>(scene.cell),
            ShapeKind::Gimp => Grid::new::<Gimp>(scene.cell),
        };
        Simulation {
            scene,
            grid,
            time: 0.0,
            steps: 0,
            energy: Energies::default(),
            phases: PhaseTimes::default(),
            signal: c + vmax,
            mass_floor: 1e-14 * mean_mass,
            chunk_sums: Vec::new(),
            block_sums: Vec::new(),
            seen: Vec::new(),
        }
    }

    /// The time step the CFL condition allows now, ms.
    pub fn stable_dt(&self) -> Real {
        self.scene.cfl * self.scene.cell / self.signal
    }

    /// Advances one step of at most `dt_cap` ms.
    pub fn step(&mut self, dt_cap: Real) -> Result<StepInfo, SolveError> {
        let stable_dt = self.stable_dt();
        let dt = stable_dt.min(dt_cap);
        // The plates' mean velocity over the step: their travel in it is exact on the ramp.
        let ramp = self.scene.ramp;
        let share = (ramp.full_speed_time(self.time + dt) - ramp.full_speed_time(self.time)) / dt;
        for plate in &mut self.scene.plates {
            plate.velocity = plate.full_velocity * share;
        }
        let (contact, kinetic) = match self.scene.shape {
            ShapeKind::Linear => self.advance::<Linear>(dt),
            ShapeKind::Gimp => self.advance::<Gimp>(dt),
        }?;
        let info = StepInfo {
            dt,
            stable_dt,
            contact,
            kinetic,
        };
        for plate in &mut self.scene.plates {
            plate.z += plate.velocity * dt;
        }
        self.time += dt;
        self.steps += 1;
        Ok(info)
    }

    /// The phases of one step of `dt`; returns the contact sums and the kinetic energy after it.
    fn advance<S: Stencil>(&mut self, dt: Real) -> Result<(ContactSums, Real), SolveError> {
        let lp = self.scene.half_size / self.scene.cell;
        let mut clock = Clock::start();
        self.grid.bin::<S>(&self.scene.particles.x, lp);
        if self.steps.is_multiple_of(RESORT_EVERY) {
            self.scene
                .particles
                .permute(&self.grid.order, &mut self.seen);
            self.grid.adopt_order(&mut self.seen);
        }
        clock.lap(&mut self.phases.bin);
        self.p2g::<S, true>(lp);
        clock.lap(&mut self.phases.p2g);
        self.grid.reduce(true);
        let contact = self.grid_update(dt);
        self.grid.broadcast();
        clock.lap(&mut self.phases.grid);
        self.g2p_velocity::<S>(lp);
        clock.lap(&mut self.phases.g2p);
        self.p2g::<S, false>(lp);
        clock.lap(&mut self.phases.p2g);
        self.grid.reduce(false);
        self.remap();
        self.grid.broadcast();
        clock.lap(&mut self.phases.grid);
        self.g2p_kinematics::<S>(lp, dt);
        clock.lap(&mut self.phases.g2p);
        let kinetic = self.update_stress(dt)?;
        clock.lap(&mut self.phases.stress);
        self.energy.work[0] += contact.work[0];
        self.energy.work[1] += contact.work[1];
        self.energy.catch += contact.catch;
        self.energy.friction += contact.friction;
        Ok((contact, kinetic))
    }

    /// Particle → grid. With `full`: mass, momentum and internal force; else momentum only.
    fn p2g<S: Stencil, const FULL: bool>(&mut self, lp: Real) {
        let mut padded = std::mem::take(&mut self.grid.padded);
        let p = &self.scene.particles;
        let (plates, half) = (&self.scene.plates, self.scene.half_size);
        let tolerance = CONTACT_TOLERANCE * half;
        let g = &self.grid;
        let inv = g.inv_cell;
        padded
            .par_chunks_mut(g.padded_len())
            .enumerate()
            .for_each(|(b, pad)| {
                // The remap's scatter zeroes the mass lane too: `Grid::reduce` then adds
                // only momentum to the owned nodes.
                let zero = f64x4::splat(0.0);
                pad.iter_mut().for_each(|n| {
                    n.lo = zero;
                    if FULL {
                        n.hi = zero;
                    }
                });
                let o = g.padded_origin(b);
                for &q in &g.order[g.starts[b] as usize..g.starts[b + 1] as usize] {
                    let q = q as usize;
                    let xg = p.x[q] * inv;
                    let (bx, wx, gx) = S::eval(xg.x, lp);
                    let (by, wy, gy) = S::eval(xg.y, lp);
                    let (bz, wz, gz) = S::eval(xg.z, lp);
                    let (ox, oy, oz) = (
                        (bx - o[0]) as usize,
                        (by - o[1]) as usize,
                        (bz - o[2]) as usize,
                    );
                    let (m, v) = (p.mass[q], p.v[q]);
                    // [mass, momentum] (no mass in the remap).
                    let mv = f64x4::new([if FULL { m } else { 0.0 }, m * v.x, m * v.y, m * v.z]);
                    // Particles touching a plate put their mass, signed by the plate's side, in
                    // the touch lane (see `contact::plate_of`).
                    let touch = if FULL {
                        m * contact::touching(plates, p.x[q].z, half, tolerance)
                    } else {
                        0.0
                    };
                    // σ·V/h by columns: the force on node (i, j, k) is −(c0·∂x + c1·∂y + c2·∂z)
                    // of its weight, = fa·N_z + fb·N_z′ per (i, j) row.
                    let vs = to_matrix(&p.stress[q]) * (p.vol[q] * inv);
                    let (c0, c1, c2) = (vs.column(0), vs.column(1), vs.column(2));
                    for i in 0..S::N {
                        for j in 0..S::N {
                            let (wxy, gxy, wgxy) = (wx[i] * wy[j], gx[i] * wy[j], wx[i] * gy[j]);
                            let row = padded_index(S::PAD, ox + i, oy + j, oz);
                            let lo = mv * f64x4::splat(wxy);
                            if FULL {
                                let fa = c0 * gxy + c1 * wgxy;
                                let fb = c2 * wxy;
                                let fa = f64x4::new([-fa.x, -fa.y, -fa.z, touch * wxy]);
                                let fb = f64x4::new([-fb.x, -fb.y, -fb.z, 0.0]);
                                for k in 0..S::N {
                                    let n = &mut pad[row + k];
                                    let w = f64x4::splat(wz[k]);
                                    n.lo = lo.mul_add(w, n.lo);
                                    n.hi = fb.mul_add(f64x4::splat(gz[k]), fa.mul_add(w, n.hi));
                                }
                            } else {
                                for k in 0..S::N {
                                    let n = &mut pad[row + k];
                                    n.lo = lo.mul_add(f64x4::splat(wz[k]), n.lo);
                                }
                            }
                        }
                    }
                }
            });
        self.grid.padded = padded;
    }

    /// Owned nodes: momentum → velocity, add force·dt, apply the plates. Returns contact sums.
    fn grid_update(&mut self, dt: Real) -> ContactSums {
        let (plates, mu) = (&self.scene.plates, self.scene.friction);
        let floor = self.mass_floor;
        self.block_sums
            .resize(self.grid.len(), ContactSums::default());
        self.grid
            .owned
            .par_chunks_mut(OWNED)
            .zip(self.block_sums.par_iter_mut())
            .for_each(|(own, sums)| {
                *sums = ContactSums::default();
                for n in own.iter_mut() {
                    let m = n.mass();
                    if m <= floor {
                        n.set_a(&Vector3::zeros());
                        n.set_b(&Vector3::zeros());
                        continue;
                    }
                    let old = n.a() / m;
                    let mut v = old + n.b() * (dt / m);
                    if let Some(k) = contact::plate_of(plates, n.touch()) {
                        contact::apply(k, &plates[k], mu, m, &old, &mut v, sums);
                    }
                    n.set_a(&v);
                    n.set_b(&(v - old));
                }
            });
        let mut total = ContactSums::default();
        for s in &self.block_sums {
            total.add(s);
        }
        total
    }

    /// Owned nodes: remapped momentum → velocity, with the plates applied again, so that the
    /// velocities that move the particles and strain them do not run into a plate. Nothing is
    /// booked: this pass changes neither the particles' velocities nor their momentum (so
    /// neither the kinetic energy nor the load); what approaches a plate in them is caught, and
    /// booked, in the next step's grid update.
    fn remap(&mut self) {
        let (plates, mu) = (&self.scene.plates, self.scene.friction);
        let floor = self.mass_floor;
        self.grid.owned.par_chunks_mut(OWNED).for_each(|own| {
            for n in own.iter_mut() {
                let m = n.mass();
                if m <= floor {
                    n.set_a(&Vector3::zeros());
                    continue;
                }
                let mut v = n.a() / m;
                if let Some(k) = contact::plate_of(plates, n.touch()) {
                    contact::project(&plates[k], mu, &mut v);
                }
                n.set_a(&v);
            }
        });
    }

    /// Grid → particle velocity, FLIP: add the interpolated velocity change.
    fn g2p_velocity<S: Stencil>(&mut self, lp: Real) {
        let g = &self.grid;
        let inv = g.inv_cell;
        let p = &mut self.scene.particles;
        let x = &p.x;
        p.v.par_chunks_mut(CHUNK).enumerate().for_each(|(c, vs)| {
            for (i, v) in vs.iter_mut().enumerate() {
                let q = c * CHUNK + i;
                let (pad, ox, oy, oz, e) = stencil::<S>(g, q, x[q] * inv, lp);
                // Lanes 0..3 of `hi` are the velocity change b (lane 3, touch, is unused).
                let mut acc = f64x4::splat(0.0);
                for i in 0..S::N {
                    for j in 0..S::N {
                        let wxy = e[0].1[i] * e[1].1[j];
                        let row = padded_index(S::PAD, ox + i, oy + j, oz);
                        let mut s = f64x4::splat(0.0);
                        for k in 0..S::N {
                            s = pad[row + k].hi.mul_add(f64x4::splat(e[2].1[k]), s);
                        }
                        acc = s.mul_add(f64x4::splat(wxy), acc);
                    }
                }
                let a = acc.as_array();
                let dv = Vector3::new(a[0], a[1], a[2]);
                *v += dv;
            }
        });
    }

    /// Grid → particle kinematics: velocity gradient (kept in `grad`) and position from the
    /// remapped nodal velocities.
    fn g2p_kinematics<S: Stencil>(&mut self, lp: Real, dt: Real) {
        let g = &self.grid;
        let inv = g.inv_cell;
        let p = &mut self.scene.particles;
        (p.x.par_chunks_mut(CHUNK), p.grad.par_chunks_mut(CHUNK))
            .into_par_iter()
            .enumerate()
            .for_each(|(c, (xs, ls))| {
                for (i, (x, grad)) in xs.iter_mut().zip(ls.iter_mut()).enumerate() {
                    let q = c * CHUNK + i;
                    let (pad, ox, oy, oz, e) = stencil::<S>(g, q, *x * inv, lp);
                    // Lanes 1..4 of `lo` are the velocity. Per (i, j) row, s = Σ v·N_z and
                    // t = Σ v·N_z′; then the velocity and the columns of L = Σ v ⊗ ∇N.
                    let zero = f64x4::splat(0.0);
                    let (mut vel, mut l0, mut l1, mut l2) = (zero, zero, zero, zero);
                    for i in 0..S::N {
                        for j in 0..S::N {
                            let (wx, wy) = (e[0].1[i], e[1].1[j]);
                            let (wxy, gxy, wgxy) = (wx * wy, e[0].2[i] * wy, wx * e[1].2[j]);
                            let row = padded_index(S::PAD, ox + i, oy + j, oz);
                            let (mut s, mut t) = (zero, zero);
                            for k in 0..S::N {
                                let vn = pad[row + k].lo;
                                s = vn.mul_add(f64x4::splat(e[2].1[k]), s);
                                t = vn.mul_add(f64x4::splat(e[2].2[k]), t);
                            }
                            vel = s.mul_add(f64x4::splat(wxy), vel);
                            l0 = s.mul_add(f64x4::splat(gxy), l0);
                            l1 = s.mul_add(f64x4::splat(wgxy), l1);
                            l2 = t.mul_add(f64x4::splat(wxy), l2);
                        }
                    }
                    let (c0, c1, c2) = (l0.as_array(), l1.as_array(), l2.as_array());
                    let l = Matrix3::new(
                        c0[1], c1[1], c2[1], c0[2], c1[2], c2[2], c0[3], c1[3], c2[3],
                    );
                    let vel = vel.as_array();
                    let vel = Vector3::new(vel[1], vel[2], vel[3]);
                    *grad = l * inv;
                    *x += vel * dt;
                }
            });
    }

    /// Per grid cell: the volume-weighted mean dilation rate tr(L) and pressure of its particles.
    fn cell_averages(&mut self) {
        let g = &mut self.grid;
        let p = &self.scene.particles;
        let (order, starts, cell_of) = (&g.order, &g.starts, &g.cell_of);
        (
            g.cell_dilation.par_iter_mut(),
            g.cell_pressure.par_iter_mut(),
        )
            .into_par_iter()
            .enumerate()
            .for_each(|(b, (dil, pre))| {
                let mut vol = [0.0; 64];
                *dil = [0.0; 64];
                *pre = [0.0; 64];
                for &q in &order[starts[b] as usize..starts[b + 1] as usize] {
                    let q = q as usize;
                    let c = cell_of[q] as usize;
                    let s = &p.stress[q];
                    vol[c] += p.vol[q];
                    dil[c] += p.vol[q] * p.grad[q].trace();
                    pre[c] += p.vol[q] * (s[0] + s[1] + s[2]) / 3.0;
                }
                for c in 0..64 {
                    if vol[c] > 0.0 {
                        dil[c] /= vol[c];
                        pre[c] /= vol[c];
                    }
                }
            });
    }

    /// Stress, volume and energy update from the velocity gradients of `g2p_kinematics`, with
    /// the cell-averaged dilation and pressure when the scene asks for them. Finds the next
    /// step's signal speed and any particle that went bad. Returns the kinetic energy, mJ.
    fn update_stress(&mut self, dt: Real) -> Result<Real, SolveError> {
        let average = self.scene.average_volumetric;
        if average {
            self.cell_averages();
        }
        let g = &self.grid;
        let material = self.scene.material;
        let modulus = material.p_wave_modulus();
        let domain = self.scene.domain;
        let p = &mut self.scene.particles;
        let (mass, yield_scale, xs, vs, p_grad) = (&p.mass, &p.yield_scale, &p.x, &p.v, &p.grad);
        (
            p.stress.par_chunks_mut(CHUNK),
            p.vol.par_chunks_mut(CHUNK),
            p.plastic_strain.par_chunks_mut(CHUNK),
        )
            .into_par_iter()
            .enumerate()
            .map(|(c, (ss, vols, eps))| {
                let mut sums = ChunkSums::default();
                for i in 0..ss.len() {
                    let q = c * CHUNK + i;
                    let mut l = p_grad[q];
                    if average {
                        let (b, cell) = (g.home[q] as usize, g.cell_of[q] as usize);
                        let shift = (g.cell_dilation[b][cell] - l.trace()) / 3.0;
                        l[(0, 0)] += shift;
                        l[(1, 1)] += shift;
                        l[(2, 2)] += shift;
                        let s = &mut ss[i];
                        let dp = g.cell_pressure[b][cell] - (s[0] + s[1] + s[2]) / 3.0;
                        s[0] += dp;
                        s[1] += dp;
                        s[2] += dp;
                    }
                    let scale = if yield_scale.is_empty() {
                        1.0
                    } else {
                        yield_scale[q]
                    };
                    let inc = material.update(&mut ss[i], &l, dt, scale);
                    let before = vols[i];
                    vols[i] *= (Matrix3::identity() + l * dt).determinant();
                    sums.work += inc.stress_power * 0.5 * (before + vols[i]) * dt;
                    if inc.plastic_strain > 0.0 {
                        eps[i] += inc.plastic_strain;
                        sums.plastic +=
                            material.yield_stress * scale * inc.plastic_strain * vols[i];
                    }
                    sums.kinetic += 0.5 * mass[q] * vs[q].norm_squared();
                    sums.signal = sums
                        .signal
                        .max((modulus * vols[i] / mass[q]).sqrt() + vs[q].norm());
                    // One sum is not finite if any term is not: the full check names the
                    // fault only then.
                    let (x, v, st) = (&xs[q], &vs[q], &ss[i]);
                    let total = x.sum() + v.sum() + st.iter().sum::<Real>() + vols[i];
                    let inside = (0..3).all(|a| x[a] >= domain[0][a] && x[a] <= domain[1][a]);
                    if sums.bad.is_none() && !(total.is_finite() && vols[i] > 0.0 && inside) {
                        sums.bad = diagnose(x, st, vols[i], v, &domain).map(|what| (q, what));
                    }
                }
                sums
            })
            .collect_into_vec(&mut self.chunk_sums);
        let mut signal: Real = 0.0;
        let mut kinetic = 0.0;
        for s in &self.chunk_sums {
            kinetic += s.kinetic;
            self.energy.internal += s.work;
            self.energy.plastic += s.plastic;
            signal = signal.max(s.signal);
            if let Some((q, what)) = s.bad {
                let (x, id) = (self.scene.particles.x[q], self.scene.particles.id[q]);
                return Err(SolveError::Unstable {
                    step: self.steps + 1,
                    time_ms: self.time + dt,
                    what: format!(
                        "particle {id} at ({:.4}, {:.4}, {:.4}) mm: {what}",
                        x.x, x.y, x.z
                    ),
                });
            }
        }
        if !signal.is_finite() {
            return Err(SolveError::Unstable {
                step: self.steps + 1,
                time_ms: self.time + dt,
                what: "signal speed is not finite".into(),
            });
        }
        self.signal = signal;
        Ok(kinetic)
    }
}

/// What is wrong with a particle's state, if anything.
fn diagnose(
    x: &Vector3<Real>,
    s: &[Real; 6],
    vol: Real,
    v: &Vector3<Real>,
    domain: &[[Real; 3]; 2],
) -> Option<&'static str> {
    if !(x.iter().all(|c| c.is_finite())) {
        Some("position is not finite")
    } else if !(v.iter().all(|c| c.is_finite())) {
        Some("velocity is not finite")
    } else if !(s.iter().all(|c| c.is_finite())) {
        Some("stress is not finite")
    } else if !(vol.is_finite() && vol > 0.0) {
        Some("volume is not positive (the material turned inside out)")
    } else if (0..3).any(|a| x[a] < domain[0][a] || x[a] > domain[1][a]) {
        Some("left the domain (crossed a plate or flew away)")
    } else {
        None
    }
}

/// A particle's padded buffer, its stencil's offset in it and the per-axis weights.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn stencil<S: Stencil>(
    g: &Grid,
    q: usize,
    xg: Vector3<Real>,
    lp: Real,
) -> (
    &[Node],
    usize,
    usize,
    usize,
    [(i32, [Real; 3], [Real; 3]); 3],
) {
    let b = g.home[q] as usize;
    let o = g.padded_origin(b);
    let e = [S::eval(xg.x, lp), S::eval(xg.y, lp), S::eval(xg.z, lp)];
    (
        &g.padded[b * g.padded_len()..(b + 1) * g.padded_len()],
        (e[0].0 - o[0]) as usize,
        (e[1].0 - o[1]) as usize,
        (e[2].0 - o[2]) as usize,
        e,
    )
}
