//! Contact of the tube with rigid plates at grid nodes (design page §3): a plate of infinite mass
//! and prescribed velocity; at a node in contact whose velocity approaches the plate, the normal
//! velocity becomes the plate's and the tangential impulse is capped at μ times the normal one.
//!
//! Which nodes are in contact, and with which plate: those that a particle touching a plate
//! contributes mass to (`touching`, scattered as `Node::touch` with the sign of that plate's
//! side), and the plate whose touching particles gave the node more mass. Not every node within
//! one cell of the plate: each time the plate crosses a node plane a whole layer of nodes would
//! be caught at once (load spikes of 3–5 times the mean every cell of travel in the lateral
//! crush), and the material within a cell of the plate would act as a rigid end cap. Not the
//! plate nearest the node: that is wrong once the plates are a few cells apart (the end of every
//! lateral crush), where a node that only bottom-touching particles reach could be held by the
//! top plate.
//!
//! Energy: a projection of a node's velocity against a plate of velocity V with impulse J does
//! work J·V on the tube (the plate's work) and J·v̄ on the node, v̄ the node's mean velocity over
//! the step (start of step and end, leapfrog's midpoint: the grid's kinetic energy changes by
//! exactly (f·dt + J)·v̄). The difference J·(V − v̄) is the energy the projection dissipates: the
//! inelastic catch of a node by the plate (normal part) and friction (tangential part). A node
//! caught at rest from v0 loses ½·m·(v0 − V)² exactly; a node merely held against the plate
//! (v̄ = V) loses nothing, though its velocity after the force update is projected every step.
//! (Taking the velocity after the force update instead of v̄, ½·m·|v* − V|², books f²·dt²/2m
//! every step against a held node: a loss that the internal energy has already counted.)
//!
//! A step applies the law twice: in the grid update, to the velocity after the force, and in
//! the remap, to the velocity remapped from the particles' new momenta (no force between: v̄
//! is the mean of the velocities before and after the projection, so a node caught from b
//! loses ½·m·|b − V|² of normal approach exactly). Both projections are booked and both reach
//! the particles, FLIP's through the velocity change and the remap's through its own gather
//! (the engine's `g2p_catch` phase). The grid update's friction is booked against the
//! particles' mean velocity at the node instead of the node's own ([`apply_slip_deferred`],
//! [`book_slip_end`]): after the force update a node of almost no mass can move at any speed,
//! and its slip, booked against that, is a friction its particles never had.
//! Units: g, mm/ms, g·mm/ms (impulse: N·ms), mJ.

use crate::solver::Real;
use nalgebra::Vector3;

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

/// Index of the top (moving) plate and the bottom (fixed) plate in `Scene::plates`.
pub const TOP: usize = 0;
pub const BOTTOM: usize = 1;

/// A particle touches a plate when its edge is within this share of its half-size of the
/// surface: far more than the few micrometres it moves in a step, far less than its size.
pub const CONTACT_TOLERANCE: Real = 0.05;

/// What contact did over one step, summed over nodes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactSums {
    /// Normal impulse the tube received from each plate (top, bottom), N·ms, positive.
    pub impulse: [Real; 2],
    /// Work done by each plate (top, bottom) on the tube, J·V, mJ.
    pub work: [Real; 2],
    /// Energy dissipated by the normal part of the projection (the inelastic catch of nodes by
    /// a plate), mJ.
    pub catch: Real,
    /// Energy dissipated by the tangential part (friction), mJ.
    pub friction: Real,
}

impl ContactSums {
    /// Whether any node was projected: a projection always changes a node's normal velocity
    /// (it approached the plate), so it always has an impulse. (Not the friction: the remap's
    /// sums also hold the grid update's deferred friction, [`book_slip_end`].)
    pub fn caught_any(&self) -> bool {
        self.impulse != [0.0; 2]
    }

    pub fn add(&mut self, o: &ContactSums) {
        for k in 0..2 {
            self.impulse[k] += o.impulse[k];
            self.work[k] += o.work[k];
        }
        self.catch += o.catch;
        self.friction += o.friction;
    }
}

/// The plate law on a node velocity `v`: when it approaches `plate`, its normal component
/// becomes the plate's and the tangential one loses at most μ times the normal change. Returns
/// whether the node was in contact.
#[inline]
pub fn project(plate: &Plate, mu: Real, v: &mut Vector3<Real>) -> bool {
    // Normal out of the tube towards the plate is (0, 0, side).
    let approach = (v.z - plate.velocity) * plate.side;
    if approach <= 0.0 {
        return false;
    }
    v.z = plate.velocity;
    if mu > 0.0 {
        let slide = (v.x * v.x + v.y * v.y).sqrt();
        if slide > 0.0 {
            // Impulse that stops sliding is m·slide; Coulomb allows μ·m·approach.
            let keep = (1.0 - mu * approach / slide).max(0.0);
            v.x *= keep;
            v.y *= keep;
        }
    }
    true
}

/// [`project`] at a node of mass `m` in contact with plate `k`, with the books: `start` is the
/// node's velocity at the start of the pass, and the node's own mean velocity over it is what
/// the tangential impulse is booked against. See the module's note.
#[inline]
pub fn apply(
    k: usize,
    plate: &Plate,
    mu: Real,
    m: Real,
    start: &Vector3<Real>,
    v: &mut Vector3<Real>,
    sums: &mut ContactSums,
) {
    let slip = apply_slip_deferred(k, plate, mu, m, start, v, sums);
    if slip != [0.0; 2] {
        book_slip_end(slip, v, sums);
    }
}

/// [`apply`] in the grid update, with the friction booked against the particles' velocities
/// and not the node's own: returns the tangential impulse (x, y), of which only the start half,
/// −½·J_t·start, is booked here; [`book_slip_end`] books the other half in the remap, against
/// the remapped velocity. The remap scatters the particles' new momenta with the weights of the
/// grid update, so the two halves are J_t against the particles' mass-weighted mean velocity
/// at the node over the step: the work the tangential impulse does on the particles, which is
/// what they lose to friction. The node's own mean velocity would do as well where the node
/// carries its particles' motion, but not at a node of almost no mass (reached only by the tips
/// of its particles' shape functions): a finite force over almost no mass gives it a velocity
/// of 10⁷ mm/ms after the force update, and a partial slip booked against that books a friction
/// the particles never had (189 mJ in one step on a thin tube at its first peak, at the 4e-9 of
/// a particle's mass of two such nodes; docs/studies.md §4).
#[inline]
pub fn apply_slip_deferred(
    k: usize,
    plate: &Plate,
    mu: Real,
    m: Real,
    start: &Vector3<Real>,
    v: &mut Vector3<Real>,
    sums: &mut ContactSums,
) -> [Real; 2] {
    let before = *v;
    if !project(plate, mu, v) {
        return [0.0; 2];
    }
    let j = (*v - before) * m;
    let mean_z = 0.5 * (start.z + v.z);
    sums.impulse[k] += -j.z * plate.side;
    sums.work[k] += j.z * plate.velocity;
    sums.catch += j.z * (plate.velocity - mean_z);
    sums.friction -= 0.5 * (j.x * start.x + j.y * start.y);
    [j.x, j.y]
}

/// The end half of a friction booked by [`apply_slip_deferred`]: −½·J_t·`end`, `end` the
/// node's remapped velocity (its particles' mass-weighted mean velocity after the grid update).
#[inline]
pub fn book_slip_end(slip_impulse: [Real; 2], end: &Vector3<Real>, sums: &mut ContactSums) {
    sums.friction -= 0.5 * (slip_impulse[0] * end.x + slip_impulse[1] * end.y);
}

/// The plate a contact node obeys, from its touch lane (Σ m·N·side over the particles touching
/// a plate): the top plate (side +1) when positive, the bottom one when negative; None when no
/// touching particle reaches the node.
#[inline]
pub fn plate_of(plates: &[Plate], touch: Real) -> Option<usize> {
    if touch == 0.0 {
        return None;
    }
    plates.iter().position(|p| p.side * touch > 0.0)
}

/// Whether a particle at height `z` can reach a contact node, for a stencil of `nodes` nodes
/// per axis on cells of `cell` mm: a node's change reaches the particles whose stencils share
/// it with a particle touching the plate, within a half-size and two stencil supports (at most
/// 1.5 cells each) of the surface, 3.5 cells; `nodes` + 1 cells hold that for every stencil.
/// A filter for the particles the remap's catch can change (the rest would add zeros).
#[inline]
pub fn near_a_plate(
    plates: &[Plate],
    cell: Real,
    nodes: usize,
) -> impl Fn(Real) -> bool + Sync + '_ {
    let reach = cell * (nodes as Real + 1.0);
    move |z| plates.iter().any(|p| (p.z - z) * p.side <= reach)
}

/// The side of the plate a particle of half-size `half` (mm) centred at height `z` touches (its
/// edge within `tolerance` mm of the surface, or past it), or 0 when it touches none. Plates are
/// more than a particle apart while a crush runs, so a particle touches one plate at most.
#[inline]
pub fn touching(plates: &[Plate], z: Real, half: Real, tolerance: Real) -> Real {
    plates
        .iter()
        .find(|p| (p.z - z) * p.side - half <= tolerance)
        .map_or(0.0, |p| p.side)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn top(speed: Real) -> Plate {
        Plate {
            z: 10.0,
            side: 1.0,
            velocity: -speed,
            full_velocity: -speed,
        }
    }

    fn bottom() -> Plate {
        Plate {
            z: 0.0,
            side: -1.0,
            velocity: 0.0,
            full_velocity: 0.0,
        }
    }

    fn kinetic(m: Real, v: &Vector3<Real>) -> Real {
        0.5 * m * v.norm_squared()
    }

    #[test]
    fn approaching_node_takes_the_plate_normal_velocity() {
        let start = Vector3::new(0.0, 0.0, 2.0);
        let mut v = start;
        let mut s = ContactSums::default();
        apply(0, &top(5.0), 0.0, 2.0, &start, &mut v, &mut s);
        assert_eq!(v.z, -5.0);
        // impulse on the tube m·Δv = 2·(−7) downwards: the plate feels +14 N·ms
        assert!((s.impulse[0] - 14.0).abs() < 1e-12);
        // plate work = impulse · plate velocity = 14 · 5
        assert!((s.work[0] - 70.0).abs() < 1e-12, "{s:?}");
        // the catch of a node met at relative speed 7: ½·2·7² = 49, and the books close:
        // work = Δ kinetic + catch
        assert!((s.catch - 49.0).abs() < 1e-12, "{s:?}");
        let gain = kinetic(2.0, &v) - kinetic(2.0, &start);
        assert!((s.work[0] - gain - s.catch).abs() < 1e-12);
    }

    /// A node held against the plate (moving with it at the start of the step) whose force
    /// update pushes it into the plate is projected back every step: that is no loss.
    #[test]
    fn a_held_node_books_no_catch() {
        let start = Vector3::new(0.0, 0.0, -5.0);
        let mut v = Vector3::new(0.0, 0.0, -4.0);
        let mut s = ContactSums::default();
        apply(0, &top(5.0), 0.0, 2.0, &start, &mut v, &mut s);
        assert_eq!(v.z, -5.0);
        assert_eq!(s.catch, 0.0);
        assert!((s.work[0] - 2.0 * 5.0).abs() < 1e-12);
    }

    #[test]
    fn receding_nodes_are_left_alone_and_only_touching_particles_touch() {
        let mut v = Vector3::new(0.0, 0.0, -9.0);
        assert!(!project(&top(5.0), 0.3, &mut v));
        assert_eq!(v, Vector3::new(0.0, 0.0, -9.0));
        // plate at z = 10: a particle of half-size 0.25 touches when its centre is at 9.75
        let one = [top(5.0)];
        assert_eq!(touching(&one, 9.75, 0.25, 1e-3), 1.0);
        assert_eq!(touching(&one, 9.7, 0.25, 1e-3), 0.0);
        assert_eq!(touching(&one, 10.2, 0.25, 1e-3), 1.0);
        let both = [top(5.0), bottom()];
        assert_eq!(touching(&both, 0.25, 0.25, 1e-3), -1.0);
        // The plate a node obeys is the one its touching particles touch, wherever it stands.
        assert_eq!(plate_of(&both, 0.3), Some(0));
        assert_eq!(plate_of(&both, -0.3), Some(1));
        assert_eq!(plate_of(&both, 0.0), None);
    }

    #[test]
    fn friction_caps_the_tangential_impulse_at_mu_times_normal() {
        // normal approach 1, slide 10, μ = 0.2: tangential impulse 0.2 → slide 9.8
        let start = Vector3::new(10.0, 0.0, -1.0);
        let mut v = start;
        let mut s = ContactSums::default();
        apply(0, &bottom(), 0.2, 1.0, &start, &mut v, &mut s);
        assert!((v.x - 9.8).abs() < 1e-12 && v.z == 0.0);
        // friction work = tangential impulse (0.2) × mean slip over the step (9.9)
        assert!((s.friction - 0.2 * 9.9).abs() < 1e-12, "{s:?}");
        // catch: ½·1·1²; the fixed plate does no work; the node lost exactly the two
        assert!((s.catch - 0.5).abs() < 1e-12);
        assert_eq!(s.work, [0.0, 0.0]);
        let lost = kinetic(1.0, &start) - kinetic(1.0, &v);
        assert!((lost - s.catch - s.friction).abs() < 1e-12);
    }

    /// What broke: a node of almost no mass (2e-13 g against a particle's 4e-5 g), reached by
    /// the tips of its particles' shape functions, had 7e7 mm/ms after the force update and
    /// slipped on the plate; its friction booked against its own mean velocity came to tens of
    /// mJ, energy its particles never had. Booked against the particles' velocities (start and
    /// remapped end, here both about 1 mm/ms) it is the tangential impulse times their slip.
    #[test]
    fn a_node_of_almost_no_mass_slipping_on_a_plate_books_only_its_particles_slip() {
        let m = 2e-13;
        let start = Vector3::new(0.7, 0.4, -8.2);
        let mut v = Vector3::new(1.2e7, -3.6e7, 7.2e7);
        let (mut own, mut deferred) = (ContactSums::default(), ContactSums::default());
        let mut w = v;
        apply(0, &top(10.0), 0.3, m, &start, &mut w, &mut own);
        let jt = apply_slip_deferred(0, &top(10.0), 0.3, m, &start, &mut v, &mut deferred);
        assert_eq!(v, w, "the same projection");
        assert_eq!(
            (own.impulse, own.work, own.catch),
            (deferred.impulse, deferred.work, deferred.catch)
        );
        assert!(own.friction > 10.0, "the node's own books: {own:?}");
        let end = Vector3::new(0.9, 0.5, -10.0);
        book_slip_end(jt, &end, &mut deferred);
        let slip = 0.5 * (start.xy() + end.xy());
        let expect = -(jt[0] * slip.x + jt[1] * slip.y);
        assert!((deferred.friction - expect).abs() < 1e-15, "{deferred:?}");
        assert!(deferred.friction.abs() < 1e-4, "{deferred:?}");
    }

    /// The deferred friction is the tangential impulse times the particles' mean slip over the
    /// step, half at the start and half at the end: normal approach 1, slide 10, μ 0.2 (impulse
    /// 0.2), particles ending at 9.0 (they lag the node's 9.8): 0.2 × ½ (10 + 9.0) = 1.9; the
    /// catch is the node's, ½·1·1².
    #[test]
    fn the_deferred_friction_is_the_tangential_impulse_times_the_particles_mean_slip() {
        let start = Vector3::new(10.0, 0.0, -1.0);
        let mut v = start;
        let mut s = ContactSums::default();
        let jt = apply_slip_deferred(0, &bottom(), 0.2, 1.0, &start, &mut v, &mut s);
        assert!(
            (v.x - 9.8).abs() < 1e-12 && (jt[0] + 0.2).abs() < 1e-12,
            "{v:?} {jt:?}"
        );
        assert!((s.friction - 0.2 * 5.0).abs() < 1e-12, "start half: {s:?}");
        book_slip_end(jt, &Vector3::new(9.0, 0.0, 0.0), &mut s);
        assert!((s.friction - 1.9).abs() < 1e-12, "{s:?}");
        assert!((s.catch - 0.5).abs() < 1e-12, "{s:?}");
    }

    /// What broke: friction was booked as m·(t0 − t1)·t1, so a node that sticks (t1 = 0) booked
    /// nothing while it lost ½·m·t0².
    #[test]
    fn a_sticking_node_books_its_lost_tangential_energy() {
        let start = Vector3::new(0.1, 0.0, -1.0);
        let mut v = start;
        let mut s = ContactSums::default();
        apply(0, &bottom(), 0.2, 1.0, &start, &mut v, &mut s);
        assert_eq!(v, Vector3::zeros());
        assert!((s.friction - 0.5 * 0.1 * 0.1).abs() < 1e-15, "{s:?}");
    }
}
