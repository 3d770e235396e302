//! Contact of the tube with rigid plates at grid nodes (design page §3): a plate of infinite mass
//! and prescribed velocity; at a node in contact whose velocity approaches the plate, the normal
//! velocity becomes the plate's and the tangential impulse is capped at μ times the normal one.
//!
//! Which nodes are in contact: those that a particle touching the plate contributes mass to
//! (`touches`, scattered as `Node::touch`). The first version took every node within one cell of
//! the plate instead; each time the plate crossed a node plane a whole layer of nodes was
//! caught at once, giving load spikes of 3–5 times the mean every cell of travel in the lateral
//! crush, and the material within a cell of the plate acted as a rigid end cap.
//! Units: g, mm/ms, g·mm/ms (impulse: N·ms), mJ.

use super::scene::Plate;
use super::Real;
use nalgebra::Vector3;

/// What contact did over one step, summed over nodes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactSums {
    /// Normal impulse the tube received from each plate (top, bottom), N·ms, positive.
    pub impulse: [Real; 2],
    /// Work done by the plates on the tube, mJ.
    pub work: Real,
    /// Energy dissipated by friction: tangential impulse times the remaining slip, mJ.
    pub friction: Real,
}

impl ContactSums {
    pub fn add(&mut self, o: &ContactSums) {
        self.impulse[0] += o.impulse[0];
        self.impulse[1] += o.impulse[1];
        self.work += o.work;
        self.friction += o.friction;
    }
}

/// The plate law at one node of mass `m` in contact with plate `k`: when the node's velocity `v`
/// approaches the plate, its normal component becomes the plate's and the tangential one loses
/// at most μ times the normal impulse. Accounting goes to `sums` when given.
#[inline]
pub fn apply(
    k: usize,
    plate: &Plate,
    mu: Real,
    m: Real,
    v: &mut Vector3<Real>,
    sums: Option<&mut ContactSums>,
) {
    // Normal out of the tube towards the plate is (0, 0, side).
    let approach = (v.z - plate.velocity) * plate.side;
    if approach <= 0.0 {
        return;
    }
    let before = *v;
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
    if let Some(s) = sums {
        let impulse = (*v - before) * m;
        s.impulse[k] += -impulse.z * plate.side;
        s.work += impulse.z * plate.velocity;
        let (t0, t1) = (before.x.hypot(before.y), v.x.hypot(v.y));
        s.friction += m * (t0 - t1) * t1;
    }
}

/// The plate a node at height `z` can touch: the nearer one.
#[inline]
fn nearer(plates: &[Plate], z: Real) -> Option<usize> {
    (0..plates.len()).min_by(|&a, &b| (plates[a].z - z).abs().total_cmp(&(plates[b].z - z).abs()))
}

/// [`apply`] with the plate nearer to a node at height `z` (a node in contact touches one plate).
#[inline]
pub fn apply_nearest(
    plates: &[Plate],
    mu: Real,
    z: Real,
    m: Real,
    v: &mut Vector3<Real>,
    sums: Option<&mut ContactSums>,
) {
    if let Some(k) = nearer(plates, z) {
        apply(k, &plates[k], mu, m, v, sums);
    }
}

/// Whether a particle of half-size `half` (mm) centred at height `z` touches some plate: its
/// edge within `tolerance` (mm) of the surface, or past it.
#[inline]
pub fn touches(plates: &[Plate], z: Real, half: Real, tolerance: Real) -> bool {
    plates
        .iter()
        .any(|p| (p.z - z) * p.side - half <= tolerance)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn top(speed: Real) -> Vec<Plate> {
        vec![Plate {
            z: 10.0,
            side: 1.0,
            velocity: -speed,
        }]
    }

    #[test]
    fn approaching_node_takes_the_plate_normal_velocity() {
        let mut v = Vector3::new(0.0, 0.0, 2.0);
        let mut s = ContactSums::default();
        apply(0, &top(5.0)[0], 0.0, 2.0, &mut v, Some(&mut s));
        assert_eq!(v.z, -5.0);
        // impulse on the tube m·Δv = 2·(−7) downwards: the plate feels +14 N·ms
        assert!((s.impulse[0] - 14.0).abs() < 1e-12);
        // plate work = impulse · plate velocity = 14 · 5
        assert!((s.work - 70.0).abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn receding_nodes_are_left_alone_and_only_touching_particles_touch() {
        let mut v = Vector3::new(0.0, 0.0, -9.0);
        apply(0, &top(5.0)[0], 0.3, 1.0, &mut v, None);
        assert_eq!(v, Vector3::new(0.0, 0.0, -9.0));
        // plate at z = 10: a particle of half-size 0.25 touches when its centre is at 9.75
        assert!(touches(&top(5.0), 9.75, 0.25, 1e-3));
        assert!(!touches(&top(5.0), 9.7, 0.25, 1e-3));
        assert!(touches(&top(5.0), 10.2, 0.25, 1e-3));
        let both = vec![
            top(5.0)[0],
            Plate {
                z: 0.0,
                side: -1.0,
                velocity: 0.0,
            },
        ];
        assert_eq!(nearer(&both, 7.0), Some(0));
        assert_eq!(nearer(&both, 2.0), Some(1));
    }

    #[test]
    fn friction_caps_the_tangential_impulse_at_mu_times_normal() {
        let plates = [Plate {
            z: 0.0,
            side: -1.0,
            velocity: 0.0,
        }];
        // normal approach 1, slide 10, μ = 0.2: tangential impulse 0.2 → slide 9.8
        let mut v = Vector3::new(10.0, 0.0, -1.0);
        let mut s = ContactSums::default();
        apply(0, &plates[0], 0.2, 1.0, &mut v, Some(&mut s));
        assert!((v.x - 9.8).abs() < 1e-12 && v.z == 0.0);
        // friction work = tangential impulse (0.2) × remaining slip (9.8)
        assert!((s.friction - 0.2 * 9.8).abs() < 1e-12);
        // slow slide is stopped entirely (stick)
        let mut v = Vector3::new(0.1, 0.0, -1.0);
        apply(0, &plates[0], 0.2, 1.0, &mut v, None);
        assert_eq!(v, Vector3::zeros());
    }
}
