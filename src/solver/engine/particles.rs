//! Particle state, struct of arrays. Units: mm, m/s (= mm/ms), g, mm³, MPa.

use crate::solver::model::material::Sym;
use crate::solver::Real;
use nalgebra::Vector3;

/// Every particle's state; all vectors have one entry per particle.
#[derive(Debug, Clone, Default)]
pub struct Particles {
    pub x: Vec<Vector3<Real>>,
    pub v: Vec<Vector3<Real>>,
    /// Cauchy stress, MPa.
    pub stress: Vec<Sym>,
    /// Mass, g (constant).
    pub mass: Vec<Real>,
    /// Current volume, mm³.
    pub vol: Vec<Real>,
    /// Equivalent plastic strain.
    pub plastic_strain: Vec<Real>,
    /// Yield stress factor per particle; empty when the scene has no weak particles.
    pub yield_scale: Vec<Real>,
    /// Each particle's index in the scene as built: the solver reorders particles for speed,
    /// and outputs use this to report them in their original order.
    pub id: Vec<u32>,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Room for `n` more particles in every array, exactly, so that a scene built particle by
    /// particle holds no spare capacity (growth by doubling would leave up to half of each
    /// array unused).
    pub fn reserve_exact(&mut self, n: usize) {
        self.x.reserve_exact(n);
        self.v.reserve_exact(n);
        self.stress.reserve_exact(n);
        self.mass.reserve_exact(n);
        self.vol.reserve_exact(n);
        self.plastic_strain.reserve_exact(n);
        self.id.reserve_exact(n);
    }

    /// Adds a particle at rest, unstressed.
    pub fn push(&mut self, x: Vector3<Real>, mass: Real, vol: Real) {
        self.x.push(x);
        self.v.push(Vector3::zeros());
        self.stress.push([0.0; 6]);
        self.mass.push(mass);
        self.vol.push(vol);
        self.plastic_strain.push(0.0);
        self.id.push(self.id.len() as u32);
    }

    /// Reorders every particle so that new particle `i` is old particle `order[i]` (`order` a
    /// permutation), in place; `seen` is scratch of any length.
    pub fn permute(&mut self, order: &[u32], seen: &mut Vec<bool>) {
        permute(&mut self.x, order, seen);
        permute(&mut self.v, order, seen);
        permute(&mut self.stress, order, seen);
        permute(&mut self.mass, order, seen);
        permute(&mut self.vol, order, seen);
        permute(&mut self.plastic_strain, order, seen);
        permute(&mut self.id, order, seen);
        if !self.yield_scale.is_empty() {
            permute(&mut self.yield_scale, order, seen);
        }
    }

    /// `value(i)` of every particle, in the original order (see `id`).
    pub fn in_original_order<T: Copy + Default>(&self, value: impl Fn(usize) -> T) -> Vec<T> {
        let mut out = vec![T::default(); self.len()];
        for (i, &id) in self.id.iter().enumerate() {
            out[id as usize] = value(i);
        }
        out
    }

    /// Total momentum, g·mm/ms.
    pub fn momentum(&self) -> Vector3<Real> {
        self.v.iter().zip(&self.mass).map(|(v, m)| v * *m).sum()
    }

    /// Bytes held per particle by these arrays (capacity, not length).
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.x.capacity() * size_of::<Vector3<Real>>()
            + self.v.capacity() * size_of::<Vector3<Real>>()
            + self.stress.capacity() * size_of::<Sym>()
            + (self.mass.capacity() + self.vol.capacity() + self.plastic_strain.capacity())
                * size_of::<Real>()
            + self.yield_scale.capacity() * size_of::<Real>()
            + self.id.capacity() * size_of::<u32>()
    }
}

/// `v[i] ← v[order[i]]` for a permutation `order`, in place, cycle by cycle.
pub fn permute<T>(v: &mut [T], order: &[u32], seen: &mut Vec<bool>) {
    seen.clear();
    seen.resize(v.len(), false);
    for start in 0..v.len() {
        if seen[start] {
            continue;
        }
        // Along the cycle start → order[start] → …, each slot takes its successor's value; the
        // start's value travels along by the swaps and lands in the cycle's last slot.
        let mut j = start;
        loop {
            seen[j] = true;
            let k = order[j] as usize;
            if k == start {
                break;
            }
            v.swap(j, k);
            j = k;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_moves_each_value_to_its_new_place() {
        let old: Vec<u32> = (0..50).map(|i| i * 7 + 3).collect();
        // A permutation with cycles of several lengths and fixed points.
        let order: Vec<u32> = (0..50u32).map(|i| (i * 17 + 5) % 50).collect();
        let mut v = old.clone();
        permute(&mut v, &order, &mut Vec::new());
        for i in 0..50 {
            assert_eq!(v[i], old[order[i] as usize]);
        }
        let identity: Vec<u32> = (0..50).collect();
        let mut w = old.clone();
        permute(&mut w, &identity, &mut Vec::new());
        assert_eq!(w, old);
    }
}
