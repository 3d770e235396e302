//! Contact of the tube with rigid plates at grid nodes (design page §3): a plate of infinite mass
//! and prescribed velocity; at a node near the plate whose velocity approaches it, the normal
//! velocity becomes the plate's and the tangential impulse is capped at μ times the normal one.
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

/// The plate law for one node of mass `m` at height `z` whose velocity `v` is modified in place.
/// A node is in a plate's contact zone when it lies less than `zone` (mm) from the plate on the
/// tube's side, or beyond the plate. Accounting goes to `sums` when given.
#[inline]
pub fn apply(
    plates: &[Plate],
    zone: Real,
    mu: Real,
    z: Real,
    m: Real,
    v: &mut Vector3<Real>,
    mut sums: Option<&mut ContactSums>,
) {
    for (k, plate) in plates.iter().enumerate() {
        if (plate.z - z) * plate.side >= zone {
            continue;
        }
        // Normal out of the tube towards the plate is (0, 0, side).
        let approach = (v.z - plate.velocity) * plate.side;
        if approach <= 0.0 {
            continue;
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
        if let Some(s) = sums.as_deref_mut() {
            let impulse = (*v - before) * m;
            s.impulse[k] += -impulse.z * plate.side;
            s.work += impulse.z * plate.velocity;
            let (t0, t1) = (before.x.hypot(before.y), v.x.hypot(v.y));
            s.friction += m * (t0 - t1) * t1;
        }
    }
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
        apply(&top(5.0), 1.0, 0.0, 9.5, 2.0, &mut v, Some(&mut s));
        assert_eq!(v.z, -5.0);
        // impulse on the tube m·Δv = 2·(−7) downwards: the plate feels +14 N·ms
        assert!((s.impulse[0] - 14.0).abs() < 1e-12);
        // plate work = impulse · plate velocity = 14 · 5
        assert!((s.work - 70.0).abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn receding_or_distant_nodes_are_left_alone() {
        let mut v = Vector3::new(0.0, 0.0, -9.0);
        apply(&top(5.0), 1.0, 0.3, 9.5, 1.0, &mut v, None);
        assert_eq!(v, Vector3::new(0.0, 0.0, -9.0));
        let mut v = Vector3::new(1.0, 0.0, 3.0);
        apply(&top(5.0), 1.0, 0.3, 8.0, 1.0, &mut v, None);
        assert_eq!(v, Vector3::new(1.0, 0.0, 3.0));
    }

    #[test]
    fn friction_caps_the_tangential_impulse_at_mu_times_normal() {
        let plates = vec![Plate {
            z: 0.0,
            side: -1.0,
            velocity: 0.0,
        }];
        // normal approach 1, slide 10, μ = 0.2: tangential impulse 0.2 → slide 9.8
        let mut v = Vector3::new(10.0, 0.0, -1.0);
        let mut s = ContactSums::default();
        apply(&plates, 1.0, 0.2, 0.5, 1.0, &mut v, Some(&mut s));
        assert!((v.x - 9.8).abs() < 1e-12 && v.z == 0.0);
        // friction work = tangential impulse (0.2) × remaining slip (9.8)
        assert!((s.friction - 0.2 * 9.8).abs() < 1e-12);
        // slow slide is stopped entirely (stick)
        let mut v = Vector3::new(0.1, 0.0, -1.0);
        apply(&plates, 1.0, 0.2, 0.5, 1.0, &mut v, None);
        assert_eq!(v, Vector3::zeros());
    }
}
