//! The per-particle stress loop every model shares (units: MPa, 1/ms, mm³, mJ): each
//! particle's stress update from its velocity gradient, its volume, the energy books, the next
//! step's signal speed, and the check that stops a run whose numbers went bad. A model gives
//! the gradients and volume changes of its geometry through [`Deformation`].

use super::kernel::Energies;
use super::kernel::SolveError;
use super::particles::Particles;
use super::scene::Scene;
use crate::solver::model::material::{Increment, Law, MaterialLaw, Point, Sym, WithLaw};
use crate::solver::Real;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

/// Particles per stress update in one go: one per lane of `f64x4`.
const LANES: usize = 4;

/// Per chunk of particles: the sums the stress update books, and the first bad particle.
#[derive(Debug, Clone, Copy, Default)]
pub struct ChunkSums {
    work: Real,
    plastic: Real,
    kinetic: Real,
    signal: Real,
    bad: Option<(usize, &'static str)>,
}

/// What the books of a stress update hold fixed over a step (3D and the reduced models alike).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Books {
    /// The step, ms.
    pub dt: Real,
    /// P-wave modulus, MPa (for the signal speed).
    pub modulus: Real,
    /// Particles must stay inside this box, mm.
    pub domain: [[Real; 3]; 2],
}

impl Books {
    pub(crate) fn of(scene: &Scene, dt: Real) -> Books {
        Books {
            dt,
            modulus: scene.material.p_wave_modulus(),
            domain: scene.domain,
        }
    }
}

/// One particle after its stress update, as the books read it.
pub(crate) struct Updated<'a> {
    /// Its index in the particle arrays.
    pub q: usize,
    pub increment: Increment,
    /// Volume before and after the step, mm³.
    pub volume: (Real, Real),
    pub mass: Real,
    pub x: &'a Vector3<Real>,
    pub v: &'a Vector3<Real>,
    pub stress: &'a Sym,
}

impl ChunkSums {
    /// Books one updated particle: stress power (trapezoidal in volume), plastic work, kinetic
    /// energy, signal speed; and notes the first particle of the chunk whose state went bad.
    #[inline(always)]
    pub(crate) fn book(&mut self, b: &Books, u: Updated) {
        let (before, vol) = u.volume;
        let inc = &u.increment;
        self.work += inc.stress_power * 0.5 * (before + vol) * b.dt;
        // The law's own plastic work; adding the zero of an elastic particle leaves the sum's
        // bits as they are, so there is no branch.
        self.plastic += inc.plastic_work * vol;
        self.kinetic += 0.5 * u.mass * u.v.norm_squared();
        self.signal = self
            .signal
            .max((b.modulus * vol / u.mass).sqrt() + u.v.norm());
        // One sum is not finite if any term is not: the full check names the fault only then.
        let (x, v, st) = (u.x, u.v, u.stress);
        let total = x.sum() + v.sum() + st.iter().sum::<Real>() + vol;
        let inside = (0..3).all(|a| x[a] >= b.domain[0][a] && x[a] <= b.domain[1][a]);
        if self.bad.is_none() && !(total.is_finite() && vol > 0.0 && inside) {
            self.bad = diagnose(x, st, vol, v, &b.domain).map(|what| (u.q, what));
        }
    }
}

/// Adds the chunks' work into `energy` in chunk order, and returns the kinetic energy (mJ) and
/// the largest signal speed (mm/ms); or the first bad particle's instability, its place
/// written by `place(q)`, at `step` and `time_ms`.
pub(crate) fn close_books(
    chunks: &[ChunkSums],
    energy: &mut Energies,
    (step, time_ms): (u64, Real),
    place: impl Fn(usize) -> String,
) -> Result<(Real, Real), SolveError> {
    let mut signal: Real = 0.0;
    let mut kinetic = 0.0;
    for s in chunks {
        kinetic += s.kinetic;
        energy.internal += s.work;
        energy.plastic += s.plastic;
        signal = signal.max(s.signal);
        if let Some((q, what)) = s.bad {
            return Err(SolveError::Unstable {
                step,
                time_ms,
                what: format!("{}: {what}", place(q)),
            });
        }
    }
    if !signal.is_finite() {
        return Err(SolveError::Unstable {
            step,
            time_ms,
            what: "signal speed is not finite".into(),
        });
    }
    Ok((kinetic, signal))
}

/// What a model's kinematics give the stress update of each particle.
pub(crate) trait Deformation: Sync {
    /// Particle `q`'s velocity gradient (1/ms) and, with volumetric averaging, its cell's mean
    /// dilation rate (1/ms) and pressure (MPa), which replace the particle's own.
    fn gradient(&self, q: usize) -> (Matrix3<Real>, Option<(Real, Real)>);
    /// det(I + L·dt) in the model's geometry: a particle's volume after the step over before.
    fn volume_factor(&self, l: &Matrix3<Real>, dt: Real) -> Real;
}

/// The stress update of every particle `p` under the scene's law, for the 3D simulation and
/// the reduced models alike ([`update_particles_as`] with the law as a type,
/// [`MaterialLaw::with`]: one match a step, and the loop over the particles is monomorphic).
pub(crate) fn update_particles(
    p: &mut Particles,
    (law, books): (&MaterialLaw, &Books),
    chunks: (usize, &mut Vec<ChunkSums>),
    model: &impl Deformation,
) {
    struct Update<'a, D> {
        p: &'a mut Particles,
        books: &'a Books,
        chunks: (usize, &'a mut Vec<ChunkSums>),
        model: &'a D,
    }
    impl<D: Deformation> WithLaw for Update<'_, D> {
        type Output = ();
        fn with<L: Law>(self, law: &L) {
            update_particles_as(self.p, (law, self.books), self.chunks, self.model);
        }
    }
    law.with(Update {
        p,
        books,
        chunks,
        model,
    });
}

/// The stress update of every particle `p` under `law`, four at a time, in parallel chunks of
/// `chunk` particles whose sums go to `sums`, with the gradients and volume changes of `model`.
fn update_particles_as<L: Law>(
    p: &mut Particles,
    (law, books): (&L, &Books),
    (chunk, sums): (usize, &mut Vec<ChunkSums>),
    model: &impl Deformation,
) {
    let (mass, yield_scale, xs, vs) = (&p.mass, &p.yield_scale, &p.x, &p.v);
    let scaled = !yield_scale.is_empty();
    (
        p.stress.par_chunks_mut(chunk),
        p.vol.par_chunks_mut(chunk),
        p.plastic_strain.par_chunks_mut(chunk),
    )
        .into_par_iter()
        .enumerate()
        .map(|(c, (ss, vols, eps))| {
            let mut sums = ChunkSums::default();
            for first in (0..ss.len()).step_by(LANES) {
                let lanes = LANES.min(ss.len() - first);
                // Per particle: the velocity gradient and stress with the cell averages. Short
                // groups are padded with zero lanes (zero stress and gradient, which the update
                // leaves at zero).
                let mut ls = [Matrix3::zeros(); LANES];
                let mut points = [Point::FRESH; LANES];
                for (j, l) in ls.iter_mut().enumerate().take(lanes) {
                    let (i, q) = (first + j, c * chunk + first + j);
                    let averages;
                    (*l, averages) = model.gradient(q);
                    if let Some((dilation, pressure)) = averages {
                        let shift = (dilation - l.trace()) / 3.0;
                        l[(0, 0)] += shift;
                        l[(1, 1)] += shift;
                        l[(2, 2)] += shift;
                        let s = &mut ss[i];
                        let dp = pressure - (s[0] + s[1] + s[2]) / 3.0;
                        s[0] += dp;
                        s[1] += dp;
                        s[2] += dp;
                    }
                    if scaled {
                        points[j].strength_scale = yield_scale[q];
                    }
                    points[j].plastic_strain = eps[i];
                }
                // The lanes' stresses copied in one go after the averaging, not one by one
                // inside the loop above: filling them particle by particle measured the stress
                // phase 11–18 % slower (the update reads them back across lanes).
                let mut sa = [[0.0; 6]; LANES];
                sa[..lanes].copy_from_slice(&ss[first..first + lanes]);
                // Four stress updates at once, one per lane.
                let inc = law.update_four(&mut sa, &ls, books.dt, points);
                // Per particle again, in order: volume, books, checks. (These four at once too
                // measured slower: the gathers cost more than the lanes saved.)
                for j in 0..lanes {
                    let (i, q, l) = (first + j, c * chunk + first + j, &ls[j]);
                    ss[i] = sa[j];
                    let before = vols[i];
                    vols[i] *= model.volume_factor(l, books.dt);
                    eps[i] += inc[j].plastic_strain;
                    let updated = Updated {
                        q,
                        increment: inc[j],
                        volume: (before, vols[i]),
                        mass: mass[q],
                        x: &xs[q],
                        v: &vs[q],
                        stress: &ss[i],
                    };
                    sums.book(books, updated);
                }
            }
            sums
        })
        .collect_into_vec(sums);
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
